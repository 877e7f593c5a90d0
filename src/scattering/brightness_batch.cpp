// The very-rough brightness over arrays (brightness_batch.hpp): Eq. 4 / Eq. 5 shapes, §3.3.
#include "roughscope/scattering/brightness_batch.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdint>
#include <exception>
#include <limits>
#include <string>

#include "../core/target_clones.hpp"  // (private to the library: src/core/)
#include "roughscope/core/errors.hpp"
#include "roughscope/core/names.hpp"
#include "roughscope/scattering/geometry.hpp"

#if defined(__x86_64__) && defined(__GLIBC__) && defined(__GNUC__) && !defined(__clang__)
#define ROUGHSCOPE_HAVE_LIBMVEC 1
#include <immintrin.h>
#else
#define ROUGHSCOPE_HAVE_LIBMVEC 0
#endif

namespace roughscope {
namespace {

using Index = std::ptrdiff_t;

// =============================================================================================
// Vector math: e^x and x^(−3/2) over arrays, per instruction set (glibc's libmvec has one entry
// point per instruction set, the vector function ABI's; the kernel's own loops are built by the
// compiler for each, core/target_clones.hpp)
// =============================================================================================

enum class MathFn { Exp, InvPow32 };  // e^x; x^(−3/2) for x > 0

template <class Fn>
inline void apply_scalar(Fn fn, const double* x, double* y, Index n) {
    for (Index j = 0; j < n; ++j) y[j] = fn(x[j]);
}

void apply_generic(MathFn fn, const double* x, double* y, Index n) {
    switch (fn) {
        case MathFn::Exp:
            return apply_scalar([](double v) { return std::exp(v); }, x, y, n);
        case MathFn::InvPow32:
            return apply_scalar([](double v) { return 1.0 / (v * std::sqrt(v)); }, x, y, n);
    }
}

#if ROUGHSCOPE_HAVE_LIBMVEC
// glibc's libmvec (linked through libm): AVX2 4-lane and AVX-512 8-lane exp, ≤ 4 ulp.
#pragma GCC push_options
#pragma GCC target("avx2,fma")
// The name is fixed by the x86-64 vector function ABI that libmvec implements.
// NOLINTNEXTLINE(bugprone-reserved-identifier,readability-identifier-naming)
extern "C" __m256d _ZGVdN4v_exp(__m256d);
// x^(−3/2) = 1/(x √x), IEEE sqrt and division.
__m256d inv_pow32_avx2(__m256d x) {
    return _mm256_div_pd(_mm256_set1_pd(1.0), _mm256_mul_pd(x, _mm256_sqrt_pd(x)));
}

template <__m256d (*Fn)(__m256d)>
void apply_avx2_fn(const double* x, double* y, Index n) {
    Index j = 0;
    for (; j + 4 <= n; j += 4) _mm256_storeu_pd(y + j, Fn(_mm256_loadu_pd(x + j)));
    if (j < n) {  // the tail goes through the same vector function (position-independent)
        alignas(32) double in[4] = {0.0, 0.0, 0.0, 0.0}, res[4];
        for (Index t = 0; j + t < n; ++t) in[t] = x[j + t];
        _mm256_store_pd(res, Fn(_mm256_load_pd(in)));
        for (Index t = 0; j + t < n; ++t) y[j + t] = res[t];
    }
}

void apply_avx2(MathFn fn, const double* x, double* y, Index n) {
    switch (fn) {
        case MathFn::Exp:
            return apply_avx2_fn<_ZGVdN4v_exp>(x, y, n);
        case MathFn::InvPow32:
            return apply_avx2_fn<inv_pow32_avx2>(x, y, n);
    }
}
#pragma GCC pop_options

#pragma GCC push_options
#pragma GCC target("avx512f")
// The name is fixed by the x86-64 vector function ABI that libmvec implements.
// NOLINTNEXTLINE(bugprone-reserved-identifier,readability-identifier-naming)
extern "C" __m512d _ZGVeN8v_exp(__m512d);
// x^(−3/2) without the divider (its sqrt + div cost ~10% of the Eq. 5 kernel): y ≈ 1/√x from
// vrsqrt14pd (relative error < 2^−14), two Newton steps y += y (1 − x y²)/2 (error ~1.5 e² each,
// then rounding: a few ulp), then y³. x = +inf gives 0 (as 1/(x √x) does), NaN stays NaN.
__m512d inv_pow32_avx512(__m512d x) {
    const __m512d one = _mm512_set1_pd(1.0), half = _mm512_set1_pd(0.5);
    __m512d y = _mm512_maskz_rsqrt14_pd(0xFF, x);  // (maskz: no uninitialised-operand warning)
    for (int step = 0; step < 2; ++step) {
        const __m512d r = _mm512_fnmadd_pd(_mm512_mul_pd(x, y), y, one);  // 1 − x y²
        y = _mm512_fmadd_pd(_mm512_mul_pd(half, y), r, y);
    }
    y = _mm512_maskz_mov_pd(_mm512_cmp_pd_mask(x, _mm512_set1_pd(HUGE_VAL), _CMP_NEQ_UQ), y);
    return _mm512_mul_pd(_mm512_mul_pd(y, y), y);
}

template <__m512d (*Fn)(__m512d)>
void apply_avx512_fn(const double* x, double* y, Index n) {
    Index j = 0;
    for (; j + 8 <= n; j += 8) _mm512_storeu_pd(y + j, Fn(_mm512_loadu_pd(x + j)));
    if (j < n) {
        const __mmask8 mask = static_cast<__mmask8>((1u << (n - j)) - 1u);
        _mm512_mask_storeu_pd(y + j, mask, Fn(_mm512_maskz_loadu_pd(mask, x + j)));
    }
}

void apply_avx512(MathFn fn, const double* x, double* y, Index n) {
    switch (fn) {
        case MathFn::Exp:
            return apply_avx512_fn<_ZGVeN8v_exp>(x, y, n);
        case MathFn::InvPow32:
            return apply_avx512_fn<inv_pow32_avx512>(x, y, n);
    }
}
#pragma GCC pop_options

VectorIsa detect_cpu_isa() {
    __builtin_cpu_init();
    if (__builtin_cpu_supports("avx512f")) return VectorIsa::Avx512;
    if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return VectorIsa::Avx2;
    return VectorIsa::Generic;
}
#else
VectorIsa detect_cpu_isa() { return VectorIsa::Generic; }
#endif

std::atomic<VectorIsa> g_isa_cap{VectorIsa::Avx512};

// `isa`: the instruction set the processor runs (never above cpu_vector_isa()).
inline void apply_math(VectorIsa isa, MathFn fn, const double* x, double* y, Index n) {
#if ROUGHSCOPE_HAVE_LIBMVEC
    if (isa == VectorIsa::Avx512) return apply_avx512(fn, x, y, n);
    if (isa == VectorIsa::Avx2) return apply_avx2(fn, x, y, n);
#endif
    (void)isa;
    apply_generic(fn, x, y, n);
}

// =============================================================================================
// The kernel
// =============================================================================================

// One operand: element k is data[k * step] (step 0: one value for all elements).
struct Inputs {
    const double* theta_i;
    Index step_i;
    const double* theta_s;
    Index step_s;
    const double* phi_s;
    Index step_p;
    const double* sigma_over_T;
    Index step_m;
};

constexpr Index kBlock = 512;

template <AngleUnit U>
struct Unit {
    static constexpr bool kDegrees = U == AngleUnit::Degrees;
    static constexpr double kToRad = kDegrees ? kPi / 180.0 : 1.0;
    static constexpr const char* kThetaI = kDegrees ? "theta_i_deg" : "theta_i";
    static constexpr const char* kThetaS = kDegrees ? "theta_s_deg" : "theta_s";
    static constexpr const char* kPhiS = kDegrees ? "phi_s_deg" : "phi_s";
    // One turn = kTurn1 + kTurn2 (Cody–Waite; kTurn1 · k exact for |k| < 2^20).
    // Degrees: 360 exactly. Radians: 4 × fdlibm's pio2_1, pio2_1t (33 + 53 bits of 2π).
    static constexpr double kTurn1 = kDegrees ? 360.0 : 6.28318530693650245667e+00;
    static constexpr double kTurn2 = kDegrees ? 0.0 : 2.43084020260247689973e-10;
    static constexpr double kInvTurn = kDegrees ? 1.0 / 360.0 : 1.0 / (2.0 * kPi);
    // |φs| below this: the reduction above is exact (degrees) or within ~1e-16 rad (radians).
    static constexpr double kWide = kDegrees ? 0x1p44 : 0x1p22;
    static constexpr double kHalfToRad = kDegrees ? kPi / 360.0 : 0.5;  // φ/2 in radians
    static constexpr double kTurn = kDegrees ? 360.0 : 2.0 * kPi;  // for std::fmod beyond kWide
};

// Finds the first bad element of [begin, end) and throws the library's error for it (called only
// when the kernel's branch-free test found one); `at` is left at that element.
template <AngleUnit U>
void validate(const Inputs& in, Index begin, Index end, Index& at) {
    using Un = Unit<U>;
    constexpr double kHalfPi = kPi / 2.0;
    for (at = begin; at < end; ++at) {
        const double ti = in.theta_i[at * in.step_i] * Un::kToRad;
        const double ts = in.theta_s[at * in.step_s] * Un::kToRad;
        const double p = in.phi_s[at * in.step_p];
        const double m = in.sigma_over_T[at * in.step_m];
        if (!(ti >= 0.0 && ti < kHalfPi)) check::polar_angle(Un::kThetaI, ti);
        if (!(ts >= 0.0 && ts < kHalfPi)) check::polar_angle(Un::kThetaS, ts);
        if (!std::isfinite(p)) check::azimuth(Un::kPhiS, p * Un::kToRad);
        if (!(m > 0.0 && m <= std::numeric_limits<double>::max()))
            check::positive("sigma_over_T", m);
        // The library accepted what the quick test rejected (never expected): say so anyway.
        if (!(ti >= 0.0 && ti < kHalfPi && ts >= 0.0 && ts < kHalfPi && std::isfinite(p) &&
              m > 0.0 && m <= std::numeric_limits<double>::max()))
            throw InvalidArgument(
                "very_rough_brightness: angles must be in [0, 90) degrees, "
                "phi_s finite and sigma_over_T finite and > 0");
    }
}

// sin x and cos x for |x| <= π/4 (fdlibm's __kernel_sin / __kernel_cos minimax polynomials, ~1
// ulp).
[[gnu::always_inline]] inline double kernel_sin(double x) {
    constexpr double kS1 = -1.66666666666666324348e-01, kS2 = 8.33333333332248946124e-03,
                     kS3 = -1.98412698298579493134e-04, kS4 = 2.75573137070700676789e-06,
                     kS5 = -2.50507602534068634195e-08, kS6 = 1.58969099521155010221e-10;
    const double z = x * x;
    const double r = kS2 + z * (kS3 + z * (kS4 + z * (kS5 + z * kS6)));
    return x + (z * x) * (kS1 + z * r);
}
[[gnu::always_inline]] inline double kernel_cos(double x) {
    constexpr double kC1 = 4.16666666666666019037e-02, kC2 = -1.38888888888741095749e-03,
                     kC3 = 2.48015872894767294178e-05, kC4 = -2.75573143513906633035e-07,
                     kC5 = 2.08757232129817482790e-09, kC6 = -1.13596475577881948265e-11;
    const double z = x * x;
    // 1 + z q with q = −1/2 + z (kC1 + ...): the last step (an FMA where the ISA has one) adds
    // |z q| <= 0.31 to 1, so the result (>= 0.7) is within ~1 ulp.
    const double q = -0.5 + z * (kC1 + z * (kC2 + z * (kC3 + z * (kC4 + z * (kC5 + z * kC6)))));
    return 1.0 + z * q;
}
// c ? a : b for doubles as a bitwise select: both sides are evaluated, so GCC cannot sink them
// into a branch (which, under -ftrapping-math, it would then not if-convert and the loop would
// stay scalar on AVX2 and SSE2).
[[gnu::always_inline]] inline double select(bool c, double a, double b) {
    const std::uint64_t mask = -static_cast<std::uint64_t>(c);
    return std::bit_cast<double>((std::bit_cast<std::uint64_t>(a) & mask) |
                                 (std::bit_cast<std::uint64_t>(b) & ~mask));
}
// π/2 = kPio2Hi + kPio2Lo; kPio2Hi − x is exact for x in [π/4, π/2] (Sterbenz).
constexpr double kPio2Hi = 1.57079632679489655800e+00, kPio2Lo = 6.12323399573676603587e-17;

// sin θ and cos θ for a polar angle θ in [0, π/2] (what validation admits): one reduction to
// |y| <= π/4 and both kernels, branch-free (vectorises), no general range reduction.
[[gnu::always_inline]] inline void polar_sincos(double theta, double& s, double& c) {
    const bool upper = theta > 0.25 * kPi;
    const double y = select(upper, (kPio2Hi - theta) + kPio2Lo, theta);
    const double sy = kernel_sin(y), cy = kernel_cos(y);
    s = select(upper, cy, sy);
    c = select(upper, sy, cy);
}

// sin²(φ/2) for φ already reduced to half a turn (+ rounding): x = |φ|/2 in radians is in
// [0, π/2]; sin² x = s² (x <= π/4) or cos² y = 1 − sin² y with y = π/2 − x (>= 1/2, no
// cancellation). One polynomial.
template <AngleUnit U>
[[gnu::always_inline]] inline double sin2_half_azimuth(double phi_reduced) {
    const double x = __builtin_fabs(phi_reduced) * Unit<U>::kHalfToRad;
    const bool upper = x > 0.25 * kPi;
    const double y = select(upper, (kPio2Hi - x) + kPio2Lo, x);  // may be ~−1e-16: sin² is even
    const double s = kernel_sin(y), s2 = s * s;
    return select(upper, 1.0 - s2, s2);
}

// Brightness for elements [begin, end), one block of kBlock elements at a time. Inlined into the
// kernel's builds (kernel_best, kernel_baseline) so that the loops are auto-vectorised for each;
// `math` is the instruction set of the exponential and w^(−3/2) (apply_math). One pass per block
// reads the inputs where they are (a repeated scalar is read from a block filled once), validates
// them (branch-free; nothing is returned unless all are valid) and computes everything but the
// exponential (Gaussian, libmvec) or w^(−3/2) (exponential); a last pass writes the result. Per
// element: one reduction and two short polynomials per polar angle (sin and cos together), one
// polynomial for sin²(φs/2) after a reduction of φs modulo one turn, one division at most
// (Gaussian: 1/q_z²; exponential: none); no general-purpose sin/cos, no pow.
template <Correlation C, GeometricFactor F, Radiometry R, AngleUnit U>
[[gnu::always_inline]] inline void body(const Inputs& in, Index begin, Index end,
                                        double* __restrict out, Index& at, VectorIsa math) {
    using Un = Unit<U>;
    constexpr double kHalfPi = kPi / 2.0;
    constexpr double kMax = std::numeric_limits<double>::max();
    constexpr double kRound = 0x1.8p52;  // (x + kRound) − kRound = nearest integer, |x| < 2^51
    // km = 1/(4 m²) (Gaussian) or 1/m² (exponential), m = σ/T.
    constexpr double kM = C == Correlation::Gaussian ? 0.25 : 1.0;
    static_assert(C == Correlation::Gaussian || C == Correlation::Exponential,
                  "a new correlation function needs its vector form (pref, arg, MathFn) here");
    alignas(64) double km[kBlock], pref[kBlock], arg[kBlock], aux[kBlock];
    alignas(64) double scalar_ti[kBlock], scalar_ts[kBlock], scalar_p[kBlock], wide_p[kBlock];
    // Operands repeated over the result (step 0) are read from a block filled once.
    auto source = [](const double* data, Index step, double* fill) {
        if (step == 0) std::fill_n(fill, kBlock, data[0]);
        return step == 0;
    };
    const bool ti_rep = source(in.theta_i, in.step_i, scalar_ti);
    const bool ts_rep = source(in.theta_s, in.step_s, scalar_ts);
    const bool p_rep = source(in.phi_s, in.step_p, scalar_p);
    const bool m_rep = in.step_m == 0;
    const double m0 = in.sigma_over_T[0];
    const bool m0_bad = !(m0 > 0.0 && m0 <= kMax);
    if (m_rep) std::fill_n(km, kBlock, kM / (m0 * m0));
    for (Index start = begin; start < end; start += kBlock) {
        const Index n = std::min(kBlock, end - start);
        const double* __restrict ti_in = ti_rep ? scalar_ti : in.theta_i + start;
        const double* __restrict ts_in = ts_rep ? scalar_ts : in.theta_s + start;
        const double* __restrict p_in = p_rep ? scalar_p : in.phi_s + start;
        int bad = m_rep && m0_bad;
        if (!m_rep) {
            const double* __restrict m = in.sigma_over_T + start;
            for (Index j = 0; j < n; ++j) {
                bad += static_cast<int>(!(m[j] > 0.0) | !(m[j] <= kMax));
                km[j] = kM / (m[j] * m[j]);
            }
        }
        // The pass (inlined: it must be compiled for the wrapper's instruction set); `phi`
        // holds φs, reduced below when |φs| < kWide.
        auto pass = [&](const double* __restrict phi) __attribute__((always_inline)) {
            int bad_here = 0, wide = 0;
            for (Index j = 0; j < n; ++j) {
                const double t_i = ti_in[j] * Un::kToRad, t_s = ts_in[j] * Un::kToRad;
                const double p = phi[j];
                const double dp = p - p;  // 0 if finite, NaN otherwise
                bad_here += static_cast<int>(!(t_i >= 0.0) | !(t_i < kHalfPi) | !(t_s >= 0.0) |
                                             !(t_s < kHalfPi) | !(dp == 0.0));
                wide += static_cast<int>(!(__builtin_fabs(p) < Un::kWide));
                const double k = (p * Un::kInvTurn + kRound) - kRound;
                // φs − k turns, in half a turn either side of 0 (+ rounding)
                const double reduced = (p - k * Un::kTurn1) - k * Un::kTurn2;
                const double sh2 = sin2_half_azimuth<U>(reduced);
                double si, ci, ss, cs;
                polar_sincos(t_i, si, ci);
                polar_sincos(t_s, ss, cs);
                // q_xy² = sin²θi + sin²θs − 2 sinθi sinθs cos φs, without cancellation:
                const double d = si - ss;
                const double qxy2 = d * d + 4.0 * si * ss * sh2;
                const double sum_c = ci + cs;
                const double qz2 = sum_c * sum_c;
                double F2;
                if constexpr (F == GeometricFactor::VernoldHarvey) {
                    F2 = ci;  // F_VH² = cos θi (§3.2)
                } else {
                    // Eq. 6 with cos φs = 1 − 2 sin²(φs/2).
                    const double cos_phi = 1.0 - 2.0 * sh2;
                    double f = (1.0 + ci * cs - si * ss * cos_phi) / (ci * sum_c);
                    if constexpr (F == GeometricFactor::Ogilvy) f *= ci;
                    if constexpr (F == GeometricFactor::Kirchhoff) f *= ci / cs;
                    F2 = f * f;
                }
                // q_xy²/m² (× the constant of km): 0 on the specular direction however small m
                // is (km = +inf when m² underflows; 0 × inf would be NaN).
                const double qxy2_km = qxy2 == 0.0 ? 0.0 : qxy2 * km[j];
                // The radiometric factor 1/cos θs of intensity (§3.3) joins the denominator.
                if constexpr (C == Correlation::Gaussian) {
                    // Eq. 4 shape: F²/q_z² exp(−q_xy²/(4 m² q_z²))
                    if constexpr (R == Radiometry::Intensity) {
                        const double r = 1.0 / (qz2 * cs);
                        pref[j] = F2 * r;
                        arg[j] = -qxy2_km * (cs * r);
                    } else {
                        const double r = 1.0 / qz2;
                        pref[j] = F2 * r;
                        arg[j] = -qxy2_km * r;
                    }
                } else {
                    // Eq. 5 shape: F²/(q_z² t^{3/2}), t = 1 + q_xy²/(m² q_z²). With w = q_z² t =
                    // q_z² + q_xy²/m² (> 0, no cancellation) and √q_z² = cos θi + cos θs:
                    // F²/(q_z² t^{3/2}) = F² (cos θi + cos θs)/(w √w); the root is taken below.
                    pref[j] = F2 * sum_c;
                    arg[j] = qz2 + qxy2_km;
                    if constexpr (R == Radiometry::Intensity) pref[j] /= cs;
                }
            }
            bad += bad_here;
            return wide;
        };
        if (pass(p_in)) {  // rare: some |φs| >= kWide; reduce those with std::fmod
            for (Index j = 0; j < n; ++j)
                wide_p[j] =
                    __builtin_fabs(p_in[j]) < Un::kWide ? p_in[j] : std::fmod(p_in[j], Un::kTurn);
            pass(wide_p);
        }
        // The library's checks find and report the first bad element of the block.
        if (bad) validate<U>(in, start, start + n, at);
        double* __restrict o = out + start;
        if constexpr (C == Correlation::Gaussian) {
            apply_math(math, MathFn::Exp, arg, arg, n);
            for (Index j = 0; j < n; ++j) o[j] = pref[j] * arg[j];
        } else {
            apply_math(math, MathFn::InvPow32, arg, aux, n);  // w^(−3/2)
            for (Index j = 0; j < n; ++j) o[j] = pref[j] * aux[j];
        }
    }
}

// The kernel of the model and unit (their instance of body).
template <Correlation C, Radiometry R, AngleUnit U>
[[gnu::always_inline]] inline void run_factor(GeometricFactor f, const Inputs& in, Index begin,
                                              Index end, double* out, Index& at, VectorIsa math) {
    switch (f) {
        case GeometricFactor::Beckmann:
            return body<C, GeometricFactor::Beckmann, R, U>(in, begin, end, out, at, math);
        case GeometricFactor::VernoldHarvey:
            return body<C, GeometricFactor::VernoldHarvey, R, U>(in, begin, end, out, at, math);
        case GeometricFactor::Ogilvy:
            return body<C, GeometricFactor::Ogilvy, R, U>(in, begin, end, out, at, math);
        case GeometricFactor::Kirchhoff:
            return body<C, GeometricFactor::Kirchhoff, R, U>(in, begin, end, out, at, math);
    }
}

template <AngleUnit U>
[[gnu::always_inline]] inline void run_model(const BrightnessBatchModel& m, const Inputs& in,
                                             Index begin, Index end, double* out, Index& at,
                                             VectorIsa math) {
    using enum Correlation;
    using enum Radiometry;
    // One kernel per correlation function (each has its own vector form above).
    switch (m.correlation) {
        case Gaussian:
            if (m.radiometry == Radiance)
                return run_factor<Gaussian, Radiance, U>(m.factor, in, begin, end, out, at, math);
            return run_factor<Gaussian, Intensity, U>(m.factor, in, begin, end, out, at, math);
        case Exponential:
            if (m.radiometry == Radiance)
                return run_factor<Exponential, Radiance, U>(m.factor, in, begin, end, out, at,
                                                            math);
            return run_factor<Exponential, Intensity, U>(m.factor, in, begin, end, out, at, math);
    }
}

[[gnu::always_inline]] inline void run_kernel(const BrightnessBatchModel& m, AngleUnit unit,
                                              const Inputs& in, Index begin, Index end, double* out,
                                              Index& at, VectorIsa math) {
    if (unit == AngleUnit::Degrees)
        return run_model<AngleUnit::Degrees>(m, in, begin, end, out, at, math);
    run_model<AngleUnit::Radians>(m, in, begin, end, out, at, math);
}

// The kernel built for every instruction set of the clones' list (the processor's best runs) and
// for the baseline alone (VectorIsa::Generic). The clones return the validation's error instead
// of throwing it (core/target_clones.hpp: no exception may leave a cloned function).
ROUGHSCOPE_TARGET_CLONES std::exception_ptr kernel_best(const BrightnessBatchModel& m,
                                                        AngleUnit unit, const Inputs& in,
                                                        Index begin, Index end, double* out,
                                                        Index& at, VectorIsa math) {
    try {
        run_kernel(m, unit, in, begin, end, out, at, math);
    } catch (...) {
        return std::current_exception();
    }
    return nullptr;
}
void kernel_baseline(const BrightnessBatchModel& m, AngleUnit unit, const Inputs& in, Index begin,
                     Index end, double* out, Index& at) {
    run_kernel(m, unit, in, begin, end, out, at, VectorIsa::Generic);
}

Index step_of(std::span<const double> s, std::size_t n, const char* name) {
    if (s.size() == n && n != 1) return 1;
    if (s.size() == 1) return 0;
    throw InvalidArgument(std::string("very_rough_brightness_batch: ") + name + " has " +
                          std::to_string(s.size()) + " values; it must have " + std::to_string(n) +
                          " (one per output element) or 1");
}

constexpr std::array<NameEntry<VectorIsa>, 4> kIsaNames{{
    {"generic", VectorIsa::Generic},
    {"avx2", VectorIsa::Avx2},
    {"avx512", VectorIsa::Avx512},
    {"best", VectorIsa::Avx512},
}};

}  // namespace

std::string_view to_string(VectorIsa isa) { return name_of(kIsaNames, isa); }
VectorIsa parse_vector_isa(std::string_view name) {
    return parse_name(kIsaNames, "instruction set", name);
}

VectorIsa cpu_vector_isa() {
    static const VectorIsa isa = detect_cpu_isa();
    return isa;
}
// The CPU's best, or (a cap below it) the baseline build: the kernel's builds for instruction
// sets between the two are chosen by the program's loader, not at run time.
VectorIsa active_vector_isa() {
    const VectorIsa cpu = cpu_vector_isa();
    return g_isa_cap.load() >= cpu ? cpu : VectorIsa::Generic;
}
VectorIsa set_vector_isa_cap(VectorIsa cap) {
    g_isa_cap.store(cap);
    return active_vector_isa();
}

void very_rough_brightness_batch(const BrightnessBatchInput& in, std::span<double> out,
                                 const BrightnessBatchModel& model, std::size_t begin,
                                 std::size_t end, std::size_t& at) {
    const std::size_t n = out.size();
    if (begin > end || end > n)
        throw InvalidArgument("very_rough_brightness_batch: range [" + std::to_string(begin) +
                              ", " + std::to_string(end) + ") is outside [0, " + std::to_string(n) +
                              ")");
    if (begin == end) return;
    const Inputs inputs{in.theta_i.data(),      step_of(in.theta_i, n, "theta_i"),
                        in.theta_s.data(),      step_of(in.theta_s, n, "theta_s"),
                        in.phi_s.data(),        step_of(in.phi_s, n, "phi_s"),
                        in.sigma_over_T.data(), step_of(in.sigma_over_T, n, "sigma_over_T")};
    const VectorIsa isa = active_vector_isa();
    Index bad_at = static_cast<Index>(begin);
    try {
        if (isa == VectorIsa::Generic)
            kernel_baseline(model, in.unit, inputs, static_cast<Index>(begin),
                            static_cast<Index>(end), out.data(), bad_at);
        else if (const std::exception_ptr error =
                     kernel_best(model, in.unit, inputs, static_cast<Index>(begin),
                                 static_cast<Index>(end), out.data(), bad_at, isa))
            std::rethrow_exception(error);
    } catch (...) {
        at = static_cast<std::size_t>(bad_at);
        throw;
    }
}

void very_rough_brightness_batch(const BrightnessBatchInput& in, std::span<double> out,
                                 const BrightnessBatchModel& model) {
    std::size_t at = 0;
    try {
        very_rough_brightness_batch(in, out, model, 0, out.size(), at);
    } catch (const InvalidArgument& e) {
        if (out.empty() || std::string_view(e.what()).starts_with("very_rough_brightness_batch"))
            throw;
        throw InvalidArgument("element " + std::to_string(at) + ": " + e.what());
    }
}

}  // namespace roughscope
