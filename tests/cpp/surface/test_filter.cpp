// The Gaussian roughness filter (ISO 16610-21 profile, ISO 16610-61 areal): 50 % transmission of
// a sinusoid at λc, the transmission exp(−π (α λc / λ)²) away from it, the renormalised weights
// at missing points and edges, and the option checks.
#include <cmath>
#include <cstddef>
#include <numbers>

#include <gtest/gtest.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/surface/statistics.hpp"
#include "test_statistics_data.hpp"

namespace roughscope::surface {
namespace {

using testdata::kNaN;

const double kAlpha2 = std::numbers::ln2 / std::numbers::pi;

// A sinusoid of unit amplitude and wavelength λ along the direction (cos θ, sin θ).
HeightMap sinusoid(std::size_t nx, std::size_t ny, double wavelength_um, double theta) {
    HeightMap m = make_height_map(nx, ny, 1.0, 1.0);
    for (std::size_t iy = 0; iy < ny; ++iy)
        for (std::size_t ix = 0; ix < nx; ++ix) {
            const double s = static_cast<double>(ix) * std::cos(theta) +
                             static_cast<double>(iy) * std::sin(theta);
            m.at(ix, iy) = std::sin(2.0 * std::numbers::pi * s / wavelength_um + 0.3);
        }
    return m;
}

// Least-squares amplitude of a·sin(φ) + b·cos(φ) fitted to `out` at the points farther than
// `margin` from every edge (no edge effect there).
double amplitude(const HeightMap& out, double wavelength_um, double theta, std::size_t margin) {
    double ss = 0, sc = 0, cc = 0, zs = 0, zc = 0;
    const std::size_t ylo = out.ny == 1 ? 0 : margin;
    const std::size_t yhi = out.ny == 1 ? 1 : out.ny - margin;
    for (std::size_t iy = ylo; iy < yhi; ++iy)
        for (std::size_t ix = margin; ix + margin < out.nx; ++ix) {
            const double s = static_cast<double>(ix) * std::cos(theta) +
                             static_cast<double>(iy) * std::sin(theta);
            const double ph = 2.0 * std::numbers::pi * s / wavelength_um + 0.3;
            const double sn = std::sin(ph), cs = std::cos(ph), z = out.at(ix, iy);
            ss += sn * sn;
            sc += sn * cs;
            cc += cs * cs;
            zs += z * sn;
            zc += z * cs;
        }
    const double det = ss * cc - sc * sc;
    const double a = (zs * cc - zc * sc) / det;
    const double b = (zc * ss - zs * sc) / det;
    return std::hypot(a, b);
}

double gaussian_transmission(double cutoff, double wavelength) {
    const double r = cutoff / wavelength;
    return std::exp(-std::numbers::pi * kAlpha2 * r * r);
}

TEST(SurfaceGaussianFilter, ProfileTransmitsHalfAtCutoff) {
    const double lc = 100.0;
    const HeightMap p = sinusoid(4000, 1, lc, 0.0);
    const FilteredHeights f = gaussian_filter(p, lc);
    const auto margin = static_cast<std::size_t>(lc);
    EXPECT_NEAR(amplitude(f.waviness, lc, 0.0, margin), 0.5, 0.01);
    EXPECT_NEAR(amplitude(f.roughness, lc, 0.0, margin), 0.5, 0.01);
}

TEST(SurfaceGaussianFilter, ProfilePassesLongWavelengthsToTheWaviness) {
    const double lc = 100.0;
    const HeightMap p_long = sinusoid(8000, 1, 10 * lc, 0.0);
    const FilteredHeights fl = gaussian_filter(p_long, lc);
    const auto margin = static_cast<std::size_t>(lc);
    const double w = amplitude(fl.waviness, 10 * lc, 0.0, margin);
    EXPECT_NEAR(w, 1.0, 0.01);  // ≈ 99.3 %
    EXPECT_NEAR(w, gaussian_transmission(lc, 10 * lc), 1e-3);
    const HeightMap p_short = sinusoid(4000, 1, lc / 10, 0.0);
    const FilteredHeights fs = gaussian_filter(p_short, lc);
    EXPECT_NEAR(amplitude(fs.roughness, lc / 10, 0.0, margin), 1.0, 0.01);
    EXPECT_LT(amplitude(fs.waviness, lc / 10, 0.0, margin), 0.01);
    const HeightMap p_mid = sinusoid(4000, 1, 2 * lc, 0.0);
    EXPECT_NEAR(amplitude(gaussian_filter(p_mid, lc).waviness, 2 * lc, 0.0, margin),
                gaussian_transmission(lc, 2 * lc), 2e-3);
}

TEST(SurfaceGaussianFilter, ArealFilterTransmitsHalfAtCutoffInAnyDirection) {
    const double lc = 32.0;
    for (double theta : {0.0, std::numbers::pi / 2, 0.6}) {
        const HeightMap m = sinusoid(256, 256, lc, theta);
        const FilteredHeights f = gaussian_filter(m, lc);
        SCOPED_TRACE(theta);
        EXPECT_NEAR(amplitude(f.waviness, lc, theta, 32), 0.5, 0.01);
        const HeightMap lng = sinusoid(256, 256, 4 * lc, theta);
        EXPECT_NEAR(amplitude(gaussian_filter(lng, lc).waviness, 4 * lc, theta, 32),
                    gaussian_transmission(lc, 4 * lc), 0.01);
    }
}

TEST(SurfaceGaussianFilter, MissingPointsAndEdgesAreRenormalised) {
    // A constant is its own mean everywhere, also next to holes and at the edges.
    HeightMap m = make_height_map(60, 40, 1.0, 1.0);
    for (double& z : m.heights_um) z = 2.5;
    m.at(0, 0) = kNaN;
    m.at(30, 20) = kNaN;
    m.at(31, 20) = kNaN;
    const FilteredHeights f = gaussian_filter(m, 16.0);
    for (std::size_t i = 0; i < m.size(); ++i) {
        if (std::isnan(m.heights_um[i])) {
            EXPECT_TRUE(std::isnan(f.waviness.heights_um[i]));
            EXPECT_TRUE(std::isnan(f.roughness.heights_um[i]));
            continue;
        }
        EXPECT_NEAR(f.waviness.heights_um[i], 2.5, 1e-12) << i;
        EXPECT_NEAR(f.roughness.heights_um[i], 0.0, 1e-12) << i;
    }
}

TEST(SurfaceGaussianFilter, RejectsBadCutoffAndMaps) {
    const HeightMap m = testdata::noise_map(40, 10, 81);  // dx 0.5, dy 0.75
    EXPECT_NO_THROW(gaussian_filter(m, 1.5));
    EXPECT_THROW(gaussian_filter(m, 1.4), InvalidArgument);  // < 2 dy
    EXPECT_THROW(gaussian_filter(m, 0.0), InvalidArgument);
    EXPECT_THROW(gaussian_filter(m, -3.0), InvalidArgument);
    EXPECT_THROW(gaussian_filter(m, kNaN), InvalidArgument);
    EXPECT_THROW(gaussian_filter(m, INFINITY), InvalidArgument);
    const HeightMap p = testdata::noise_map(40, 1, 82);  // a profile: dy unused
    EXPECT_NO_THROW(gaussian_filter(p, 1.0));
    EXPECT_THROW(gaussian_filter(p, 0.9), InvalidArgument);
    HeightMap bad = m;
    bad.heights_um.resize(3);
    EXPECT_THROW(gaussian_filter(bad, 5.0), InvalidArgument);
}

TEST(SurfaceGaussianFilter, CutoffsFarBeyondTheMapGiveTheMapMinusItsMean) {
    // A cutoff of 1e30 µm on a 40 × 30 µm map: the kernel is truncated at the map (its weights
    // are 1 to rounding there), so the roughness is the heights minus their mean. The kernel's
    // length in samples must not be computed from λc/dx alone (1e30 samples).
    HeightMap map = sinusoid(40, 30, 7.0, 0.3);
    double mean = 0;
    for (const double z : map.heights_um) mean += z;
    mean /= static_cast<double>(map.size());
    for (const double cutoff : {1e12, 1e30}) {
        const FilteredHeights f = gaussian_filter(map, cutoff);
        for (std::size_t i = 0; i < map.size(); ++i) {
            ASSERT_NEAR(f.roughness.heights_um[i], map.heights_um[i] - mean, 1e-9) << cutoff;
        }
    }
}

}  // namespace
}  // namespace roughscope::surface
