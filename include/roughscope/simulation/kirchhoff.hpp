// Numerical Kirchhoff scattering on random rough surfaces (paper §3.1): the ground truth that the
// closed forms of scattering/beckmann.hpp approximate.
//
// Beckmann's scalar Kirchhoff field scattered by a patch of area A of the surface z(x, y) is
//   ρ(v) = (F/A) ∫∫ exp(i v·r) dx dy,  r = (x, y, z(x, y)),                        (§3.1)
// with v the scattering vector of scattering/factors.hpp and F the geometric factor; a smooth
// plate gives ρ = 1 in the specular direction. On a sampled surface (nx × ny heights, spacings
// dx, dy, coordinates centred on the patch) the integral is its Riemann sum:
//   I(v) = (1/A) Σ_k dx dy exp(i (v_x x_k + v_y y_k + v_z z_k)),  A = nx dx · ny dy,  ρ = F I.
// Over an ensemble of surfaces, Eq. 1 splits the mean power into the coherent part |⟨ρ⟩|²
// (= F² ρ0² e^{−g}) and the diffuse part D = ⟨|ρ − ⟨ρ⟩|²⟩ (Eq. 2 and the exact exponential
// series). simulate_scattering estimates both, with standard errors, from generated surfaces
// (surface/generate.hpp). Method, convergence and what is exact: docs/simulation.md.
//
// Units: lengths in µm, wavenumbers in rad/µm, angles in radians (the library's convention).
#pragma once

#include <complex>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/factors.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/surface/height_map.hpp"

