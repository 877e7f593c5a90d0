// Numerical Kirchhoff scattering on generated surfaces (kirchhoff.hpp; docs/simulation.md).
#include "roughscope/simulation/kirchhoff.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <complex>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "phasor.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/memory.hpp"
#include "roughscope/core/names.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/surface/generate.hpp"
#include "surface/fft.hpp"

namespace roughscope::simulation {

namespace {

using cd = std::complex<double>;

constexpr std::size_t kMinGridSide = 8;
constexpr std::size_t kMaxGridSide = 4096;  // 2^24 points: 128 MB of heights
constexpr std::size_t kMaxRealisations = 10'000'000;
// Fewest realisations for a standard error worth the name: with 2 the samples d_r are equal (the
// two fields are ±(ρ1 − ρ2)/2 from their mean) and the error is 0; the interval ±3 standard
// errors covers the exact series in 94-95 % of runs from 10 realisations (docs/simulation.md,
// "Realisations"), 67-78 % at 3.
constexpr std::size_t kMinRealisations = 10;
// The automatic spacing resolves the diffuse kernel until the nearest alias of its spectrum is
// below kAliasTolerance of the value at v_xy (times ~9, the lattice sum Σ 1/|a|³ of all aliases
// of an algebraic tail); the spacing never goes below 2π·T/kMaxKT. The automatic patch keeps the
// periodic images' change of the kernel, ~4·g·C(L), below the same tolerance.
constexpr double kAliasTolerance = 3e-3;
constexpr double kAliasLatticeSum = 9.0;
constexpr double kMaxKT = 2048.0;

void check_grid_side(std::size_t n) {
    if (n != 0 && (n < kMinGridSide || n > kMaxGridSide)) {
        throw InvalidArgument(concat("simulation option n = ", std::to_string(n),
                                     " is out of range: it must be 0 (chosen from the geometry) "
                                     "or an integer in [8, 4096]"));
    }
}

void check_map(const surface::HeightMap& map) {
    surface::validate(map, "heights");
    for (const double z : map.heights_um) {
        if (!std::isfinite(z)) {
            throw InvalidArgument(
                "the scattering integral needs a complete height map: this one has missing "
                "(NaN) points; fill or crop them first");
        }
    }
}

// a·b and a·conj(b) without the NaN/inf recovery of std::complex's operator* (a library call per
// product under GCC's default -fcx-fortran-rules off): the operands here are always finite.
inline cd mul(cd a, cd b) {
    return {a.real() * b.real() - a.imag() * b.imag(), a.real() * b.imag() + a.imag() * b.real()};
}
inline cd mul_conj(cd a, cd b) {
    return {a.real() * b.real() + a.imag() * b.imag(), a.imag() * b.real() - a.real() * b.imag()};
}

// SplitMix64's finaliser: the seed of realisation r of geometry k is h(h(h(seed) + k) + r).
std::uint64_t mix(std::uint64_t x) {
    x += 0x9e3779b97f4a7c15ULL;
    x = (x ^ (x >> 30U)) * 0xbf58476d1ce4e5b9ULL;
    x = (x ^ (x >> 27U)) * 0x94d049bb133111ebULL;
    return x ^ (x >> 31U);
}

// exp(i·u·x_k) for the centred coordinates x_k = (k − (n−1)/2)·d, k = 0..n−1.
std::vector<cd> centred_phases(std::size_t n, double u, double d) {
    std::vector<cd> out(n);
    const double c = 0.5 * static_cast<double>(n - 1);
    for (std::size_t k = 0; k < n; ++k) {
        const double x = (static_cast<double>(k) - c) * d;
        out[k] = std::polar(1.0, u * x);
    }
    return out;
}

// The diffuse kernel's spectrum shape: the series sum without its prefactor.
double series_shape(Correlation c, double g, double T2_vxy2) {
    return diffuse_series_sum(c, g, T2_vxy2);
}

// ρ0 of a sampled square patch: the Dirichlet kernel Π sin(n u d/2)/(n sin(u d/2)) (→ the
// continuous sinc(u X) of §3.1 as d → 0 with n·d = 2X fixed).
double dirichlet(double u, std::size_t n, double d) {
    const double h = 0.5 * u * d;
    const double s = std::sin(h);
    if (std::abs(s) < 1e-300) {
        return 1.0;  // on a multiple of the lattice's period: every sample in phase
    }
    return std::sin(static_cast<double>(n) * h) / (static_cast<double>(n) * s);
}

// Whether the sampling frequency K = 2π/dx (as K·T) resolves the diffuse kernel at g and T·|v_xy|:
// the nearest alias of its spectrum, at K − |v_xy|, times the lattice sum of all aliases, is
// below kAliasTolerance of the spectrum at v_xy.
bool kernel_resolved(Correlation c, double g, double wT, double KT) {
    const double target = series_shape(c, g, wT * wT);
    const double a = KT - wT;
    return a > 0.0 && kAliasLatticeSum * series_shape(c, g, a * a) <= kAliasTolerance * target;
}

// InvalidArgument for a surface too rough for the finest automatic grid (K·T = kMaxKT): at large
// g the Gaussian kernel's spectrum is about exp(−T²v²/(4g))/g, a width 2√g/T that the spacing
// 2π·T/kMaxKT no longer samples (docs/simulation.md, "Choosing the grid"); the aliased Riemann sum
// would be a confident wrong number. The message gives the largest g (and σ) resolved at this
// geometry.
[[noreturn]] void refuse_unresolved(const ScatterOptions& o, double g, const ScatteringVector& v,
                                    double wT) {
    double lo = std::log(std::min(g, 1e-6)), hi = std::log(g);  // resolved at lo, not at hi
    for (int it = 0; it < 60; ++it) {
        const double mid = 0.5 * (lo + hi);
        (kernel_resolved(o.correlation, std::exp(mid), wT, kMaxKT) ? lo : hi) = mid;
    }
    const double g_max = std::exp(lo);
    throw InvalidArgument(concat(
        "sigma_um = ", format_message(o.sigma_um), " is too rough for the simulation at this ",
        "geometry: g = ", format_message(g), " (sigma_um = ", format_message(o.sigma_um),
        ", wavelength_um = ", format_message(o.wavelength_um), ") needs a grid spacing below T/",
        format_message(kMaxKT / (2.0 * kPi)), " to sample the diffuse kernel (",
        to_string(o.correlation), " correlation) without aliasing; valid: g up to ",
        format_message(g_max), " here, sigma_um up to about ",
        format_message(std::sqrt(g_max) / std::abs(v.vz)), " um (or give dx_um and nx)"));
}

// What one geometry needs: the directions evaluated per realisation and the constants.
struct Plan {
    Geometry geometry;
    ScatteringVector v;
    double F = 0.0, F2 = 0.0;
    std::size_t n = 0;
    double dx_um = 0.0;
    PatchLayout layout = PatchLayout::LatticeAligned;
    long m = 0;
    // Direction evaluation: kind 0 = v_xy = 0 (one direction); 1 = the four lattice directions
    // (±m, 0), (0, ±m); 2 = one arbitrary (vx, vy) (Fixed).
    int kind = 0;
    std::vector<cd> ex, ey;  // centred phase tables along x and y
    // Side of the generated periodic surface: n, or 2n for the Fixed layout, whose n × n patch
    // is a corner of it, so that points near opposite edges of the patch are not the periodic
    // neighbours they would be on an n-periodic surface (a finite patch of an unbounded surface).
    std::size_t generated_n = 0;
    std::size_t directions() const { return kind == 1 ? 4 : 1; }
};

Plan make_plan(const Geometry& geom, const ScatterOptions& o) {
    Plan p;
    p.geometry = geom;
    p.v = scattering_vector(geom, o.wavelength_um);
    p.F2 = geometric_factor_squared(o.factor, geom);
    p.F = std::sqrt(p.F2);
    const ScatterGrid grid = choose_scatter_grid(geom, o);
    p.n = grid.n;
    p.dx_um = grid.dx_um;
    const double w = std::sqrt(p.v.vxy2());
    const double L = static_cast<double>(p.n) * p.dx_um;
    if (w * p.dx_um >= kPi) {
        throw InvalidArgument(
            concat("simulation spacing dx_um = ", format_message(p.dx_um),
                   " is too coarse for this direction: |v_xy| = ", format_message(w),
                   " rad/um lies beyond the grid's Nyquist frequency pi/dx; give dx_um below ",
                   format_message(kPi / w), " um (or 0 to choose it)"));
    }
    p.layout = o.layout;
    if (w == 0.0) {
        p.kind = 0;
        p.layout = o.layout;
    } else if (o.layout == PatchLayout::LatticeAligned) {
        const double m_real = w * L / (2.0 * kPi);
        p.m = std::lround(m_real);
        if (p.m == 0) {
            // Inside the first lattice cell: no lattice direction is near v_xy; evaluate exactly.
            p.layout = PatchLayout::Fixed;
        } else {
            p.dx_um = 2.0 * kPi * static_cast<double>(p.m) / (static_cast<double>(p.n) * w);
            p.kind = 1;
            p.ex = centred_phases(p.n, w, p.dx_um);
        }
    }
    if (w != 0.0 && p.layout == PatchLayout::Fixed) {
        p.m = 0;
        p.kind = 2;
        p.ex = centred_phases(p.n, p.v.vx, p.dx_um);
        p.ey = centred_phases(p.n, p.v.vy, p.dx_um);
    }
    p.generated_n = p.layout == PatchLayout::Fixed ? 2 * p.n : p.n;
    if (p.generated_n > kMaxGridSide) {
        throw InvalidArgument(concat("simulation option nx = ", std::to_string(p.n),
                                     " is too large for the fixed layout, which generates a "
                                     "surface of twice the side: it must be at most 2048"));
    }
    return p;
}

// I at the plan's directions for the n × n patch at the start of a surface with row stride
// `stride` (heights z, row-major), into out[0..J).
void evaluate(const Plan& p, const double* z, std::size_t stride, cd* out) {
    const std::size_t n = p.n;
    const double vz = p.v.vz;
    const double norm = 1.0 / (static_cast<double>(n) * static_cast<double>(n));
    const detail::PhasorTable& table = detail::phasor_table();
    cd s0{}, s1{}, s2{}, s3{};
    for (std::size_t iy = 0; iy < n; ++iy) {
        const double* row = z + iy * stride;
        cd r0{}, rp{}, rm{};
        for (std::size_t ix = 0; ix < n; ++ix) {
            const cd e = detail::unit_phasor(vz * row[ix], table);
            if (p.kind == 0) {
                r0 += e;
            } else if (p.kind == 1) {
                r0 += e;
                rp += mul(e, p.ex[ix]);
                rm += mul_conj(e, p.ex[ix]);
            } else {
                rp += mul(e, p.ex[ix]);
            }
        }
        if (p.kind == 0) {
            s0 += r0;
        } else if (p.kind == 1) {
            s0 += rp;                      // (+m, 0)
            s1 += rm;                      // (−m, 0)
            s2 += mul(r0, p.ex[iy]);       // (0, +m)
            s3 += mul_conj(r0, p.ex[iy]);  // (0, −m)
        } else {
            s0 += mul(rp, p.ey[iy]);
        }
    }
    out[0] = s0 * norm;
    if (p.kind == 1) {
        out[1] = s1 * norm;
        out[2] = s2 * norm;
        out[3] = s3 * norm;
    }
}

ScatterResult summarise(const Plan& p, const ScatterOptions& o, const std::vector<cd>& fields) {
    const std::size_t J = p.directions();
    const std::size_t R = fields.size() / J;
    const double Rd = static_cast<double>(R);
    std::vector<cd> mean(J);
    for (std::size_t r = 0; r < R; ++r) {
        for (std::size_t j = 0; j < J; ++j) mean[j] += p.F * fields[r * J + j];
    }
    for (cd& m : mean) m /= Rd;
    // Per-realisation diffuse samples d_r (the J directions averaged), unbiased for D.
    double sum = 0.0, sum2 = 0.0;
    std::vector<double> d(R);
    for (std::size_t r = 0; r < R; ++r) {
        double acc = 0.0;
        for (std::size_t j = 0; j < J; ++j) acc += std::norm(p.F * fields[r * J + j] - mean[j]);
        d[r] = acc / static_cast<double>(J) * Rd / (Rd - 1.0);
        sum += d[r];
    }
    const double diffuse = sum / Rd;
    for (const double x : d) sum2 += (x - diffuse) * (x - diffuse);
    ScatterResult res;
    res.geometry = p.geometry;
    res.g = roughness_g(o.sigma_um, p.v.vz);
    res.T_vxy = o.T_um * std::sqrt(p.v.vxy2());
    res.F2 = p.F2;
    res.diffuse = diffuse;
    res.diffuse_stderr = std::sqrt(sum2 / (Rd - 1.0) / Rd);
    double coherent = 0.0, coherent_var = 0.0;
    for (const cd& m : mean) {
        const double c = std::norm(m) - diffuse / Rd;
        coherent += c;
        coherent_var +=
            2.0 * std::max(std::norm(m), 0.0) * diffuse / Rd + (diffuse / Rd) * (diffuse / Rd);
    }
    res.coherent = coherent / static_cast<double>(J);
    res.coherent_stderr = std::sqrt(coherent_var) / static_cast<double>(J);
    res.n = p.n;
    res.dx_um = p.dx_um;
    const double L = static_cast<double>(p.n) * p.dx_um;
    res.area_um2 = L * L;
    res.realisations = R;
    res.layout = p.layout;
    res.lattice_index = p.m;
    res.series_diffuse =
        diffuse_power_series(o.correlation, p.F2, o.T_um, res.area_um2, res.g, p.v.vxy2());
    double rho0 = 1.0;
    if (p.kind == 1) {
        rho0 = 0.0;  // a nonzero lattice frequency: the plate's sum vanishes
    } else if (p.kind == 2) {
        rho0 = dirichlet(p.v.vx, p.n, p.dx_um) * dirichlet(p.v.vy, p.n, p.dx_um);
    }
    res.series_coherent = p.F2 * rho0 * rho0 * std::exp(-res.g);
    return res;
}

}  // namespace

// ---------------------------------------------------------------------------------------------

std::complex<double> LatticeField::at(long i, long j) const {
    const auto wrap = [](long k, std::size_t n) {
        const long nn = static_cast<long>(n);
        return static_cast<std::size_t>(((k % nn) + nn) % nn);
    };
    return values[wrap(j, ny) * nx + wrap(i, nx)];
}

LatticeField scattering_integral_lattice(const surface::HeightMap& map, double vz_per_um) {
    check_map(map);
    check::finite("v_z", vz_per_um);
    const std::size_t count = map.nx * map.ny;
    LatticeField out;
    out.nx = map.nx;
    out.ny = map.ny;
    out.dvx_per_um = 2.0 * kPi / (static_cast<double>(map.nx) * map.dx_um);
    out.dvy_per_um = 2.0 * kPi / (static_cast<double>(map.ny) * map.dy_um);
    out.vz_per_um = vz_per_um;
    out.values.resize(count);
    cd* data = out.values.data();
    // FFTW's forward transform has e^{−i}; I wants e^{+i v·r}: transform the conjugate
    // exp(−i v_z z) in place and conjugate back, then shift to centred coordinates (a phase per
    // lattice index) and normalise by the number of points (dx dy / A = 1/(nx ny)).
    surface::fft::ComplexPlane plane(map.ny, map.nx, data);
    const detail::PhasorTable& table = detail::phasor_table();
    for (std::size_t k = 0; k < count; ++k) {
        data[k] = detail::unit_phasor(-vz_per_um * map.heights_um[k], table);
    }
    plane.forward();
    const double norm = 1.0 / static_cast<double>(count);
    const double cx = 0.5 * static_cast<double>(map.nx - 1);
    const double cy = 0.5 * static_cast<double>(map.ny - 1);
    std::vector<cd> shift_x(map.nx), shift_y(map.ny);
    for (std::size_t i = 0; i < map.nx; ++i) {
        const long si = i <= map.nx / 2 ? static_cast<long>(i)
                                        : static_cast<long>(i) - static_cast<long>(map.nx);
        shift_x[i] = std::polar(
            1.0, -2.0 * kPi * static_cast<double>(si) * cx / static_cast<double>(map.nx));
    }
    for (std::size_t j = 0; j < map.ny; ++j) {
        const long sj = j <= map.ny / 2 ? static_cast<long>(j)
                                        : static_cast<long>(j) - static_cast<long>(map.ny);
        shift_y[j] = std::polar(
            1.0, -2.0 * kPi * static_cast<double>(sj) * cy / static_cast<double>(map.ny));
    }
    for (std::size_t j = 0; j < map.ny; ++j) {
        const cd row_factor = norm * shift_y[j];
        cd* row = data + j * map.nx;
        for (std::size_t i = 0; i < map.nx; ++i) {
            row[i] = mul(std::conj(row[i]), mul(row_factor, shift_x[i]));
        }
    }
    return out;
}

std::complex<double> scattering_integral_at(const surface::HeightMap& map,
                                            const ScatteringVector& v) {
    check_map(map);
    check::finite("v_x", v.vx);
    check::finite("v_y", v.vy);
    check::finite("v_z", v.vz);
    const std::vector<cd> ex = centred_phases(map.nx, v.vx, map.dx_um);
    const std::vector<cd> ey = centred_phases(map.ny, v.vy, map.dy_um);
    const detail::PhasorTable& table = detail::phasor_table();
    cd sum{};
    for (std::size_t j = 0; j < map.ny; ++j) {
        cd row_sum{};
        const double* row = map.heights_um.data() + j * map.nx;
        for (std::size_t i = 0; i < map.nx; ++i) {
            row_sum += mul(detail::unit_phasor(v.vz * row[i], table), ex[i]);
        }
        sum += mul(row_sum, ey[j]);
    }
    return sum / (static_cast<double>(map.nx) * static_cast<double>(map.ny));
}

// ---------------------------------------------------------------------------------------------

void check_scatter_options(const ScatterOptions& o) {
    if (!is_valid(o.correlation)) {
        throw InvalidArgument("simulation option correlation is invalid: it must be " +
                              correlation_names_text());
    }
    check_length_um("sigma", o.sigma_um);
    if (!(o.sigma_um <= kMaxLengthUm * 1e-2)) {
        throw InvalidArgument(concat("sigma = ", format_message(o.sigma_um),
                                     " um is out of range for a simulation: it must be at most "
                                     "1e+28 um"));
    }
    check_length_um("T", o.T_um);
    check_length_um("wavelength", o.wavelength_um);
    check_grid_side(o.n);
    if (o.dx_um != 0.0) check_length_um("dx", o.dx_um);
    if (!(o.patch_over_T == 0.0 || (o.patch_over_T >= 1.0 && o.patch_over_T <= 1e4))) {
        throw InvalidArgument(
            concat("simulation option patch_over_T = ", format_message(o.patch_over_T),
                   " is out of range: it must be 0 (chosen) or in [1, 1e4]"));
    }
    if (o.realisations < kMinRealisations || o.realisations > kMaxRealisations) {
        throw InvalidArgument(
            concat("simulation option realisations = ", std::to_string(o.realisations),
                   " is out of range: it must be an integer in [10, 1e7] (fewer give no "
                   "usable standard error: docs/simulation.md, \"Realisations\")"));
    }
    if (o.n != 0 && o.dx_um != 0.0 && !(o.T_um <= static_cast<double>(o.n) * o.dx_um)) {
        throw InvalidArgument(concat(
            "simulation patch nx*dx_um = ", format_message(static_cast<double>(o.n) * o.dx_um),
            " um is shorter than T_um = ", format_message(o.T_um),
            " um: the patch must be at least one correlation length"));
    }
}

ScatterGrid choose_scatter_grid(const Geometry& geom, const ScatterOptions& o) {
    check::geometry(geom);
    const ScatteringVector v = scattering_vector(geom, o.wavelength_um);
    const double w = std::sqrt(v.vxy2());
    const double T = o.T_um;
    const double g = roughness_g(o.sigma_um, v.vz);
    ScatterGrid grid;
    bool unresolved = false;
    if (o.dx_um != 0.0) {
        grid.dx_um = o.dx_um;
    } else {
        // Smallest sampling frequency K = 2π/dx (in steps of 10 %) at which the nearest alias
        // of the kernel's spectrum, at K − |v_xy|, is below kAliasTolerance of its value at v_xy.
        double KT = std::max(2.5 * w * T, 4.0);
        while (KT < kMaxKT && !kernel_resolved(o.correlation, g, w * T, KT)) KT *= 1.1;
        KT = std::min(KT, kMaxKT);
        // (At w·T ≥ K·T/2 the direction itself is beyond the grid's Nyquist frequency, which
        // make_plan reports.) Refused below, after a patch too large for the grid is.
        unresolved = 2.0 * w * T < KT && !kernel_resolved(o.correlation, g, w * T, KT);
        grid.dx_um = 2.0 * kPi * T / KT;
    }
    if (o.n != 0) {
        grid.n = o.n;
    } else {
        double patch_over_T = o.patch_over_T;
        if (patch_over_T == 0.0) {
            patch_over_T = simulation_patch_over_T(o.correlation, g, kAliasTolerance);
        }
        const double want = std::ceil(patch_over_T * T / grid.dx_um);
        if (!(want <= static_cast<double>(kMaxGridSide))) {
            throw InvalidArgument(concat(
                "the simulation grid needed at this geometry (g = ", format_message(g),
                " from sigma_um = ", format_message(o.sigma_um), " and wavelength_um = ",
                format_message(o.wavelength_um), ", T_um*v_xy = ", format_message(w * T), ") has ",
                format_message(want), " points per side with dx_um = ", format_message(grid.dx_um),
                ", beyond the limit of 4096 (nx): give nx and dx_um, or a smaller patch_over_T"));
        }
        grid.n = surface::fft::good_size(std::max(kMinGridSide, static_cast<std::size_t>(want)));
        grid.n = std::min(grid.n, kMaxGridSide);
    }
    if (unresolved) refuse_unresolved(o, g, v, w * T);
    if (!(T <= static_cast<double>(grid.n) * grid.dx_um)) {
        throw InvalidArgument(concat(
            "simulation patch nx*dx_um = ", std::to_string(grid.n), " x ",
            format_message(grid.dx_um), " = ",
            format_message(static_cast<double>(grid.n) * grid.dx_um),
            " um is shorter than T_um = ", format_message(T), " um (",
            o.dx_um != 0.0 ? "dx_um given" : "dx_um chosen to resolve the kernel",
            " at g = ", format_message(g), " from sigma_um = ", format_message(o.sigma_um),
            " and wavelength_um = ", format_message(o.wavelength_um),
            "): the patch must be at least one correlation length; give a larger nx or dx_um"));
    }
    return grid;
}

ScatterMemory scatter_memory(const std::vector<ScatterPlanSummary>& plans,
                             const ScatterOptions& o) {
    ScatterMemory m;
    for (const ScatterPlanSummary& p : plans) {
        const double gn = static_cast<double>(p.generated_n);
        const double half = std::floor(gn / 2.0) + 1.0;
        const double directions =
            p.layout == PatchLayout::LatticeAligned && p.lattice_index != 0 ? 4.0 : 1.0;
        // The generator's filter (surface/generate.cpp: the half spectrum's rows ky >= 0) and
        // the fields of every realisation (16 bytes a direction).
        m.fixed_bytes +=
            8.0 * half * half + 16.0 * static_cast<double>(o.realisations) * directions;
        // A surface in its in-place FFT buffer (ny rows of 2·(nx/2 + 1) doubles), per worker.
        m.per_thread_bytes = std::max(m.per_thread_bytes, 8.0 * gn * 2.0 * half);
    }
    return m;
}

namespace {

// The worker threads of a run: the option's (0 = the hardware's), at most the hardware's and the
// number of realisations, and at most what the memory budget holds (at least one).
unsigned scatter_threads(const ScatterOptions& o, const ScatterMemory& memory, std::size_t jobs) {
    const unsigned hardware = std::max(1U, std::thread::hardware_concurrency());
    std::size_t threads = o.threads != 0 ? std::min(o.threads, hardware) : hardware;
    threads = std::min(threads, std::max<std::size_t>(jobs, 1));
    const double room = memory_budget().bytes - memory.fixed_bytes;
    if (memory.per_thread_bytes > 0.0) {
        const double fit = std::floor(room / memory.per_thread_bytes);
        threads = std::min(threads, static_cast<std::size_t>(std::max(1.0, std::min(fit, 1e6))));
    }
    return static_cast<unsigned>(threads);
}

}  // namespace

std::vector<ScatterPlanSummary> check_scattering_run(const std::vector<Geometry>& geometries,
                                                     const ScatterOptions& o) {
    check_scatter_options(o);
    std::vector<ScatterPlanSummary> out;
    out.reserve(geometries.size());
    for (const Geometry& geom : geometries) {
        const Plan p = make_plan(geom, o);
        out.push_back({p.n, p.dx_um, p.generated_n, p.layout, p.m});
    }
    const ScatterMemory memory = scatter_memory(out, o);
    std::size_t largest = 0;
    for (const ScatterPlanSummary& p : out) largest = std::max(largest, p.generated_n);
    check_memory(
        memory.fixed_bytes + memory.per_thread_bytes,
        concat("the simulation (nx up to ", std::to_string(largest), ": a generated surface of ",
               std::to_string(largest), " x ", std::to_string(largest), " points, ",
               format_gigabytes(memory.per_thread_bytes), " a worker thread; ",
               std::to_string(o.realisations), " realisations at ",
               std::to_string(geometries.size()), " geometries)"),
        "give a smaller nx (or patch_over_T, or a larger dx_um), fewer realisations or "
        "fewer geometries");
    return out;
}

std::vector<ScatterResult> simulate_scattering(const std::vector<Geometry>& geometries,
                                               const ScatterOptions& o,
                                               const ProgressCallback& progress) {
    const ScatterMemory memory = scatter_memory(check_scattering_run(geometries, o), o);
    std::vector<Plan> plans;
    plans.reserve(geometries.size());
    for (const Geometry& geom : geometries) plans.push_back(make_plan(geom, o));

    // One generator per geometry (the filter is computed once, each realisation draws noise).
    std::vector<surface::SurfaceGenerator> generators;
    generators.reserve(plans.size());
    for (const Plan& p : plans) {
        surface::GenerationOptions g;
        g.correlation = o.correlation;
        g.sigma_um = o.sigma_um;
        g.T_um = o.T_um;
        g.nx = g.ny = p.generated_n;
        g.dx_um = g.dy_um = p.dx_um;
        generators.emplace_back(g);
    }
    const std::size_t R = o.realisations;
    std::vector<std::vector<cd>> fields(plans.size());
    for (std::size_t k = 0; k < plans.size(); ++k) fields[k].resize(R * plans[k].directions());
    const std::size_t total = plans.size() * R;

    std::atomic<std::size_t> next{0}, done{0};
    std::atomic<bool> stop{false};
    std::exception_ptr failure;
    std::mutex failure_mutex;
    auto work = [&](bool caller) {
        try {
            while (!stop.load(std::memory_order_relaxed)) {
                const std::size_t job = next.fetch_add(1);
                if (job >= total) break;
                const std::size_t k = job / R, r = job % R;
                const Plan& p = plans[k];
                const surface::HeightMap map =
                    generators[k].generate(mix(mix(mix(o.seed) + k) + r));
                evaluate(p, map.heights_um.data(), p.generated_n,
                         fields[k].data() + r * p.directions());
                const std::size_t finished = done.fetch_add(1) + 1;
                if (caller && progress) progress(finished, total);
            }
        } catch (...) {
            stop = true;
            const std::lock_guard<std::mutex> lock(failure_mutex);
            if (!failure) failure = std::current_exception();
        }
    };
    const unsigned threads = scatter_threads(o, memory, total);
    std::vector<std::thread> pool;
    for (unsigned t = 1; t < threads; ++t) pool.emplace_back(work, false);
    work(true);
    for (std::thread& t : pool) t.join();
    if (failure) std::rethrow_exception(failure);
    if (progress) progress(total, total);

    std::vector<ScatterResult> out;
    out.reserve(plans.size());
    for (std::size_t k = 0; k < plans.size(); ++k) out.push_back(summarise(plans[k], o, fields[k]));
    return out;
}

ScatterResult simulate_scattering(const Geometry& geom, const ScatterOptions& options) {
    return simulate_scattering(std::vector<Geometry>{geom}, options).front();
}

namespace {
constexpr std::array<NameEntry<PatchLayout>, 2> kLayoutNames{{
    {"lattice_aligned", PatchLayout::LatticeAligned},
    {"fixed", PatchLayout::Fixed},
}};
}  // namespace

std::string_view to_string(PatchLayout layout) { return name_of(kLayoutNames, layout); }
PatchLayout parse_patch_layout(std::string_view name) {
    return parse_name(kLayoutNames, "patch layout", name);
}

}  // namespace roughscope::simulation
