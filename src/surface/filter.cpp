// The Gaussian roughness filter: ISO 16610-21 along x for a profile, the separable areal
// ISO 16610-61 filter for a map. Missing points and the map's edges are handled by renormalising
// the weights over the valid points under the kernel (docs/surface.md, "Gaussian filter").
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/surface/statistics.hpp"

namespace roughscope::surface {
namespace {

// α = sqrt(ln 2 / π): the Gaussian weighting function transmits 50 % at λc (ISO 16610-21).
const double kAlpha = std::sqrt(std::numbers::ln2 / std::numbers::pi);

// Weights w_k = exp(−π (k·spacing / (α λc))²) for k = 0..K, truncated at |x| ≤ λc (where the
// weight is 7e−7 of the centre's) and at the longest lag of a line of n samples (weights beyond
// it never meet a sample).
std::vector<double> gaussian_weights(double cutoff_um, double spacing_um, std::size_t n) {
    const double max_lag = static_cast<double>(n > 0 ? n - 1 : 0);
    const auto half =
        static_cast<std::size_t>(std::min(std::floor(cutoff_um / spacing_um), max_lag));
    std::vector<double> w(half + 1);
    for (std::size_t k = 0; k <= half; ++k) {
        const double x = static_cast<double>(k) * spacing_um / (kAlpha * cutoff_um);
        w[k] = std::exp(-std::numbers::pi * x * x);
    }
    return w;
}

// out[i] = Σ_{|k| ≤ K, 0 ≤ i+k < n} w_|k| in[(i+k)·stride] for lines of n samples; `lines`
// lines, line l starting at l·line_step. Loops are ordered so the inner one runs over
// contiguous memory (k outer, samples or lines inner).
void convolve_rows(const std::vector<double>& in, std::vector<double>& out, std::size_t nx,
                   std::size_t ny, const std::vector<double>& w) {
    const std::size_t half = w.size() - 1;
    for (std::size_t iy = 0; iy < ny; ++iy) {
        const double* src = &in[iy * nx];
        double* dst = &out[iy * nx];
        for (std::size_t ix = 0; ix < nx; ++ix) dst[ix] = w[0] * src[ix];
        for (std::size_t k = 1; k <= std::min(half, nx - 1); ++k) {
            const double wk = w[k];
            for (std::size_t ix = 0; ix + k < nx; ++ix) dst[ix] += wk * src[ix + k];
            for (std::size_t ix = k; ix < nx; ++ix) dst[ix] += wk * src[ix - k];
        }
    }
}

void convolve_columns(const std::vector<double>& in, std::vector<double>& out, std::size_t nx,
                      std::size_t ny, const std::vector<double>& w) {
    const std::size_t half = w.size() - 1;
    for (std::size_t iy = 0; iy < ny; ++iy) {
        double* dst = &out[iy * nx];
        const double* src = &in[iy * nx];
        for (std::size_t ix = 0; ix < nx; ++ix) dst[ix] = w[0] * src[ix];
        for (std::size_t k = 1; k <= std::min(half, ny - 1); ++k) {
            const double wk = w[k];
            if (iy + k < ny) {
                const double* up = &in[(iy + k) * nx];
                for (std::size_t ix = 0; ix < nx; ++ix) dst[ix] += wk * up[ix];
            }
            if (iy >= k) {
                const double* down = &in[(iy - k) * nx];
                for (std::size_t ix = 0; ix < nx; ++ix) dst[ix] += wk * down[ix];
            }
        }
    }
}

}  // namespace

FilteredHeights gaussian_filter(const HeightMap& map, double cutoff_um) {
    validate(map, "heights");
    check::positive("cutoff_um", cutoff_um, "µm");
    const bool profile = map.is_profile();
    const double finest = profile ? map.dx_um : std::max(map.dx_um, map.dy_um);
    if (cutoff_um < 2.0 * finest)
        throw InvalidArgument("gaussian_filter: cutoff_um = " + format_message(cutoff_um) +
                              " must be at least 2 sampling spacings (" +
                              format_message(2.0 * finest) + " µm)");

    const std::size_t n = map.size();
    std::vector<double> weighted(n), valid(n);  // z·m and m (m = 1 valid, 0 missing)
    for (std::size_t i = 0; i < n; ++i) {
        const bool ok = !std::isnan(map.heights_um[i]);
        weighted[i] = ok ? map.heights_um[i] : 0.0;
        valid[i] = ok ? 1.0 : 0.0;
    }
    std::vector<double> num(n), den(n);
    const std::vector<double> wx = gaussian_weights(cutoff_um, map.dx_um, map.nx);
    convolve_rows(weighted, num, map.nx, map.ny, wx);
    convolve_rows(valid, den, map.nx, map.ny, wx);
    if (!profile) {
        const std::vector<double> wy = gaussian_weights(cutoff_um, map.dy_um, map.ny);
        convolve_columns(num, weighted, map.nx, map.ny, wy);
        convolve_columns(den, valid, map.nx, map.ny, wy);
        num.swap(weighted);
        den.swap(valid);
    }

    FilteredHeights out{map, map};
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (std::size_t i = 0; i < n; ++i) {
        const double z = map.heights_um[i];
        if (std::isnan(z)) {
            out.waviness.heights_um[i] = nan;
            out.roughness.heights_um[i] = nan;
            continue;
        }
        const double mean = num[i] / den[i];  // den ≥ w_0² > 0 at a valid point
        out.waviness.heights_um[i] = mean;
        out.roughness.heights_um[i] = z - mean;
    }
    return out;
}

}  // namespace roughscope::surface
