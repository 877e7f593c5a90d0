// The very-rough brightness (Eq. 4 / Eq. 5 shapes times the radiometric factor of §3.3) over
// arrays: the batch form of very_rough_brightness (beckmann.hpp) for fits, comparisons, images
// and the Python module.
//
// Same physics as the scalar function, evaluated in blocks: each block is validated (branch-free)
// in the pass that computes it; sin/cos of the polar angles come from one range reduction and
// fdlibm's minimax polynomials on [0, π/2] (the validated range), sin²(φs/2) from one more after an
// exact reduction of φs, the exponential (Gaussian) from glibc's vector math library on AVX2 or
// AVX-512 when the CPU has them (std::exp otherwise), and w^(−3/2) (exponential) from a square
// root and a division (AVX-512: rsqrt14 + two Newton steps). With
//   q_xy² = (sin θi − sin θs)² + 4 sin θi sin θs sin²(φs/2),   q_z² = (cos θi + cos θs)²
// (q_xy² written without cancellation):
//   Gaussian (Eq. 4):    F² / q_z² · exp(−q_xy² / (4 (σ/T)² q_z²))
//   exponential (Eq. 5): F² / (q_z² (1 + q_xy² / ((σ/T)² q_z²))^{3/2})
// times 1/cos θs for Radiometry::Intensity.
//
// Accuracy against the scalar very_rough_brightness: |batch − scalar| <= 1e-12 |scalar| (+1e-300
// where the Gaussian lobe underflows) on every instruction set; the largest relative difference
// measured by tests/cpp/core/test_brightness_batch.cpp over random geometries (θ in [0°, 89°], φs
// over a few turns and up to 1000 turns out, σ/T in [0.1, 3], every model) is 4e-13, from the
// exponential's argument (|error| ~ ulp of arguments up to ~700).
// Azimuths: in degrees φs is reduced modulo 360° exactly for |φs| < 2^44°; in radians modulo 2π
// with a two-part Cody–Waite constant (86 bits of 2π; error ~1e-16 rad for |φs| < 4e6 rad);
// beyond those, by std::fmod.
//
// Instruction set: picked at run time (__builtin_cpu_supports) among the ones compiled in with
// function target attributes — no -march flag is needed, any x86-64 CPU runs it; other
// architectures use the generic path.
#pragma once

#include <cstddef>
#include <span>
#include <string_view>

#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/factors.hpp"

namespace roughscope {

enum class AngleUnit { Radians, Degrees };

// The inputs: each span holds either n values (one per output element) or exactly 1 (the same
// value for every element).
struct BrightnessBatchInput {
    std::span<const double> theta_i;       // θi, [0, 90°)
    std::span<const double> theta_s;       // θs, [0, 90°)
    std::span<const double> phi_s;         // φs, finite
    std::span<const double> sigma_over_T;  // σ/T, finite and > 0
    AngleUnit unit = AngleUnit::Radians;   // of the three angles
};

// The model: correlation (Eq. 4 Gaussian or Eq. 5 exponential), geometric factor, radiometry.
struct BrightnessBatchModel {
    Correlation correlation = Correlation::Gaussian;
    GeometricFactor factor = GeometricFactor::VernoldHarvey;
    Radiometry radiometry = Radiometry::Radiance;
};

// out[k] = very_rough_brightness at element k, for k in [0, out.size()). Throws InvalidArgument
// "element <k>: <the scalar function's message>" for the first bad element (angle names are
// theta_i/theta_s/phi_s, or theta_i_deg/... for degrees); `out` is then unspecified. Input
// spans of a size other than out.size() or 1 are an InvalidArgument too.
void very_rough_brightness_batch(const BrightnessBatchInput& in, std::span<double> out,
                                 const BrightnessBatchModel& model = {});

// The same for elements [begin, end) only (for callers that split the work over threads); out
// still covers every element. On a bad element, `at` is set to it and the scalar function's
// message is thrown without the index.
void very_rough_brightness_batch(const BrightnessBatchInput& in, std::span<double> out,
                                 const BrightnessBatchModel& model, std::size_t begin,
                                 std::size_t end, std::size_t& at);

// Instruction sets of the batch kernel. Its loops are built by the compiler for several
// instruction sets (target clones, the best the processor runs chosen when the library is
// loaded) and once for the baseline alone (Generic); its exponential is glibc's vector math
// library (libmvec) for AVX2 or AVX-512, std::exp for Generic.
enum class VectorIsa { Generic, Avx2, Avx512 };
std::string_view to_string(VectorIsa isa);          // "generic", "avx2", "avx512"
VectorIsa parse_vector_isa(std::string_view name);  // also "best" (= Avx512, capped by the CPU)

// The best instruction set the CPU offers among those compiled in.
VectorIsa cpu_vector_isa();
// The one in use: cpu_vector_isa(), or Generic (the baseline build) when set_vector_isa_cap
// caps it below that (testing and benchmark aid; process-wide, thread-safe). Returns the one now
// in use.
VectorIsa active_vector_isa();
VectorIsa set_vector_isa_cap(VectorIsa cap);

}  // namespace roughscope
