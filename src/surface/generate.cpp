// Random rough surfaces by Fourier filtering of white noise (generate.hpp). Method, and what is
// exact and what is not: docs/surface-generation.md.
#include "roughscope/surface/generate.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include <boost/random/mersenne_twister.hpp>
#include <boost/random/normal_distribution.hpp>

#include "fft.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/memory.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/core/text.hpp"

namespace roughscope::surface {

namespace {

constexpr double kPi = 3.14159265358979323846;

// Standard normal deviates: Boost.Random's normal_distribution (the ziggurat method) driven by
// boost::random::mt19937_64 (the standard's mt19937_64 sequence). Unlike std::normal_distribution,
// whose algorithm each standard library chooses, Boost's algorithm is fixed by its source, so a
// seed gives the same deviates wherever the same Boost version is used (the table construction
// and the tails use exp/log: machines whose libm rounds differently could differ in the last bit).
class NormalStream {
  public:
    explicit NormalStream(std::uint64_t seed) : engine_(seed) {}
    // The next n deviates into out[0..n), in order.
    void fill(double* out, std::size_t n) {
        for (std::size_t i = 0; i < n; ++i) {
            out[i] = normal_(engine_);
        }
    }

  private:
    boost::random::mt19937_64 engine_;
    boost::random::normal_distribution<double> normal_;
};

std::string size_message(const char* name, std::size_t value, const char* rule) {
    std::string message = "generation option ";
    message.append(name).append(" = ").append(std::to_string(value)).append(" is invalid: ");
    message.append(rule);
    return message;
}

// Everything but the correlation and T (which the PSD route does not use).
void check_in_range(const char* name, double value, double lo, double hi) {
    if (!(value >= lo && value <= hi)) {
        std::string message = "generation option ";
        message.append(name)
            .append(" = ")
            .append(format_message(value))
            .append(" is out of range: it must be in [")
            .append(format_message(lo))
            .append(", ")
            .append(format_message(hi))
            .append("] um");
        throw InvalidArgument(message);
    }
}

void check_grid_options(const GenerationOptions& o) {
    // σ at most 1e-2 of the longest length: a Gaussian height beyond 100σ does not occur, so
    // every height stays within the HeightMap's ±1e30 µm.
    check_in_range("sigma_um", o.sigma_um, kMinLengthUm, kMaxLengthUm * 1e-2);
    check_in_range("dx_um", o.dx_um, kMinLengthUm, kMaxLengthUm);
    check_in_range("dy_um", o.dy_um, kMinLengthUm, kMaxLengthUm);
    if (o.nx < 2 || o.nx > kMaxHeightMapPoints) {
        throw InvalidArgument(size_message("nx", o.nx, "it must be an integer in [2, 2^28]"));
    }
    if (o.ny < 1 || o.ny > kMaxHeightMapPoints / o.nx) {
        throw InvalidArgument(
            size_message("ny", o.ny, "it must be >= 1 (1 = a profile) with nx·ny <= 2^28 points"));
    }
    check_memory(generation_memory_bytes(o),
                 concat("a generated surface of nx x ny = ", std::to_string(o.nx), " x ",
                        std::to_string(o.ny), " points"),
                 "give a smaller nx or ny");
}

void check_options(const GenerationOptions& o) {
    if (!is_valid(o.correlation)) {
        throw InvalidArgument("generation option correlation is invalid: it must be " +
                              correlation_names_text());
    }
    check_in_range("T_um", o.T_um, kMinLengthUm, kMaxLengthUm);
    check_grid_options(o);
    // The periodised target sums the ACF over the images of the map within the distance where
    // it falls below 1e-18 (fill_periodised_acf): T far beyond the map's size would need
    // millions of images per lag. T up to the map's shorter side is allowed (a surface with
    // T > L is a random tilt and offset at the map's scale, not a rough surface).
    const double lx = static_cast<double>(o.nx) * o.dx_um;
    const double l_min = o.ny == 1 ? lx : std::min(lx, static_cast<double>(o.ny) * o.dy_um);
    if (!(o.T_um <= l_min)) {
        std::string message = "generation option T_um = ";
        message.append(format_message(o.T_um))
            .append(" is out of range: it must not exceed the map's ")
            .append(o.ny == 1 ? "length nx·dx_um = " : "shorter side min(nx·dx_um, ny·dy_um) = ")
            .append(format_message(l_min))
            .append(" um");
        throw InvalidArgument(message);
    }
}

// Offsets u + m·period (m integer) within r_max of 0: the periodic images of lag u that matter.
std::vector<double> images_within(double u, double period, double r_max, bool periodic) {
    std::vector<double> out;
    if (!periodic) {
        out.push_back(u);
        return out;
    }
    const auto first = static_cast<long>(std::ceil((-r_max - u) / period));
    const auto last = static_cast<long>(std::floor((r_max - u) / period));
    for (long m = first; m <= last; ++m) {
        out.push_back(u + static_cast<double>(m) * period);
    }
    return out;
}

// Fills f's real array with the target ACF C(τ) sampled on the lattice and periodised with the
// map's periods Lx = nx dx, Ly = ny dy: C_p(τ) = Σ_{m,n} C(τ + (m Lx, n Ly)), normalised to
// C_p(0) = 1 (it exceeds 1 by the images' overlap, e.g. by 2e^{−L/T} for an exponential ACF).
// Images farther than r_max, where C < 1e−18, are left out.
void fill_periodised_acf(const GenerationOptions& o, fft::RealToComplex& f) {
    const Correlation c = o.correlation;
    const double T = o.T_um;
    constexpr double kCutoff = 41.5;  // e^{−41.5} ≈ 1e−18
    const double r_max = T * acf_cutoff_over_T(c, kCutoff);
    const double lx = static_cast<double>(o.nx) * o.dx_um;
    const double ly = static_cast<double>(o.ny) * o.dy_um;
    const bool profile = o.ny == 1;
    // C_p depends on |x| and |y| only: compute the quadrant jx ≤ nx/2, jy ≤ ny/2 and mirror it.
    const std::size_t hx = o.nx / 2;
    const std::size_t hy = o.ny / 2;
    std::vector<std::vector<double>> x_images(hx + 1);
    for (std::size_t jx = 0; jx <= hx; ++jx) {
        x_images[jx] = images_within(static_cast<double>(jx) * o.dx_um, lx, r_max, true);
    }
    if (info(c).separable) {
        // ρ(√(x² + y²)/T) = ρ(|x|/T) ρ(|y|/T) (Gaussian: exp(−(x² + y²)/T²) = exp(−x²/T²)
        // exp(−y²/T²)): C_p is the product of the 1-D sums.
        const auto periodised_1d = [&](const std::vector<double>& images) {
            double sum = 0;
            for (const double u : images) {
                sum += acf(c, std::abs(u) / T);
            }
            return sum;
        };
        std::vector<double> gx(hx + 1);
        for (std::size_t jx = 0; jx <= hx; ++jx) {
            gx[jx] = periodised_1d(x_images[jx]);
        }
        for (std::size_t jy = 0; jy <= hy; ++jy) {
            const double gy = periodised_1d(
                images_within(static_cast<double>(jy) * o.dy_um, ly, r_max, !profile));
            double* row = f.real_row(jy);
            for (std::size_t jx = 0; jx <= hx; ++jx) {
                row[jx] = gx[jx] * gy;
            }
        }
    } else {
        for (std::size_t jy = 0; jy <= hy; ++jy) {
            const std::vector<double> y_images =
                images_within(static_cast<double>(jy) * o.dy_um, ly, r_max, !profile);
            double* row = f.real_row(jy);
            for (std::size_t jx = 0; jx <= hx; ++jx) {
                double sum = 0;
                for (const double xm : x_images[jx]) {
                    for (const double yn : y_images) {
                        const double r2 = xm * xm + yn * yn;
                        if (r2 <= r_max * r_max) {
                            sum += acf(c, std::sqrt(r2) / T);
                        }
                    }
                }
                row[jx] = sum;
            }
        }
    }
    const double c0 = f.real_row(0)[0];
    for (std::size_t jy = 0; jy <= hy; ++jy) {
        double* row = f.real_row(jy);
        for (std::size_t jx = 0; jx <= hx; ++jx) {
            row[jx] /= c0;
        }
        for (std::size_t jx = hx + 1; jx < o.nx; ++jx) {
            row[jx] = row[o.nx - jx];
        }
    }
    for (std::size_t jy = hy + 1; jy < o.ny; ++jy) {
        std::copy_n(f.real_row(o.ny - jy), o.nx, f.real_row(jy));
    }
}

// A height map of the options' grid whose heights_um is, for now, the padded in-place FFT array
// (ny rows of 2·(nx/2 + 1) doubles at a 32-byte aligned offset, for FFTW's fastest codelets):
// the transform works inside the result's own storage, and take_heights() packs the rows in place.
struct MapBuffer {
    HeightMap map;
    std::size_t offset = 0;  // doubles before the aligned array
    std::size_t stride = 0;  // doubles per row of the real array

