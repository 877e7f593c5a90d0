// The FFT side of the height statistics (spectral.hpp): 2-D ACF by zero-padded FFT with
// mask-aware pair counts, its radial average, ISO 25178-2 Sal/Str, and the 1-D and radially
// averaged 2-D PSD. Definitions and formulas: docs/surface-generation.md ("Spectral statistics").
#include "roughscope/surface/spectral.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "fft.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/memory.hpp"
#include "roughscope/core/numbers.hpp"

namespace roughscope::surface {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Copies the map into the first rows of the transform's real array, missing points as 0 (the
// rest of the array, the zero padding, stays 0).
void load_heights(const HeightMap& map, fft::RealToComplex& f) {
    f.fill_zero();
    for (std::size_t iy = 0; iy < map.ny; ++iy) {
        const double* src = map.heights_um.data() + iy * map.nx;
        double* dst = f.real_row(iy);
        for (std::size_t ix = 0; ix < map.nx; ++ix) {
            dst[ix] = std::isnan(src[ix]) ? 0.0 : src[ix];
        }
    }
}

void load_mask(const HeightMap& map, fft::RealToComplex& f) {
    f.fill_zero();
    for (std::size_t iy = 0; iy < map.ny; ++iy) {
        const double* src = map.heights_um.data() + iy * map.nx;
        double* dst = f.real_row(iy);
        for (std::size_t ix = 0; ix < map.nx; ++ix) {
            dst[ix] = std::isnan(src[ix]) ? 0.0 : 1.0;
        }
    }
}

// Replaces the spectrum by its squared modulus and transforms back: the real array then holds
// the circular autocorrelation Σ_r a(r) a(r + τ) times the number of points transformed.
void autocorrelate_in_place(fft::RealToComplex& f) {
    f.forward();
    for (std::size_t r = 0; r < f.rows(); ++r) {
        std::complex<double>* row = f.spectrum_row(r);
        for (std::size_t k = 0; k < f.spectrum_cols(); ++k) {
            row[k] = std::norm(row[k]);
        }
    }
    f.backward();
}

// Index of lag j (|j| < period) in a circular array of the given period.
std::size_t wrap(std::ptrdiff_t j, std::size_t period) {
    return j >= 0 ? static_cast<std::size_t>(j) : period - static_cast<std::size_t>(-j);
}

void check_acf(const Acf2d& acf) {
    if (acf.nx == 0 || acf.ny == 0 || acf.nx % 2 == 0 || acf.ny % 2 == 0 ||
        acf.values.size() != acf.nx * acf.ny) {
        throw InvalidArgument(
            "2-D ACF: expected an odd nx × ny lag grid (2·map.nx − 1 by "
            "2·map.ny − 1) with nx·ny values, as acf_2d returns");
    }
    check::positive("2-D ACF dx_um", acf.dx_um, "um");
    check::positive("2-D ACF dy_um", acf.dy_um, "um");
}

// C at fractional lag (ux, uy) in lag units (bilinear); NaN outside the lag grid.
double acf_bilinear(const Acf2d& acf, double ux, double uy) {
    const std::size_t centre_x = acf.nx / 2;  // index of lag 0
    const std::size_t centre_y = acf.ny / 2;
    const auto half_x = static_cast<double>(centre_x);
    const auto half_y = static_cast<double>(centre_y);
    const double gx = ux + half_x;
    const double gy = uy + half_y;
    if (gx < 0 || gy < 0 || gx > static_cast<double>(acf.nx - 1) ||
        gy > static_cast<double>(acf.ny - 1)) {
        return kNaN;
    }
    const auto x0 = std::min(static_cast<std::size_t>(gx), acf.nx > 1 ? acf.nx - 2 : 0);
    const auto y0 = std::min(static_cast<std::size_t>(gy), acf.ny > 1 ? acf.ny - 2 : 0);
    const double tx = acf.nx > 1 ? gx - static_cast<double>(x0) : 0.0;
    const double ty = acf.ny > 1 ? gy - static_cast<double>(y0) : 0.0;
    const std::size_t x1 = acf.nx > 1 ? x0 + 1 : x0;
    const std::size_t y1 = acf.ny > 1 ? y0 + 1 : y0;
    const double c00 = acf.values[y0 * acf.nx + x0];
    const double c10 = acf.values[y0 * acf.nx + x1];
    const double c01 = acf.values[y1 * acf.nx + x0];
    const double c11 = acf.values[y1 * acf.nx + x1];
    return (1 - ty) * ((1 - tx) * c00 + tx * c10) + ty * ((1 - tx) * c01 + tx * c11);
}

// Distance (µm) along the direction (cx, cy) at which C first falls to s, by marching in steps
// of a quarter of the finer spacing and interpolating linearly; none if the ray leaves the lag
// grid or meets a lag without valid pairs first.
std::optional<double> first_crossing(const Acf2d& acf, double cx, double cy, double s) {
    // The ray's direction in lag-index units, (cx/dx, cy/dy), scaled so that one step moves a
    // quarter of a lag along the faster index: the walk leaves the lag grid after at most
    // 4·max(nx, ny) steps whatever the spacings (computed as (cx·dy, cy·dx), which cannot
    // overflow or underflow to 0 for spacings in the HeightMap's range).
    const double a = cx * acf.dy_um;
    const double b = acf.ny == 1 ? 0.0 : cy * acf.dx_um;
    const double longest = std::max(std::abs(a), std::abs(b));
    const double ux = a / longest / 4;
    const double uy = b / longest / 4;
    const double step_um = std::hypot(ux * acf.dx_um, uy * acf.dy_um);
    double previous = 1.0;
    for (std::size_t i = 1;; ++i) {
        const double t = static_cast<double>(i);
        const double c = acf_bilinear(acf, t * ux, t * uy);
        if (std::isnan(c)) {
            return std::nullopt;
        }
        if (c <= s) {
            return (t - 1 + (previous - s) / (previous - c)) * step_um;
        }
        previous = c;
    }
}

}  // namespace