namespace roughscope::simulation {

// ---------------------------------------------------------------------------------------------
// One surface: the scattering integral I = ρ/F.

// I on the whole lattice v_xy = 2π (i/Lx, j/Ly) (signed i, j; Lx = nx dx, Ly = ny dy) for one
// v_z: the 2-D DFT of exp(i v_z z), one FFT for every direction of that v_z.
struct LatticeField {
    std::size_t nx = 0, ny = 0;
    double dvx_per_um = 0.0, dvy_per_um = 0.0;  // lattice steps 2π/Lx, 2π/Ly
    double vz_per_um = 0.0;
    // I at signed indices (i, j), stored in FFT order: values[jj·nx + ii] with ii = i mod nx,
    // jj = j mod ny. at(i, j) does the wrapping; with the centred coordinates the Nyquist index
    // of an even side is +n/2 (the value at −n/2 differs by the factor e^{iπ(n−1)} = −1).
    std::vector<std::complex<double>> values;
    std::complex<double> at(long i, long j) const;
    double vx_per_um(long i) const { return dvx_per_um * static_cast<double>(i); }
    double vy_per_um(long j) const { return dvy_per_um * static_cast<double>(j); }
};

// InvalidArgument when the map has missing points (NaN) or v_z is not finite.
LatticeField scattering_integral_lattice(const surface::HeightMap& map, double vz_per_um);

// I at one arbitrary v by direct summation (exact; separable, O(nx·ny)). On the lattice it equals
// scattering_integral_lattice up to rounding. InvalidArgument for missing points or a non-finite v.
std::complex<double> scattering_integral_at(const surface::HeightMap& map,
                                            const ScatteringVector& v);

// ---------------------------------------------------------------------------------------------
// Ensembles: Monte Carlo estimates of the coherent and diffuse power at given geometries.

// How the simulated patch is laid out for a direction.
enum class PatchLayout {
    // Default. The surfaces are isotropic, so the frame is turned until v_xy lies along +x, and the
    // spacing is adjusted (by at most half a lattice step of v_xy: a relative change ≤ 1/(2m)
    // when v_xy is the m-th lattice frequency) so that v_xy falls exactly on the lattice. With
    // the periodic surfaces of the generator the Monte Carlo mean is then the Riemann sum of the
    // infinite-patch integral: no finite-patch leakage from the coherent peak.
    LatticeAligned,
    // The spacing and the frame are kept; I is evaluated at v by direct summation over an
    // n × n patch cut from a generated surface of side 2n (so that the patch is a finite piece
    // of an unbounded surface, not one period of a periodic one). The finite patch shows: the
    // coherent peak ρ0 (a Dirichlet kernel) leaks into nearby directions and the diffuse part is
    // the infinite-patch one convolved with the patch's window (bias ~T/L). n ≤ 2048.
    Fixed,
};

struct ScatterOptions {
    Correlation correlation = Correlation::Gaussian;
    double sigma_um = 0.1;         // RMS height σ
    double T_um = 1.0;             // correlation length T
    double wavelength_um = 0.555;  // λ (the paper's mean wavelength)
    // F multiplying the field (ρ = F I) and the closed form; Beckmann's F_Beck (Eq. 6) by default
    // (for the others F = √F²).
    GeometricFactor factor = GeometricFactor::Beckmann;
    // Grid: n × n points with spacing dx. 0 = chosen from the geometry (docs/simulation.md,
    // "Choosing the grid"): dx resolves the kernel of the diffuse integral at this g and v_xy
    // (its spectrum's nearest alias below 0.3 % of its value at v_xy), and the patch side n·dx is
    // patch_over_T · T.
    std::size_t n = 0;
    double dx_um = 0.0;
    // The patch side in units of T when n is chosen; 0 = chosen: 6 for Gaussian correlation, and
    // for exponential max(8, ln(4·max(g, 1)/0.003)), where the periodic surface's images change
    // the kernel e^{−g(1−C)} by less than 0.3 %. Otherwise in [1, 1e4].
    double patch_over_T = 0.0;
    std::size_t realisations = 100;  // ≥ 10 (a standard error needs them; docs/simulation.md)
    std::uint64_t seed = 1;
    PatchLayout layout = PatchLayout::LatticeAligned;
    // Worker threads (0 = the hardware's); at most the hardware's and what the memory budget
    // holds (scatter_memory) are run. Results do not depend on it: realisation r of geometry k
    // always uses the surface of seed (seed, k, r) and sums run in a fixed order.
    unsigned threads = 0;
};

struct ScatterResult {
    Geometry geometry;
    double g = 0.0;      // σ² v_z²
    double T_vxy = 0.0;  // T·|v_xy|
    double F2 = 0.0;     // F² of the chosen factor
    // Monte Carlo estimates with their standard errors:
    //   diffuse  = (1/(R−1)) Σ_r |ρ_r − ρ̄|²  (the unbiased sample variance of the field)
    //   coherent = |ρ̄|² − diffuse/R          (unbiased for |⟨ρ⟩|²; may be slightly negative
    //                                          where |⟨ρ⟩|² is far below its standard error)
    double diffuse = 0.0;
    double diffuse_stderr = 0.0;
    double coherent = 0.0;
    double coherent_stderr = 0.0;
    // The closed forms at the same geometry with the same F and the simulated patch's area
    // A = (n·dx)²: the exact series (Eq. 2, or the exact exponential series) and F² ρ0² e^{−g}
    // with ρ0 of the simulated square patch (0 on every lattice direction but v_xy = 0).
    double series_diffuse = 0.0;
    double series_coherent = 0.0;
    // The grid actually simulated.
    std::size_t n = 0;
    double dx_um = 0.0;
    double area_um2 = 0.0;
    std::size_t realisations = 0;
    PatchLayout layout = PatchLayout::LatticeAligned;
    long lattice_index = 0;  // m with |v_xy| = 2πm/(n·dx) (LatticeAligned), else 0
};

// Called from the calling thread after each realisation completes with (done, total) over all
// geometries; it may throw to stop the run (the exception propagates, nothing is returned).
using ProgressCallback = std::function<void(std::size_t done, std::size_t total)>;

// Validates the options (InvalidArgument naming the option and its valid range): σ, T, λ in the
// library's length range; n = 0 or 8 ≤ n ≤ 4096; dx = 0 or in the length range with T ≤ n·dx;
// patch_over_T = 0 or in [1, 1e4]; realisations in [10, 1e7].
void check_scatter_options(const ScatterOptions& options);

// The grid (n, dx) simulate_scattering uses at `geom` (before lattice alignment).
struct ScatterGrid {
    std::size_t n = 0;
    double dx_um = 0.0;
};
ScatterGrid choose_scatter_grid(const Geometry& geom, const ScatterOptions& options);

// The grid simulate_scattering will use at one geometry (the fields of ScatterResult of the same
// names) and the side of the surface it generates per realisation (n, or 2n for the fixed
// layout): the work of a realisation grows like generated_n² log generated_n.
struct ScatterPlanSummary {
    std::size_t n = 0;
    double dx_um = 0.0;
    std::size_t generated_n = 0;
    PatchLayout layout = PatchLayout::LatticeAligned;
    long lattice_index = 0;
};

// Everything simulate_scattering validates before the first realisation, without generating a
// surface: the options (check_scatter_options), each geometry (check::geometry) and the grid
// chosen or given there (n ≤ 4096, dx below the Nyquist limit π/|v_xy|, n·dx ≥ T) and the memory
// of the run with one worker thread (scatter_memory). Throws the same InvalidArgument
// simulate_scattering would; a run that passes it fails only on interruption. Returns the grid of
// each geometry. Cheap (no surface, no FFT).
std::vector<ScatterPlanSummary> check_scattering_run(const std::vector<Geometry>& geometries,
                                                     const ScatterOptions& options);

// The memory a run of simulate_scattering needs (docs/simulation.md, "Memory and threads"):
// fixed_bytes whatever the threads (each geometry's filter and the fields of its realisations)
// and per_thread_bytes for each worker thread (the surface it generates, in its FFT buffer).
// check_scattering_run refuses a run whose fixed part and one thread exceed the memory budget
// (core/memory.hpp); simulate_scattering runs at most as many threads as the hardware has and
// the budget holds.
struct ScatterMemory {
    double fixed_bytes = 0.0;
    double per_thread_bytes = 0.0;
};
ScatterMemory scatter_memory(const std::vector<ScatterPlanSummary>& plans,
                             const ScatterOptions& options);

// The ensemble at each geometry (validated as by check::geometry).
std::vector<ScatterResult> simulate_scattering(const std::vector<Geometry>& geometries,
                                               const ScatterOptions& options,
                                               const ProgressCallback& progress = {});
ScatterResult simulate_scattering(const Geometry& geom, const ScatterOptions& options);

std::string_view to_string(PatchLayout layout);  // "lattice_aligned", "fixed"
PatchLayout parse_patch_layout(std::string_view name);

}  // namespace roughscope::simulation
