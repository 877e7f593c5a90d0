// The roughness map's row loops (map_internal.hpp, docs/maps.md "Speed and memory"): loops
// without branches over plain arrays, written once for the auto-vectoriser and built by the
// compiler for several instruction sets (core/target_clones.hpp), plus a build for the baseline
// instruction set alone: the reference that limit_map_instruction_set(Baseline) selects. This
// file is compiled with -ffp-contract=off (CMakeLists.txt): no build contracts a multiply and an
// add into a fused multiply-add, so every build does the same arithmetic and gives the same map,
// bit for bit (tests/cpp/maps/test_maps.cpp, VectorBuildsGiveTheSameMap).
#include <atomic>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "core/target_clones.hpp"
#include "maps/map_internal.hpp"
#include "roughscope/maps/maps.hpp"

namespace roughscope::image {
namespace detail {
namespace {

std::atomic<MapInstructionSet> build_in_use{MapInstructionSet::Best};
bool best_build() {
    return build_in_use.load(std::memory_order_relaxed) == MapInstructionSet::Best;
}

// The loop of find_ratio_bins (find_ratio's bin arithmetic, the bin's position t from the
// mantissa's low bits as a double in [1, 2) minus 1 — exact, and without a 64-bit integer
// conversion SSE2 lacks).
[[gnu::always_inline]] inline void ratio_bins_loop(std::size_t n, const double* __restrict ratio,
                                                   const double* __restrict bins,
                                                   std::int64_t key_min, std::int64_t count,
                                                   int shift, double sign, double inv_anchor,
                                                   double* __restrict x, double* __restrict slope,
                                                   std::uint64_t& pending) {
    const std::uint64_t mantissa = (std::uint64_t{1} << shift) - 1;
    const std::uint64_t one = std::bit_cast<std::uint64_t>(1.0);
    const int up = 52 - shift;
    const std::uint64_t quiet_nan =
        std::bit_cast<std::uint64_t>(std::numeric_limits<double>::quiet_NaN());
    std::uint64_t left = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const double u = sign * (ratio[i] * inv_anchor - 1.0);
        const auto bits = std::bit_cast<std::uint64_t>(u);
        const std::int64_t bin = static_cast<std::int64_t>(bits >> shift) - key_min;
        const bool inside = static_cast<std::uint64_t>(bin) < static_cast<std::uint64_t>(count);
        const std::int64_t k = 5 * (bin & -static_cast<std::int64_t>(inside));  // bin 0 outside
        const double c0 = bins[k], c1 = bins[k + 1], c2 = bins[k + 2], c3 = bins[k + 3];
        const double t = std::bit_cast<double>(((bits & mantissa) << up) | one) - 1.0;
        const double value = c0 + t * (c1 + t * (c2 + t * c3));
        // 1/(bin width) = 2^(shift − 52) / 2^(exponent of u): from the exponent's bits (one
        // gather fewer than reading the bin's c4, the same power of 2).
        const double inv_width = std::bit_cast<double>(
            (std::uint64_t{2046 + 52 - static_cast<std::uint64_t>(shift)} - ((bits >> 52) & 0x7ff))
            << 52);
        const double d = (c1 + t * (2.0 * c2 + t * 3.0 * c3)) * inv_width * (sign + u);
        // Both NaN where the bin is not used: the quiet-NaN bits ORed in (no branch for the
        // vectoriser).
        const std::uint64_t unused =
            (std::uint64_t{0} - static_cast<std::uint64_t>(!(inside & (c0 > 0.0)))) & quiet_nan;
        x[i] = std::bit_cast<double>(std::bit_cast<std::uint64_t>(value) | unused);
        slope[i] = std::bit_cast<double>(std::bit_cast<std::uint64_t>(d) | unused);
        // A ratio (not NaN) outside the used bins: for find.
        left |= unused & (std::uint64_t{0} - static_cast<std::uint64_t>(ratio[i] == ratio[i]));
    }
    pending = left;
}

ROUGHSCOPE_TARGET_CLONES bool ratio_bins_best(std::size_t n, const double* ratio,
                                              const double* bins, std::int64_t key_min,
                                              std::int64_t count, int shift, double sign,
                                              double inv_anchor, double* x, double* slope) {
    std::uint64_t pending = 0;
    ratio_bins_loop(n, ratio, bins, key_min, count, shift, sign, inv_anchor, x, slope, pending);
    return pending != 0;
}
bool ratio_bins_baseline(std::size_t n, const double* ratio, const double* bins,
                         std::int64_t key_min, std::int64_t count, int shift, double sign,
                         double inv_anchor, double* x, double* slope) {
    std::uint64_t pending = 0;
    ratio_bins_loop(n, ratio, bins, key_min, count, shift, sign, inv_anchor, x, slope, pending);
    return pending != 0;
}

// out = (p0 + p1 + p2)·scale (p1, p2 null: p0·scale); whether every value is finite — the sum of
// finite floats in double is finite, and v − v is +0 for a finite v and NaN otherwise (an
// integer OR of its bits, so that the compiler vectorises the loop).
[[gnu::always_inline]] inline bool scaled_row_is_finite_body(std::size_t W,
                                                             const float* __restrict p0,
                                                             const float* __restrict p1,
                                                             const float* __restrict p2,
                                                             double scale, double* __restrict out) {
    std::uint64_t not_finite = 0;
    if (p1 == nullptr) {
        for (std::size_t x = 0; x < W; ++x) {
            const double v = static_cast<double>(p0[x]) * scale;
            out[x] = v;
            not_finite |= std::bit_cast<std::uint64_t>(v - v);
        }
    } else {
        for (std::size_t x = 0; x < W; ++x) {
            const double v = (static_cast<double>(p0[x]) + p1[x] + p2[x]) * scale;
            out[x] = v;
            not_finite |= std::bit_cast<std::uint64_t>(v - v);
        }
    }
    return not_finite == 0;
}

ROUGHSCOPE_TARGET_CLONES bool scaled_row_is_finite_best(std::size_t W, const float* p0,
                                                        const float* p1, const float* p2,
                                                        double scale, double* out) {
    return scaled_row_is_finite_body(W, p0, p1, p2, scale, out);
}
bool scaled_row_is_finite_baseline(std::size_t W, const float* p0, const float* p1, const float* p2,
                                   double scale, double* out) {
    return scaled_row_is_finite_body(W, p0, p1, p2, scale, out);
}

// v, or NaN where the mask is all ones (bit operations: a select without a branch).
inline double nan_where(double v, std::uint64_t mask) {
    constexpr auto kNaNBits =
        std::bit_cast<std::uint64_t>(std::numeric_limits<double>::quiet_NaN());
    return std::bit_cast<double>((std::bit_cast<std::uint64_t>(v) & ~mask) | (mask & kNaNBits));
}
// All ones where `condition`, else 0.
inline std::uint64_t mask_of(bool condition) {
    return std::uint64_t{0} - static_cast<std::uint64_t>(condition);
}

template <bool kOther, bool kRatio>
[[gnu::always_inline]] inline RowCounts write_flat_row_body(
    std::size_t n, const double* __restrict ratio, const double* __restrict var,
    const double* __restrict state, const double* __restrict xp, const double* __restrict sp,
    const double* __restrict xo, const double* __restrict so, double slightly, double very,
    float* __restrict e12, float* __restrict lp, float* __restrict lpse, float* __restrict lo,
    float* __restrict lose, double* __restrict klass, std::uint8_t* __restrict cls) {
    std::uint64_t valid = 0, valid_other = 0, missing = 0, n0 = 0, n1 = 0, n2 = 0;
    double s0 = 0, s1 = 0, s2 = 0, q0 = 0, q1 = 0, q2 = 0;
    // (The class sums in lanes: their order of addition is the build's, not the threads'.)
#pragma omp simd reduction(+ : valid, valid_other, missing, n0, n1, n2, s0, s1, s2, q0, q1, q2)
    for (std::size_t i = 0; i < n; ++i) {
        const double p = xp[i], sd = std::sqrt(var[i]);
        if constexpr (kRatio) e12[i] = static_cast<float>(ratio[i]);
        lp[i] = static_cast<float>(p);
        lpse[i] = static_cast<float>(std::abs(sp[i]) * sd);
        if constexpr (kOther) {
            lo[i] = static_cast<float>(xo[i]);
            lose[i] = static_cast<float>(std::abs(so[i]) * sd);
            valid_other += xo[i] == xo[i] ? 1 : 0;
        }
        const std::uint64_t none = mask_of(p != p);
        const std::uint64_t m0 = mask_of(p < slightly), m2 = mask_of(p > very);
        const std::uint64_t m1 = ~none & ~m0 & ~m2;
        klass[i] = std::bit_cast<double>((std::bit_cast<std::uint64_t>(1.0) & m1) |
                                         (std::bit_cast<std::uint64_t>(2.0) & m2) |
                                         (std::bit_cast<std::uint64_t>(255.0) & none));
        valid += 1 & ~none;
        missing += state[i] == 1.0 ? 1 : 0;
        // The layer's value (a float), as row_class_sums reads it.
        const auto bits = std::bit_cast<std::uint64_t>(static_cast<double>(static_cast<float>(p)));
        const double v0 = std::bit_cast<double>(bits & m0), v1 = std::bit_cast<double>(bits & m1),
                     v2 = std::bit_cast<double>(bits & m2);
        n0 += 1 & m0;
        n1 += 1 & m1;
        n2 += 1 & m2;
        s0 += v0;
        s1 += v1;
        s2 += v2;
        q0 += v0 * v0;
        q1 += v1 * v1;
        q2 += v2 * v2;
    }
    for (std::size_t i = 0; i < n; ++i) cls[i] = static_cast<std::uint8_t>(klass[i]);
    // Every pixel is an estimate, missing, or without a solution (the other correlation's
    // count: kOther only).
    RowCounts counts{
        valid, missing, n - valid - missing, kOther ? n - valid_other - missing : 0, {}};
    counts.classes[0] = {n0, s0, q0};
    counts.classes[1] = {n1, s1, q1};
    counts.classes[2] = {n2, s2, q2};
    return counts;
}

template <bool kOther, bool kRatio>
[[gnu::always_inline]] inline RowCounts write_flat_row_of(std::size_t n, const FlatRowIn& in,
                                                          const FlatRowOut& out) {
    return write_flat_row_body<kOther, kRatio>(n, in.ratio, in.var, in.state, in.xp, in.sp, in.xo,
                                               in.so, in.slightly, in.very, out.ratio, out.p,
                                               out.pse, out.o, out.ose, out.klass, out.cls);
}
// write_flat_row_body's instance for the layers asked for (a function template cannot be cloned:
// core/target_clones.hpp).
[[gnu::always_inline]] inline RowCounts write_flat_row_any(std::size_t n, const FlatRowIn& in,
                                                           const FlatRowOut& out) {
    const bool other = out.o != nullptr, ratio = out.ratio != nullptr;
    if (other && ratio) return write_flat_row_of<true, true>(n, in, out);
    if (other) return write_flat_row_of<true, false>(n, in, out);
    if (ratio) return write_flat_row_of<false, true>(n, in, out);
    return write_flat_row_of<false, false>(n, in, out);
}
ROUGHSCOPE_TARGET_CLONES RowCounts write_flat_row_best(std::size_t n, const FlatRowIn& in,
                                                       const FlatRowOut& out) {
    return write_flat_row_any(n, in, out);
}
RowCounts write_flat_row_baseline(std::size_t n, const FlatRowIn& in, const FlatRowOut& out) {
    return write_flat_row_any(n, in, out);
}

[[gnu::always_inline]] inline void update_column_sums_body(
    std::size_t W, const double* __restrict a, const double* __restrict b,
    const double* __restrict u, double add_weight, const double* __restrict ra,
    const double* __restrict rb, const double* __restrict ru, double remove_weight,
    double* __restrict n, double* __restrict s1, double* __restrict s2, double* __restrict s11,
    double* __restrict s22, double* __restrict s12) {
    for (std::size_t x = 0; x < W; ++x) {
        const double w = add_weight * u[x], wa = w * a[x], wb = w * b[x];
        const double v = remove_weight * ru[x], va = v * ra[x], vb = v * rb[x];
        n[x] += w - v;
        s1[x] += wa - va;
        s2[x] += wb - vb;
        s11[x] += wa * a[x] - va * ra[x];
        s22[x] += wb * b[x] - vb * rb[x];
        s12[x] += wa * b[x] - va * rb[x];
    }
}

ROUGHSCOPE_TARGET_CLONES void update_column_sums_best(std::size_t W, const double* a,
                                                      const double* b, const double* u,
                                                      double add_weight, const double* ra,
                                                      const double* rb, const double* ru,
                                                      double remove_weight, const ColumnSums& s) {
    update_column_sums_body(W, a, b, u, add_weight, ra, rb, ru, remove_weight, s.n, s.s1, s.s2,
                            s.s11, s.s22, s.s12);
}
void update_column_sums_baseline(std::size_t W, const double* a, const double* b, const double* u,
                                 double add_weight, const double* ra, const double* rb,
                                 const double* ru, double remove_weight, const ColumnSums& s) {
    update_column_sums_body(W, a, b, u, add_weight, ra, rb, ru, remove_weight, s.n, s.s1, s.s2,
                            s.s11, s.s22, s.s12);
}

// The window's sums at each pixel of a row (2R + 1 column sums from c*[x], padded), then the
// pixel's ratio x1/x2, var(ln x1/x2) of one pixel (the delta method on the window's means,
// variances and covariance, docs/maps.md, in the form n²/(n − 1) · [Σx1²/(Σx1)² + Σx2²/(Σx2)²
// − 2 Σx1x2/(Σx1 Σx2)], one division for it and the ratio) and its state (PixelState).
[[gnu::always_inline]] inline void pixel_statistics_body(
    std::size_t W, const double* __restrict a, const double* __restrict b,
    const double* __restrict u, const double* __restrict cn, const double* __restrict cs1,
    const double* __restrict cs2, const double* __restrict cs11, const double* __restrict cs22,
    const double* __restrict cs12, double* __restrict ratio, double* __restrict var,
    double* __restrict state) {
    constexpr std::size_t kTaps = 2 * kPixelNoiseRadius + 1;
    for (std::size_t x = 0; x < W; ++x) {
        double n = 0, s1 = 0, s2 = 0, s11 = 0, s22 = 0, s12 = 0;
        for (std::size_t d = 0; d < kTaps; ++d) {
            n += cn[x + d];
            s1 += cs1[x + d];
            s2 += cs2[x + d];
            s11 += cs11[x + d];
            s22 += cs22[x + d];
            s12 += cs12[x + d];
        }
        const double s1s2 = s1 * s2;
        const double p = s1s2 * s1s2 * (n - 1.0);
        const double inv = 1.0 / (p * b[x]);
        const double bracket = s11 * s2 * s2 + s22 * s1 * s1 - 2.0 * s12 * s1s2;
        var[x] = std::max(0.0, n * n * bracket * b[x] * inv);
        // Running sums of ±1 stay exact integers in n. Without branches (and in doubles, for
        // the vectoriser): 1 missing, 2 no solution, 0 an estimate — whose ratio alone is a
        // number (NaN otherwise, which the look-ups carry through to the layers).
        const double missing = !(u[x] > 0.0) || n < 3.0 ? 1.0 : 0.0;
        const double no_solution =
            !(a[x] > 0.0) || !(b[x] > 0.0) || !(s1 > 0.0) || !(s2 > 0.0) ? 1.0 : 0.0;
        const double st = missing + 2.0 * (1.0 - missing) * no_solution;
        state[x] = st;
        ratio[x] = nan_where(a[x] * p * inv, mask_of(st != 0.0));
    }
}

static_assert(static_cast<int>(PixelState::Estimate) == 0 &&
              static_cast<int>(PixelState::Missing) == 1 &&
              static_cast<int>(PixelState::NoSolution) == 2);

ROUGHSCOPE_TARGET_CLONES void pixel_statistics_best(std::size_t W, const double* a, const double* b,
                                                    const double* u, const ConstColumnSums& c,
                                                    double* ratio, double* var, double* state) {
    pixel_statistics_body(W, a, b, u, c.n, c.s1, c.s2, c.s11, c.s22, c.s12, ratio, var, state);
}
void pixel_statistics_baseline(std::size_t W, const double* a, const double* b, const double* u,
                               const ConstColumnSums& c, double* ratio, double* var,
                               double* state) {
    pixel_statistics_body(W, a, b, u, c.n, c.s1, c.s2, c.s11, c.s22, c.s12, ratio, var, state);
}

}  // namespace

bool ratio_bins_row(std::size_t n, const double* ratio, const double* bins, std::int64_t key_min,
                    std::int64_t count, int shift, double sign, double inv_anchor, double* x,
                    double* slope) {
    return (best_build() ? ratio_bins_best : ratio_bins_baseline)(
        n, ratio, bins, key_min, count, shift, sign, inv_anchor, x, slope);
}

bool scaled_row_is_finite(std::size_t W, const float* p0, const float* p1, const float* p2,
                          double scale, double* out) {
    return (best_build() ? scaled_row_is_finite_best : scaled_row_is_finite_baseline)(W, p0, p1, p2,
                                                                                      scale, out);
}

RowCounts write_flat_row(std::size_t n, const FlatRowIn& in, const FlatRowOut& out) {
    return (best_build() ? write_flat_row_best : write_flat_row_baseline)(n, in, out);
}

void update_column_sums(std::size_t W, const double* a, const double* b, const double* u,
                        double add_weight, const double* ra, const double* rb, const double* ru,
                        double remove_weight, const ColumnSums& sums) {
    (best_build() ? update_column_sums_best : update_column_sums_baseline)(
        W, a, b, u, add_weight, ra, rb, ru, remove_weight, sums);
}

void pixel_statistics(std::size_t W, const double* a, const double* b, const double* u,
                      const ConstColumnSums& cols, double* ratio, double* var, double* state) {
    (best_build() ? pixel_statistics_best : pixel_statistics_baseline)(W, a, b, u, cols, ratio, var,
                                                                       state);
}

}  // namespace detail

MapInstructionSet limit_map_instruction_set(MapInstructionSet highest) {
    return detail::build_in_use.exchange(highest, std::memory_order_relaxed);
}
MapInstructionSet map_instruction_set() {
    return detail::build_in_use.load(std::memory_order_relaxed);
}

}  // namespace roughscope::image