Acf2d acf_2d(const HeightMap& levelled, AcfEstimator estimator) {
    validate(levelled, "levelled map");
    const std::size_t nx = levelled.nx;
    const std::size_t ny = levelled.ny;
    // Zero padding to at least 2n − 1 points per direction: the circular correlation of the padded
    // arrays is then the linear one on every lag (no wrap-around).
    const std::size_t px = fft::good_size(2 * nx - 1);
    const std::size_t py = ny == 1 ? 1 : fft::good_size(2 * ny - 1);
    const double scale = 1.0 / (static_cast<double>(px) * static_cast<double>(py));

    Acf2d acf;
    acf.nx = 2 * nx - 1;
    acf.ny = 2 * ny - 1;
    acf.dx_um = levelled.dx_um;
    acf.dy_um = levelled.dy_um;
    const auto jx_max = static_cast<std::ptrdiff_t>(nx) - 1;
    const auto jy_max = static_cast<std::ptrdiff_t>(ny) - 1;

    // The transform works inside acf.values itself (at a 32-byte aligned offset, for FFTW's
    // fastest codelets): the padded array is rearranged in place into the lag grid afterwards,
    // so the peak memory is one padded array (~4 maps), not the array and the grid side by side.
    const std::size_t stride = 2 * (px / 2 + 1);  // doubles per row of the real array
    std::vector<double>& buffer = acf.values;
    assign_large(buffer, py * stride + 4, 0.0);
    const auto misalignment = reinterpret_cast<std::uintptr_t>(buffer.data()) % 32;
    const std::size_t offset = misalignment == 0 ? 0 : (32 - misalignment) / sizeof(double);
    {
        fft::RealToComplex f(py, px, fft::Layout::plane, buffer.data() + offset);
        // Sums of products R(τ) = Σ_r z(r) z(r + τ) over the valid pairs (missing points are 0).
        load_heights(levelled, f);
        autocorrelate_in_place(f);
    }
    // Circular layout (row wrap(jy), column wrap(jx)) → lag grid (row jy + jy_max, column
    // jx + jx_max): rotate the rows so that the negative lags come first, then each used row's
    // columns likewise, then pack the used (2nx − 1) × (2ny − 1) block to the front.
    double* const base = buffer.data() + offset;
    if (jy_max > 0) {
        std::rotate(base, base + (py - static_cast<std::size_t>(jy_max)) * stride,
                    base + py * stride);
    }
    for (std::size_t r = 0; r < acf.ny; ++r) {
        double* row = base + r * stride;
        if (jx_max > 0) {
            std::rotate(row, row + (px - static_cast<std::size_t>(jx_max)), row + px);
        }
        double* dst = buffer.data() + r * acf.nx;
        for (std::size_t c = 0; c < acf.nx; ++c) {
            dst[c] = row[c] * scale;  // dst ≤ row + c: moving forward is safe
        }
    }
    buffer.resize(acf.nx * acf.ny);

    const double r0 = acf.at_lag(0, 0);
    const std::size_t valid = levelled.count_valid();
    if (!(r0 > 0)) {
        throw InvalidArgument(
            "levelled map: every height is 0 (σ = 0), so its autocorrelation "
            "C(τ) = R(τ)/σ² is undefined");
    }

    // Valid-pair counts N(τ): (nx − |jx|)(ny − |jy|) for a complete map, else the same FFT
    // correlation of the mask (rounded: it is an integer up to rounding) in a second array.
    const bool complete = valid == levelled.size();
    std::unique_ptr<fft::RealToComplex> mask;
    if (!complete) {
        mask = std::make_unique<fft::RealToComplex>(py, px, fft::Layout::plane);
        load_mask(levelled, *mask);
        autocorrelate_in_place(*mask);
    }
    const double mean_square = r0 / static_cast<double>(valid);  // σ² of the valid points
    for (std::ptrdiff_t jy = -jy_max; jy <= jy_max; ++jy) {
        const double* counts = complete ? nullptr : mask->real_row(wrap(jy, py));
        double* row = acf.values.data() + static_cast<std::size_t>(jy + jy_max) * acf.nx;
        for (std::ptrdiff_t jx = -jx_max; jx <= jx_max; ++jx) {
            const double pairs =
                complete ? static_cast<double>((nx - static_cast<std::size_t>(std::abs(jx))) *
                                               (ny - static_cast<std::size_t>(std::abs(jy))))
                         : std::round(counts[wrap(jx, px)] * scale);
            double& c = row[jx + jx_max];
            if (pairs < 0.5) {
                c = kNaN;  // no pair of valid points at this lag
            } else if (estimator == AcfEstimator::Unbiased) {
                c = c / pairs / mean_square;  // (1/N(τ)) Σ z z' / σ²
            } else {
                c = c / r0;  // (1/N) Σ z z' / σ²
            }
        }
    }
    acf.values[static_cast<std::size_t>(jy_max) * acf.nx + static_cast<std::size_t>(jx_max)] = 1.0;
    return acf;
}