    explicit MapBuffer(const GenerationOptions& o) {
        map.nx = o.nx;
        map.ny = o.ny;
        map.dx_um = o.dx_um;
        map.dy_um = o.dy_um;
        stride = 2 * (o.nx / 2 + 1);
        assign_large(map.heights_um, o.ny * stride + 4, 0.0);
        const auto misalignment = reinterpret_cast<std::uintptr_t>(map.heights_um.data()) % 32;
        offset = misalignment == 0 ? 0 : (32 - misalignment) / sizeof(double);
    }
    double* array() { return map.heights_um.data() + offset; }
    // Rows of nx heights packed to the front (row r moves from offset + r·stride to r·nx, never
    // forward of itself: memmove in increasing r is safe), the padding dropped.
    HeightMap take_heights() {
        double* const data = map.heights_um.data();
        for (std::size_t r = 0; r < map.ny; ++r)
            std::memmove(data + r * map.nx, data + offset + r * stride, map.nx * sizeof(double));
        map.heights_um.resize(map.nx * map.ny);
        return std::move(map);
    }
};

// The gain's rows: the DFT gain is even in ky (C_p(x, −y) = C_p(x, y), a PSD of |k|), so only the
// rows ky ≥ 0 of the half spectrum are kept, ny/2 + 1 of them; spectrum row r (ky = r for
// r ≤ ny/2, r − ny above) uses gain row min(r, ny − r).
std::size_t gain_rows(std::size_t ny) { return ny / 2 + 1; }
std::size_t gain_row(std::size_t r, std::size_t ny) { return r <= ny / 2 ? r : ny - r; }

// Filters white noise with the half-spectrum `gain` (gain_rows(ny) × (nx/2 + 1), the DFT gain
// including the 1/(nx ny) of the inverse transform) in `f`: z = IDFT(gain · DFT(w)), w i.i.d.
// N(0, 1) drawn in row-major order from the seed; z is left in f's real rows.
void filter_noise(const GenerationOptions& o, const std::vector<double>& gain,
                  fft::RealToComplex& f) {
    NormalStream normal(o.seed);
    for (std::size_t iy = 0; iy < o.ny; ++iy) {
        normal.fill(f.real_row(iy), o.nx);
    }
    f.forward();
    const std::size_t cols = f.spectrum_cols();
    for (std::size_t r = 0; r < o.ny; ++r) {
        std::complex<double>* row = f.spectrum_row(r);
        const double* g = gain.data() + gain_row(r, o.ny) * cols;
        for (std::size_t k = 0; k < cols; ++k) {
            row[k] *= g[k];
        }
    }
    f.backward();
}

// The filtered noise as a height map, transformed inside the map's own storage.
HeightMap filtered_map(const GenerationOptions& o, const std::vector<double>& gain) {
    MapBuffer out(o);
    {
        fft::RealToComplex f(o.ny, o.nx, fft::Layout::plane, out.array());
        filter_noise(o, gain, f);
    }
    return out.take_heights();
}

}  // namespace

namespace {

// The half-spectrum gain of the options' surface, computed in `f`'s buffer (left holding the
// ACF's spectrum). S = DFT(C_p) is real (C_p is even) and ≥ 0 up to rounding (C_p is positive
// definite), so the gain σ√S/(nx ny) gives the periodic surface the ensemble ACF σ² C_p on the
// lattice. S is even in ky: the rows ky ≥ 0 are kept (gain_row).
std::vector<double> generation_gain(const GenerationOptions& o, fft::RealToComplex& f) {
    fill_periodised_acf(o, f);
    f.forward();
    const std::size_t cols = f.spectrum_cols();
    const double points = static_cast<double>(o.nx) * static_cast<double>(o.ny);
    std::vector<double> gain;
    assign_large(gain, gain_rows(o.ny) * cols, 0.0);
    for (std::size_t r = 0; r < gain_rows(o.ny); ++r) {
        const std::complex<double>* row = f.spectrum_row(r);
        for (std::size_t k = 0; k < cols; ++k) {
            gain[r * cols + k] = o.sigma_um * std::sqrt(std::max(row[k].real(), 0.0)) / points;
        }
    }
    return gain;
}

HeightMap titled(HeightMap map, const GenerationOptions& o) {
    map.title = "roughscope generated surface (";
    map.title.append(to_string(o.correlation))
        .append(" correlation, sigma_um = ")
        .append(format_message(o.sigma_um))
        .append(", T_um = ")
        .append(format_message(o.T_um))
        .append(", seed = ")
        .append(std::to_string(o.seed))
        .append(")");
    return map;
}

}  // namespace

double generation_memory_bytes(const GenerationOptions& o) {
    // The in-place FFT buffer that becomes the map (ny rows of 2·(nx/2 + 1) doubles) and the
    // filter's half spectrum (gain_rows(ny) rows of nx/2 + 1).
    const auto half_spectrum_cols = o.nx / 2 + 1;  // r2c: nx/2 + 1 complex columns
    const double cols = static_cast<double>(half_spectrum_cols);
    return 8.0 * cols * (2.0 * static_cast<double>(o.ny) + static_cast<double>(gain_rows(o.ny)));
}

SurfaceGenerator::SurfaceGenerator(const GenerationOptions& options) : options_(options) {
    check_options(options);
    fft::RealToComplex f(options_.ny, options_.nx, fft::Layout::plane);
    gain_ = generation_gain(options_, f);
}

HeightMap SurfaceGenerator::generate(std::uint64_t seed) const {
    GenerationOptions o = options_;
    o.seed = seed;
    return titled(filtered_map(o, gain_), o);
}

HeightMap generate_surface(const GenerationOptions& options) {
    // One surface: the buffer that computed the gain filters the noise too (the same numbers as
    // SurfaceGenerator(options).generate(options.seed), one FFT buffer fewer).
    check_options(options);
    MapBuffer out(options);
    {
        fft::RealToComplex f(options.ny, options.nx, fft::Layout::plane, out.array());
        const std::vector<double> gain = generation_gain(options, f);
        filter_noise(options, gain, f);
    }
    return titled(out.take_heights(), options);
}

HeightMap generate_surface_from_psd(const std::function<double(double k_rad_per_um)>& psd,
                                    const GenerationOptions& options) {
    if (!psd) {
        throw InvalidArgument("generation from a PSD: the PSD function is empty");
    }
    check_grid_options(options);
    const GenerationOptions& o = options;
    const std::size_t cols = o.nx / 2 + 1;  // the half spectrum's columns
    const double dkx = 2 * kPi / (static_cast<double>(o.nx) * o.dx_um);
    const double dky = 2 * kPi / (static_cast<double>(o.ny) * o.dy_um);
    // W at the lattice frequencies of the half spectrum's rows ky ≥ 0 (gain_row: W depends on
    // |k|); the total Σ W over the full spectrum (a half-spectrum column counted twice except at
    // kx = 0 and the Nyquist column, a row ky > 0 twice except the Nyquist row).
    std::vector<double> gain;
    assign_large(gain, gain_rows(o.ny) * cols, 0.0);
    double total = 0;
    for (std::size_t r = 0; r < gain_rows(o.ny); ++r) {
        const double ky = static_cast<double>(r) * dky;
        const double row_weight = (r != 0 && 2 * r != o.ny) ? 2 : 1;
        for (std::size_t k = 0; k < cols; ++k) {
            const double kabs = std::hypot(static_cast<double>(k) * dkx, ky);
            const double w = psd(kabs);
            if (!(std::isfinite(w) && w >= 0)) {
                std::string message = "generation from a PSD: W(k) = ";
                message.append(format_message(w))
                    .append(" at k = ")
                    .append(format_message(kabs))
                    .append(
                        " rad/um is invalid: the PSD must be finite and >= 0 at every "
                        "lattice frequency");
                throw InvalidArgument(message);
            }
            gain[r * cols + k] = w;
            total += row_weight * ((k != 0 && 2 * k != o.nx) ? 2 * w : w);
        }
    }
    if (!(total > 0) || !std::isfinite(total)) {
        throw InvalidArgument(
            "generation from a PSD: W(k) is 0 at every lattice frequency, so "
            "no surface of RMS height sigma_um > 0 has it");
    }
    // Ensemble variance (1/N) Σ |gain·N|² = σ²: gain = σ √(W / Σ W) · √N / N.
    const double points = static_cast<double>(o.nx) * static_cast<double>(o.ny);
    for (double& g : gain) {
        g = o.sigma_um * std::sqrt(g / total) / std::sqrt(points);
    }
    HeightMap map = filtered_map(o, gain);
    map.title = "roughscope generated surface (given PSD, sigma_um = ";
    map.title.append(format_message(o.sigma_um))
        .append(", seed = ")
        .append(std::to_string(o.seed))
        .append(")");
    return map;
}

}  // namespace roughscope::surface
