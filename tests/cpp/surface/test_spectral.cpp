// The FFT statistics (spectral.hpp) against brute-force sums and closed forms: the 2-D ACF with
// missing points and both estimators, its radial average, Sal/Str, and the PSD's normalisation
// (Parseval) and frequency axis.
#include <cmath>
#include <complex>
#include <cstddef>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/surface/generate.hpp"
#include "roughscope/surface/spectral.hpp"

namespace roughscope::surface {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kPi = 3.14159265358979323846;

void expect_invalid(const std::function<void()>& call, const std::string& fragment) {
    try {
        call();
        ADD_FAILURE() << "no InvalidArgument; expected one naming '" << fragment << "'";
    } catch (const InvalidArgument& e) {
        EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
}

HeightMap random_map(std::size_t nx, std::size_t ny, double dx, double dy, unsigned seed) {
    HeightMap map = make_height_map(nx, ny, dx, dy);
    std::mt19937 engine(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (double& z : map.heights_um) {
        z = u(engine);
    }
    return map;
}

// The paper's §3.1 estimators written out as sums over the valid pairs.
double brute_force_acf(const HeightMap& m, std::ptrdiff_t jx, std::ptrdiff_t jy,
                       AcfEstimator estimator) {
    double sum = 0;
    double square = 0;
    std::size_t pairs = 0;
    std::size_t valid = 0;
    const auto nx = static_cast<std::ptrdiff_t>(m.nx);
    const auto ny = static_cast<std::ptrdiff_t>(m.ny);
    for (std::ptrdiff_t iy = 0; iy < ny; ++iy) {
        for (std::ptrdiff_t ix = 0; ix < nx; ++ix) {
            const double a = m.heights_um[static_cast<std::size_t>(iy * nx + ix)];
            if (!std::isnan(a)) {
                square += a * a;
                ++valid;
            }
            const std::ptrdiff_t kx = ix + jx;
            const std::ptrdiff_t ky = iy + jy;
            if (kx < 0 || ky < 0 || kx >= nx || ky >= ny) {
                continue;
            }
            const double b = m.heights_um[static_cast<std::size_t>(ky * nx + kx)];
            if (!std::isnan(a) && !std::isnan(b)) {
                sum += a * b;
                ++pairs;
            }
        }
    }
    if (pairs == 0) {
        return kNaN;
    }
    const double sigma2 = square / static_cast<double>(valid);
    return estimator == AcfEstimator::Unbiased ? sum / static_cast<double>(pairs) / sigma2
                                               : sum / static_cast<double>(valid) / sigma2;
}

void expect_acf_matches_brute_force(const HeightMap& map, AcfEstimator estimator) {
    const Acf2d acf = acf_2d(map, estimator);
    ASSERT_EQ(acf.nx, 2 * map.nx - 1);
    ASSERT_EQ(acf.ny, 2 * map.ny - 1);
    EXPECT_EQ(acf.dx_um, map.dx_um);
    EXPECT_EQ(acf.dy_um, map.dy_um);
    const auto mx = static_cast<std::ptrdiff_t>(map.nx) - 1;
    const auto my = static_cast<std::ptrdiff_t>(map.ny) - 1;
    for (std::ptrdiff_t jy = -my; jy <= my; ++jy) {
        for (std::ptrdiff_t jx = -mx; jx <= mx; ++jx) {
            const double expected = brute_force_acf(map, jx, jy, estimator);
            const double got = acf.at_lag(jx, jy);
            if (std::isnan(expected)) {
                EXPECT_TRUE(std::isnan(got)) << "lag " << jx << "," << jy;
            } else {
                EXPECT_NEAR(got, expected, 1e-12) << "lag " << jx << "," << jy;
            }
        }
    }
    EXPECT_EQ(acf.at_lag(0, 0), 1.0);
}

TEST(Acf2d, MatchesBruteForceSumsOnCompleteMapsBothEstimators) {
    for (const AcfEstimator e : {AcfEstimator::Unbiased, AcfEstimator::Biased}) {
        expect_acf_matches_brute_force(random_map(7, 5, 0.5, 2.0, 1), e);
        expect_acf_matches_brute_force(random_map(8, 6, 1.0, 1.0, 2), e);
        expect_acf_matches_brute_force(random_map(9, 1, 0.25, 1.0, 3), e);  // a profile
    }
}

TEST(Acf2d, MatchesBruteForceSumsWithMissingPointsBothEstimators) {
    HeightMap map = random_map(7, 5, 0.5, 2.0, 4);
    map.at(0, 0) = kNaN;  // the lag (6, 4) then has no valid pair
    map.at(3, 2) = kNaN;
    map.at(4, 2) = kNaN;
    map.at(6, 1) = kNaN;
    HeightMap profile = random_map(10, 1, 1.0, 1.0, 5);
    profile.at(9, 0) = kNaN;
    profile.at(2, 0) = kNaN;
    for (const AcfEstimator e : {AcfEstimator::Unbiased, AcfEstimator::Biased}) {
        expect_acf_matches_brute_force(map, e);
        expect_acf_matches_brute_force(profile, e);
    }
    EXPECT_TRUE(std::isnan(acf_2d(map, AcfEstimator::Unbiased).at_lag(6, 4)));
}

TEST(Acf2d, RejectsAFlatMapAndAMalformedOne) {
    HeightMap flat = make_height_map(4, 3, 1, 1);
    expect_invalid([&] { (void)acf_2d(flat, AcfEstimator::Unbiased); }, "σ = 0");
    flat.heights_um[1] = std::numeric_limits<double>::infinity();
    EXPECT_THROW((void)acf_2d(flat, AcfEstimator::Biased), InvalidArgument);
    flat.heights_um.pop_back();
    EXPECT_THROW((void)acf_2d(flat, AcfEstimator::Biased), InvalidArgument);
}

TEST(RadialAcf, IsTheRingAverageOfTheTwoDimensionalAcf) {
    HeightMap map = random_map(9, 7, 1.0, 1.5, 6);
    map.at(2, 3) = kNaN;
    const Acf2d acf = acf_2d(map, AcfEstimator::Unbiased);
    const Curve radial = radial_acf(acf);
    // Rings of width min(dx, dy) = 1 up to the shorter side of the lag grid, min(8, 6 × 1.5) = 8.
    ASSERT_EQ(radial.x.size(), 9U);
    for (std::size_t i = 0; i < radial.x.size(); ++i) {
        EXPECT_DOUBLE_EQ(radial.x[i], static_cast<double>(i));
        double sum = 0;
        int n = 0;
        for (int jy = -6; jy <= 6; ++jy) {
            for (int jx = -8; jx <= 8; ++jx) {
                const double r = std::hypot(jx * 1.0, jy * 1.5);
                const double c = acf.at_lag(jx, jy);
                if (std::floor(r + 0.5) == static_cast<double>(i) && !std::isnan(c)) {
                    sum += c;
                    ++n;
                }
            }
        }
        ASSERT_GT(n, 0);
        EXPECT_NEAR(radial.y[i], sum / n, 1e-12) << "ring " << i;
    }
    EXPECT_DOUBLE_EQ(radial.y[0], 1.0);
}

TEST(RadialAcf, RejectsAMalformedAcf) {
    Acf2d acf;
    expect_invalid([&] { (void)radial_acf(acf); }, "2-D ACF");
    acf.nx = 3;
    acf.ny = 3;
    acf.values.assign(8, 1.0);
    expect_invalid([&] { (void)radial_acf(acf); }, "2-D ACF");
}

// C(τ) = exp(−(τx/Tx)² − (τy/Ty)²) written on a lag grid.
Acf2d gaussian_acf_grid(double Tx, double Ty, std::size_t half, double dx, double dy) {
    Acf2d acf;
    acf.nx = 2 * half + 1;
    acf.ny = 2 * half + 1;
    acf.dx_um = dx;
    acf.dy_um = dy;
    acf.values.resize(acf.nx * acf.ny);
    const auto h = static_cast<std::ptrdiff_t>(half);
    for (std::ptrdiff_t jy = -h; jy <= h; ++jy) {
        for (std::ptrdiff_t jx = -h; jx <= h; ++jx) {
            const double x = static_cast<double>(jx) * dx / Tx;
            const double y = static_cast<double>(jy) * dy / Ty;
            acf.values[static_cast<std::size_t>((jy + h) * (2 * h + 1) + jx + h)] =
                std::exp(-x * x - y * y);
        }
    }
    return acf;
}

TEST(TextureParameters, SalAndStrOfAnAnalyticAnisotropicGaussianAcf) {
    // exp(−r²/T²) = s at r = T √ln(1/s): Sal = Tx √ln 5, Str = Tx / Ty.
    const TextureParameters t = texture_parameters(gaussian_acf_grid(10, 20, 100, 1, 1));
    ASSERT_TRUE(t.Sal_um && t.Str);
    EXPECT_NEAR(*t.Sal_um, 10 * std::sqrt(std::log(5.0)), 0.02);
    EXPECT_NEAR(*t.Str, 0.5, 0.005);
    const TextureParameters t5 = texture_parameters(gaussian_acf_grid(10, 10, 60, 1, 1), 0.5);
    ASSERT_TRUE(t5.Sal_um && t5.Str);
    EXPECT_NEAR(*t5.Sal_um, 10 * std::sqrt(std::log(2.0)), 0.02);
    EXPECT_NEAR(*t5.Str, 1.0, 0.005);
}

TEST(TextureParameters, StrIsUndefinedWhenTheAcfNeverDecaysAlongTheGrooves) {
    // Grooves along y: C depends on τx only and never falls to s along y.
    const TextureParameters t = texture_parameters(gaussian_acf_grid(10, 1e9, 40, 1, 1));
    ASSERT_TRUE(t.Sal_um);
    EXPECT_NEAR(*t.Sal_um, 10 * std::sqrt(std::log(5.0)), 0.03);
    EXPECT_FALSE(t.Str);
}

TEST(TextureParameters, GeneratedSurfaceRelabelledToTwiceTheYSpacingHasStrOneHalf) {
    GenerationOptions o;
    o.correlation = Correlation::Gaussian;
    o.sigma_um = 1;
    o.T_um = 8;
    o.nx = 384;
    o.ny = 384;
    o.seed = 11;
    HeightMap map = generate_surface(o);
    const TextureParameters iso = texture_parameters(acf_2d(map, AcfEstimator::Unbiased));
    map.dy_um = 2 * map.dx_um;  // the same heights, stretched along y
    const TextureParameters aniso = texture_parameters(acf_2d(map, AcfEstimator::Unbiased));
    ASSERT_TRUE(iso.Str && aniso.Str && iso.Sal_um && aniso.Sal_um);
    EXPECT_GT(*iso.Str, 0.85);
    EXPECT_NEAR(*aniso.Str, 0.5, 0.08);
    EXPECT_NEAR(*aniso.Sal_um, *iso.Sal_um, 0.05 * *iso.Sal_um);
    EXPECT_NEAR(*iso.Sal_um, 8 * std::sqrt(std::log(5.0)), 0.1 * 8 * std::sqrt(std::log(5.0)));
}

TEST(TextureParameters, RejectsAThresholdOutsideZeroOneAndAMalformedAcf) {
    const Acf2d acf = gaussian_acf_grid(3, 3, 10, 1, 1);
    for (const double s : {0.0, 1.0, -0.2, kNaN}) {
        expect_invalid([&] { (void)texture_parameters(acf, s); }, "threshold s");
    }
    expect_invalid([&] { (void)texture_parameters(Acf2d{}); }, "2-D ACF");
}

// One-sided PSD along x, averaged over rows, by a direct DFT: W(k/(n dx)) = (dx / N) Σ_rows
// |Σ_j z_j e^{−2πi jk/n}|², doubled for 0 < k < n/2.
std::vector<double> brute_force_psd_x(const HeightMap& m) {
    std::vector<double> out(m.nx / 2 + 1, 0.0);
    std::size_t valid = 0;
    for (std::size_t iy = 0; iy < m.ny; ++iy) {
        for (std::size_t k = 0; k < out.size(); ++k) {
            std::complex<double> sum = 0;
            for (std::size_t j = 0; j < m.nx; ++j) {
                const double z = m.at(j, iy);
                if (!std::isnan(z)) {
                    const double phase =
                        -2 * kPi * static_cast<double>(j * k) / static_cast<double>(m.nx);
                    sum += z * std::complex<double>(std::cos(phase), std::sin(phase));
                }
            }
            const bool paired = k != 0 && 2 * k != m.nx;
            out[k] += std::norm(sum) * (paired ? 2.0 : 1.0);
        }
        for (std::size_t j = 0; j < m.nx; ++j) {
            valid += std::isnan(m.at(j, iy)) ? 0 : 1;
        }
    }
    for (double& w : out) {
        w *= m.dx_um / static_cast<double>(valid);
    }
    return out;
}

double mean_square(const HeightMap& m) {
    double sum = 0;
    std::size_t n = 0;
    for (const double z : m.heights_um) {
        if (!std::isnan(z)) {
            sum += z * z;
            ++n;
        }
    }
    return sum / static_cast<double>(n);
}

TEST(Psd, AlongXMatchesADirectDftAndSatisfiesParseval) {
    for (const std::size_t nx : {6U, 7U}) {
        HeightMap map = random_map(nx, 3, 0.5, 1.0, 7);
        map.at(1, 1) = kNaN;  // zero-filled, N counts the valid points
        const Curve psd = psd_x(map);
        const std::vector<double> expected = brute_force_psd_x(map);
        ASSERT_EQ(psd.y.size(), expected.size());
        const double df = 1.0 / (static_cast<double>(nx) * 0.5);
        double integral = 0;
        for (std::size_t k = 0; k < expected.size(); ++k) {
            EXPECT_NEAR(psd.x[k], static_cast<double>(k) * df, 1e-15);
            EXPECT_NEAR(psd.y[k], expected[k], 1e-12);
            integral += psd.y[k] * df;
        }
        EXPECT_NEAR(integral, mean_square(map), 1e-12);  // ∫ W df = σ²
    }
}

TEST(Psd, SinusoidPeaksAtOneOverItsWavelength) {
    // z = A sin(2π x/λ), λ = 12.8 µm on 128 points of 0.4 µm (4 periods): the PSD along x and
    // the radial PSD peak at f = 1/λ, and the one-sided PSD integrates to A²/2.
    const double A = 0.3;
    const double lambda = 12.8;
    HeightMap map = make_height_map(128, 96, 0.4, 0.4);
    for (std::size_t iy = 0; iy < map.ny; ++iy) {
        for (std::size_t ix = 0; ix < map.nx; ++ix) {
            map.at(ix, iy) = A * std::sin(2 * kPi * static_cast<double>(ix) * 0.4 / lambda);
        }
    }
    const auto peak = [](const Curve& c) {
        std::size_t best = 0;
        for (std::size_t i = 1; i < c.y.size(); ++i) {
            best = c.y[i] > c.y[best] ? i : best;
        }
        return c.x[best];
    };
    const Curve px = psd_x(map);
    EXPECT_NEAR(peak(px), 1 / lambda, 1e-12);
    double integral = 0;
    for (const double w : px.y) {
        integral += w / map.length_x_um();
    }
    EXPECT_NEAR(integral, A * A / 2, 1e-12);
    EXPECT_NEAR(peak(psd_radial(map)), 1 / lambda, 1e-12);
}

TEST(Psd, RadialPsdIntegratesToTheVarianceOverTheFrequencyPlane) {
    // ∫ W(f) 2πf df = σ² (the rings' rectangle rule; exact up to the rings' discretisation).
    GenerationOptions o;
    o.T_um = 6;
    o.sigma_um = 0.7;
    o.nx = 256;
    o.ny = 256;
    o.dx_um = 0.5;
    o.dy_um = 0.5;
    o.seed = 3;
    const HeightMap map = generate_surface(o);
    const Curve radial = psd_radial(map);
    ASSERT_GT(radial.x.size(), 10U);
    const double df = radial.x[1] - radial.x[0];
    EXPECT_NEAR(df, 1 / map.length_x_um(), 1e-15);
    double integral = 0;
    for (std::size_t i = 0; i < radial.x.size(); ++i) {
        integral += radial.y[i] * 2 * kPi * radial.x[i] * df;
    }
    EXPECT_NEAR(integral, mean_square(map), 0.02 * mean_square(map));
}

TEST(Psd, RejectsAProfileForTheRadialPsdAndMalformedMaps) {
    const HeightMap profile = random_map(16, 1, 1, 1, 8);
    EXPECT_EQ(psd_x(profile).x.size(), 9U);
    expect_invalid([&] { (void)psd_radial(profile); }, "ny >= 2");
    HeightMap bad = random_map(4, 4, 1, 1, 9);
    bad.heights_um[3] = -std::numeric_limits<double>::infinity();
    EXPECT_THROW((void)psd_x(bad), InvalidArgument);
    EXPECT_THROW((void)psd_radial(bad), InvalidArgument);
}

TEST(TextureParameters, ExtremeSpacingRatiosTerminateWithFiniteLengths) {
    // The rays walk in lag-index steps: spacings 60 orders of magnitude apart (the ends of the
    // library's length range) neither hang the walk nor overflow the lengths.
    for (const auto& [dx, dy] : {std::pair{1e-30, 1e30}, std::pair{1e30, 1e-30},
                                 std::pair{1e30, 1e30}, std::pair{1e-30, 1e-30}}) {
        const Acf2d acf = acf_2d(random_map(24, 20, dx, dy, 7), AcfEstimator::Biased);
        const TextureParameters t = texture_parameters(acf);
        ASSERT_TRUE(t.Sal_um.has_value()) << dx << " " << dy;
        EXPECT_TRUE(std::isfinite(*t.Sal_um));
        EXPECT_GE(*t.Sal_um, std::min(dx, dy) * 0.1);
        if (t.Str) {
            EXPECT_TRUE(*t.Str >= 0 && *t.Str <= 1);
        }
    }
}

}  // namespace
}  // namespace roughscope::surface