Curve radial_acf(const Acf2d& acf) {
    check_acf(acf);
    const std::size_t nx = acf.nx / 2 + 1;  // the map's sizes
    const std::size_t ny = acf.ny / 2 + 1;
    const bool profile = acf.ny == 1;
    const double width = profile ? acf.dx_um : std::min(acf.dx_um, acf.dy_um);
    // Complete rings only: up to the shorter side of the lag grid.
    const double tau_max = profile ? static_cast<double>(nx - 1) * acf.dx_um
                                   : std::min(static_cast<double>(nx - 1) * acf.dx_um,
                                              static_cast<double>(ny - 1) * acf.dy_um);
    const auto rings = static_cast<std::size_t>(std::floor(tau_max / width + 1e-9)) + 1;
    std::vector<double> sum(rings, 0.0);
    std::vector<double> weight(rings, 0.0);
    const double reach = (static_cast<double>(rings) - 0.5) * width;
    const auto jx_max = std::min(static_cast<std::ptrdiff_t>(nx) - 1,
                                 static_cast<std::ptrdiff_t>(reach / acf.dx_um) + 1);
    const auto jy_max = profile ? std::ptrdiff_t{0}
                                : std::min(static_cast<std::ptrdiff_t>(ny) - 1,
                                           static_cast<std::ptrdiff_t>(reach / acf.dy_um) + 1);
    // C(−τ) = C(τ): the half plane jy ≥ 0 suffices, the row jy = 0 counted half (it holds ±jx).
    for (std::ptrdiff_t jy = 0; jy <= jy_max; ++jy) {
        const double y = static_cast<double>(jy) * acf.dy_um;
        const double w = jy == 0 ? 0.5 : 1.0;
        for (std::ptrdiff_t jx = -jx_max; jx <= jx_max; ++jx) {
            const double x = static_cast<double>(jx) * acf.dx_um;
            const auto ring = static_cast<std::size_t>(std::floor(std::hypot(x, y) / width + 0.5));
            const double c = acf.at_lag(jx, jy);
            if (ring < rings && !std::isnan(c)) {
                sum[ring] += w * c;
                weight[ring] += w;
            }
        }
    }
    Curve curve;
    for (std::size_t i = 0; i < rings; ++i) {
        if (weight[i] > 0) {
            curve.x.push_back(static_cast<double>(i) * width);
            curve.y.push_back(sum[i] / weight[i]);
        }
    }
    return curve;
}

TextureParameters texture_parameters(const Acf2d& acf, double s) {
    check_acf(acf);
    if (!(s > 0 && s < 1)) {
        std::string message = "texture parameters: threshold s = ";
        message.append(format_message(s)).append(" must lie in (0, 1) (ISO 25178-2: 0.2)");
        throw InvalidArgument(message);
    }
    TextureParameters out;
    if (acf.ny == 1) {
        out.Sal_um = first_crossing(acf, 1.0, 0.0, s);
        return out;
    }
    // Rays at kDirections angles over [0, π) (C(−τ) = C(τ) covers the other half).
    constexpr int kDirections = 360;
    out.directions = kDirections;
    std::optional<double> shortest;
    double longest = 0;
    bool all_cross = true;
    for (int k = 0; k < kDirections; ++k) {
        const double theta = std::acos(-1.0) * k / kDirections;
        const std::optional<double> r = first_crossing(acf, std::cos(theta), std::sin(theta), s);
        if (!r) {
            all_cross = false;
            ++out.directions_without_crossing;
            if (!out.first_without_crossing_deg)
                out.first_without_crossing_deg = 180.0 * k / kDirections;
            continue;
        }
        shortest = shortest ? std::min(*shortest, *r) : *r;
        longest = std::max(longest, *r);
    }
    out.Sal_um = shortest;
    if (shortest && all_cross) {
        out.Str = *shortest / longest;
    }
    return out;
}

