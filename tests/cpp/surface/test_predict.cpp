// The bridge from heights to brightness (surface/predict.hpp) against the scattering functions
// called directly, and its limits:
//  * every number equals the scattering topic's own function at the same inputs (Eq. 1–5,
//    Caron's θK and ξK, m = σ√2/T);
//  * g at normal view is (4πσ/λ)² (§3.1, v_z = −2k), and its class follows the §3.1 lines;
//  * at large g the exact series divided by the very-rough shape tends to πT²/(Aσ²k²) (Eq. 4's
//    constant), at small g the diffuse term tends to the one-term form (Eq. 3);
//  * σ, T and the correlation taken from height statistics, with the fallbacks and their
//    warnings; bad input → InvalidArgument.
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/factors.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/scattering/validity.hpp"
#include "roughscope/surface/predict.hpp"
#include "roughscope/surface/statistics.hpp"

namespace {

using namespace roughscope;
using surface::predict_brightness;

Geometry deg_geometry(double ti, double ts, double ps) {
    return make_geometry(deg_to_rad(ti), deg_to_rad(ts), deg_to_rad(ps));
}

std::vector<Geometry> some_geometries() {
    return {deg_geometry(10, 0, 0), deg_geometry(30, 20, 0), deg_geometry(45, 45, 180),
            deg_geometry(60, 30, 70)};
}

surface::SurfaceStatistics stats_with(double sigma, std::optional<double> T,
                                      std::optional<Correlation> c) {
    surface::SurfaceStatistics s;
    s.sigma_um = sigma;
    s.T_um = T;
    s.correlation = c;
    return s;
}

TEST(SurfacePredict, EqualsTheScatteringFunctionsCalledDirectly) {
    for (Correlation c : {Correlation::Gaussian, Correlation::Exponential}) {
        for (double sigma : {0.01, 0.2, 3.0}) {
            const Surface s{sigma, 4.0, c};
            ModelOptions o;
            o.factor = GeometricFactor::Beckmann;
            o.wavelength_um = 0.6;
            const auto p = predict_brightness(s, some_geometries(), o);
            ASSERT_EQ(p.points.size(), 4u);
            EXPECT_EQ(p.sigma_over_T, sigma / 4.0);
            EXPECT_EQ(p.rms_slope, rms_slope(sigma / 4.0));
            EXPECT_EQ(p.theta_K_rad, caron_theta_K_rad(sigma / 4.0));
            EXPECT_EQ(p.xi_K, caron_xi_K(sigma / 4.0));
            for (std::size_t i = 0; i < p.points.size(); ++i) {
                const Geometry g = some_geometries()[i];
                const ScatteredPower direct = mean_scattered_power(g, s, o);
                EXPECT_EQ(p.points[i].power.brightness, direct.brightness);
                EXPECT_EQ(p.points[i].power.diffuse, direct.diffuse);
                EXPECT_EQ(p.points[i].power.g, roughness_g(g, sigma, 0.6));
                EXPECT_EQ(p.points[i].very_rough_brightness,
                          very_rough_brightness(g, sigma / 4.0, c, o.factor, o.radiometry));
            }
        }
    }
}

TEST(SurfacePredict, GAtNormalViewAndItsClass) {
    // §3.1: v_z = −k(cos θi + cos θs) = −4π/λ at θi = θs = 0, so g = (4πσ/λ)².
    for (double sigma : {0.001, 0.03, 0.2, 2.0}) {
        const auto p = predict_brightness(Surface{sigma, 5.0, Correlation::Gaussian}, {}, {});
        const double expected = std::pow(4.0 * kPi * sigma / 0.555, 2);
        EXPECT_NEAR(p.g_normal, expected, 1e-12 * expected);
        EXPECT_EQ(p.roughness_class, roughness_class(expected));
    }
    EXPECT_EQ(predict_brightness(Surface{0.001, 5, Correlation::Gaussian}, {}, {}).roughness_class,
              RoughnessClass::SlightlyRough);
    EXPECT_EQ(predict_brightness(Surface{2.0, 5, Correlation::Gaussian}, {}, {}).roughness_class,
              RoughnessClass::VeryRough);
    // The wavelength moves the class: the same surface is very rough in the visible and
    // slightly rough at 100 µm.
    ModelOptions far_ir;
    far_ir.wavelength_um = 100.0;
    EXPECT_EQ(
        predict_brightness(Surface{0.5, 5, Correlation::Gaussian}, {}, far_ir).roughness_class,
        RoughnessClass::SlightlyRough);
}

TEST(SurfacePredict, VeryRoughLimitGivesEq4Constant) {
    // Eq. 4 = (πT²/(A σ² k²)) × the very-rough shape, and the exact series tends to Eq. 4 as
    // g → ∞ (error ∝ 1/g): at g ≈ 5e4 the ratio is that constant to ~1e−4.
    const double sigma = 10.0, T = 40.0;
    const ModelOptions o;
    const double k = wavenumber_per_um(o.wavelength_um);
    const double A = 4.0 * o.patch_x_um * o.patch_y_um;
    const double constant = kPi * T * T / (A * sigma * sigma * k * k);
    const auto p = predict_brightness(Surface{sigma, T, Correlation::Gaussian},
                                      {deg_geometry(20, 10, 30), deg_geometry(40, 0, 0)}, o);
    for (const auto& pt : p.points) {
        ASSERT_GT(pt.power.g, 1e4);
        EXPECT_NEAR(pt.power.brightness / pt.very_rough_brightness / constant, 1.0, 1e-3);
    }
    // Far from that limit (g ≈ 0.5) the ratio is not the constant: the test can tell.
    const auto q =
        predict_brightness(Surface{0.03, T, Correlation::Gaussian}, {deg_geometry(20, 10, 30)}, o);
    const double c2 = kPi * T * T / (A * 0.03 * 0.03 * k * k);
    EXPECT_GT(std::abs(q.points[0].power.brightness / q.points[0].very_rough_brightness / c2 - 1),
              0.1);
}

TEST(SurfacePredict, SlightlyRoughLimitGivesEq3) {
    const Geometry g = deg_geometry(30, 20, 40);
    const double sigma = 1e-4, T = 2.0;
    const auto p = predict_brightness(Surface{sigma, T, Correlation::Gaussian}, {g}, {});
    const ScatteringVector v = scattering_vector(g, 0.555);
    const double gg = roughness_g(sigma, v.vz);
    ASSERT_LT(gg, 1e-5);
    const double eq3 = diffuse_power_slightly_rough_gaussian(
        geometric_factor_squared(GeometricFactor::VernoldHarvey, g), T, 1e6, gg, v.vxy2());
    // Eq. 2's second term over its first: (g/4) exp(a/2), a = T² v_xy²/4.
    const double second_over_first = gg / 4.0 * std::exp(T * T * v.vxy2() / 8.0);
    ASSERT_LT(second_over_first, 1e-2);
    EXPECT_NEAR(p.points[0].power.diffuse / eq3, 1.0 + second_over_first, 0.01 * second_over_first);
}

TEST(SurfacePredict, CaronThetaKFlagsAndWarns) {
    // σ/T = 1: θK = 90° − atan(√2) = 35.26°.
    const auto p = predict_brightness(Surface{2.0, 2.0, Correlation::Gaussian},
                                      {deg_geometry(20, 0, 0), deg_geometry(50, 0, 0)}, {});
    EXPECT_NEAR(rad_to_deg(p.theta_K_rad), 90.0 - rad_to_deg(std::atan(std::sqrt(2.0))), 1e-12);
    EXPECT_FALSE(p.points[0].beyond_theta_K);
    EXPECT_TRUE(p.points[1].beyond_theta_K);
    ASSERT_EQ(p.warnings.size(), 1u);
    EXPECT_NE(p.warnings[0].find("theta_K"), std::string::npos);
    const auto q =
        predict_brightness(Surface{2.0, 2.0, Correlation::Gaussian}, {deg_geometry(20, 0, 0)}, {});
    EXPECT_TRUE(q.warnings.empty());
}

TEST(SurfacePredict, SurfaceFromStatistics) {
    auto a = surface::surface_from_statistics(stats_with(0.5, 7.0, Correlation::Exponential));
    EXPECT_EQ(a.surface.sigma_um, 0.5);
    EXPECT_EQ(a.surface.T_um, 7.0);
    EXPECT_EQ(a.surface.correlation, Correlation::Exponential);
    EXPECT_EQ(a.T_source, "T_um");
    EXPECT_FALSE(a.correlation_assumed);
    EXPECT_TRUE(a.warnings.empty());
    // The given correlation wins over the fit's.
    auto b = surface::surface_from_statistics(stats_with(0.5, 7.0, Correlation::Exponential),
                                              Correlation::Gaussian);
    EXPECT_EQ(b.surface.correlation, Correlation::Gaussian);
    // No correlation named: Gaussian, said so.
    auto c = surface::surface_from_statistics(stats_with(0.5, 7.0, std::nullopt));
    EXPECT_EQ(c.surface.correlation, Correlation::Gaussian);
    EXPECT_TRUE(c.correlation_assumed);
    EXPECT_EQ(c.warnings.size(), 1u);
    // No 1/e crossing: the fitted T of the correlation used, said so.
    auto s = stats_with(0.5, std::nullopt, Correlation::Exponential);
    s.T_fit_gaussian_um = 3.0;
    s.T_fit_exponential_um = 9.0;
    auto d = surface::surface_from_statistics(s);
    EXPECT_EQ(d.surface.T_um, 9.0);
    EXPECT_EQ(d.T_source, "T_fit_exponential_um");
    EXPECT_EQ(d.warnings.size(), 1u);
    // predict from the statistics = predict from the surface, warnings first.
    const auto from_stats = predict_brightness(s, {deg_geometry(10, 0, 0)});
    const auto direct = predict_brightness(d.surface, {deg_geometry(10, 0, 0)});
    EXPECT_EQ(from_stats.points[0].power.brightness, direct.points[0].power.brightness);
    EXPECT_EQ(from_stats.warnings, d.warnings);
}

TEST(SurfacePredict, SurfaceFromStatisticsRejects) {
    EXPECT_THROW(surface::surface_from_statistics(stats_with(0.0, 7.0, Correlation::Gaussian)),
                 InvalidArgument);
    EXPECT_THROW(surface::surface_from_statistics(
                     stats_with(std::numeric_limits<double>::quiet_NaN(), 7.0, std::nullopt)),
                 InvalidArgument);
    EXPECT_THROW(
        surface::surface_from_statistics(stats_with(0.5, std::nullopt, Correlation::Gaussian)),
        InvalidArgument);
    // A fit of the other correlation does not stand in for the one used.
    auto s = stats_with(0.5, std::nullopt, Correlation::Gaussian);
    s.T_fit_exponential_um = 9.0;
    EXPECT_THROW(surface::surface_from_statistics(s), InvalidArgument);
}

TEST(SurfacePredict, RejectsBadInput) {
    EXPECT_THROW(predict_brightness(Surface{0.0, 1.0, Correlation::Gaussian}, {}, {}),
                 InvalidArgument);
    EXPECT_THROW(predict_brightness(Surface{1.0, -1.0, Correlation::Gaussian}, {}, {}),
                 InvalidArgument);
    ModelOptions o;
    o.wavelength_um = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THROW(predict_brightness(Surface{1.0, 1.0, Correlation::Gaussian}, {}, o),
                 InvalidArgument);
    // An unvalidated geometry is named by its position.
    Geometry bad;
    bad.theta_i_rad = kPi / 2;
    try {
        predict_brightness(Surface{1.0, 1.0, Correlation::Gaussian}, {deg_geometry(10, 0, 0), bad});
        FAIL() << "no exception";
    } catch (const InvalidArgument& e) {
        EXPECT_NE(std::string(e.what()).find("geometry 2"), std::string::npos) << e.what();
    }
}

}  // namespace