Curve psd_x(const HeightMap& levelled) {
    validate(levelled, "levelled map");
    const std::size_t nx = levelled.nx;
    fft::RealToComplex f(levelled.ny, nx, fft::Layout::rows);
    load_heights(levelled, f);
    f.forward();
    // Two-sided W(f_k) = (dx/N_valid) Σ_rows |Z_k|², so that Σ_k W Δf = (1/N_valid) Σ z² = σ²
    // with Δf = 1/(nx dx); the one-sided PSD doubles every frequency that has a partner n − k.
    const double norm = levelled.dx_um / static_cast<double>(levelled.count_valid());
    Curve curve;
    curve.x.resize(f.spectrum_cols());
    curve.y.assign(f.spectrum_cols(), 0.0);
    for (std::size_t r = 0; r < levelled.ny; ++r) {
        const std::complex<double>* row = f.spectrum_row(r);
        for (std::size_t k = 0; k < f.spectrum_cols(); ++k) {
            curve.y[k] += std::norm(row[k]);
        }
    }
    const double length = levelled.length_x_um();
    for (std::size_t k = 0; k < f.spectrum_cols(); ++k) {
        const bool paired = k != 0 && 2 * k != nx;
        curve.x[k] = static_cast<double>(k) / length;
        curve.y[k] *= norm * (paired ? 2.0 : 1.0);
    }
    return curve;
}

Curve psd_radial(const HeightMap& levelled) {
    validate(levelled, "levelled map");
    if (levelled.is_profile()) {
        throw InvalidArgument(
            "levelled map: the radial PSD needs a map with ny >= 2 rows (this "
            "is a profile, ny = 1; use the PSD along x)");
    }
    const std::size_t nx = levelled.nx;
    const std::size_t ny = levelled.ny;
    fft::RealToComplex f(ny, nx, fft::Layout::plane);
    load_heights(levelled, f);
    f.forward();
    // Two-sided 2-D W(fx, fy) = (dx dy / N_valid) |Z|², Σ W Δfx Δfy = σ²; rings of width
    // Δf = min(Δfx, Δfy), each the mean of W over its frequencies (empty rings left out).
    const double norm =
        levelled.dx_um * levelled.dy_um / static_cast<double>(levelled.count_valid());
    const double dfx = 1.0 / levelled.length_x_um();
    const double dfy = 1.0 / levelled.length_y_um();
    const double width = std::min(dfx, dfy);
    const std::size_t nyquist_x = nx / 2;  // largest |frequency index| along x and y
    const std::size_t nyquist_y = ny / 2;
    const double f_max =
        std::hypot(static_cast<double>(nyquist_x) * dfx, static_cast<double>(nyquist_y) * dfy);
    const auto rings = static_cast<std::size_t>(std::floor(f_max / width + 0.5)) + 1;
    std::vector<double> sum(rings, 0.0);
    std::vector<double> count(rings, 0.0);
    for (std::size_t r = 0; r < ny; ++r) {
        const auto ky = static_cast<double>(r <= ny / 2 ? static_cast<std::ptrdiff_t>(r)
                                                        : static_cast<std::ptrdiff_t>(r) -
                                                              static_cast<std::ptrdiff_t>(ny));
        const std::complex<double>* row = f.spectrum_row(r);
        for (std::size_t k = 0; k < f.spectrum_cols(); ++k) {
            // The half spectrum stands for kx and −kx, except at kx = 0 and the Nyquist column.
            const double w = (k != 0 && 2 * k != nx) ? 2.0 : 1.0;
            const double freq = std::hypot(static_cast<double>(k) * dfx, ky * dfy);
            const auto ring =
                std::min(rings - 1, static_cast<std::size_t>(std::floor(freq / width + 0.5)));
            sum[ring] += w * std::norm(row[k]) * norm;
            count[ring] += w;
        }
    }
    Curve curve;
    for (std::size_t i = 0; i < rings; ++i) {
        if (count[i] > 0) {
            curve.x.push_back(static_cast<double>(i) * width);
            curve.y.push_back(sum[i] / count[i]);
        }
    }
    return curve;
}

}  // namespace roughscope::surface
