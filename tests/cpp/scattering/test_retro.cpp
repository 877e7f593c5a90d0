// Eq. 7–11 against the general forms (Eq. 3–5) evaluated at θi = θs = θ, φs = π.
#include <cmath>

#include <gtest/gtest.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/retro.hpp"

using namespace roughscope;

namespace {
constexpr double kLambda = 0.555;
const double kK = 2 * kPi / kLambda;
}  // namespace

class RetroVeryRough : public ::testing::TestWithParam<double> {};

TEST_P(RetroVeryRough, Eq7To10EqualGeneralFormsTimesTheirConstant) {
    const double m = GetParam();  // σ/T
    const double sigma = 3.0, T = sigma / m, area = 4e4;
    for (double deg = 0; deg < 89.5; deg += 2.5) {
        const double t = deg_to_rad(deg);
        const Geometry g = retro_geometry(t);
        const ScatteringVector v = scattering_vector(g, kLambda);
        const double vz2 = v.vz * v.vz, vxy2 = v.vxy2();
        const double fb = geometric_factor_squared(GeometricFactor::Beckmann, g);
        const double fvh = geometric_factor_squared(GeometricFactor::VernoldHarvey, g);
        const double cG = kPi * T * T / (4 * area * sigma * sigma * kK * kK);  // Eq. 4 → 7, 9
        const double cE = 2 * cG;                                              // Eq. 5 → 8, 10
        if (retro_vh_gaussian_very_rough(t, m) < 1e-250) {
            // Far outside the lobe both sides underflow: an expected physical zero.
            EXPECT_LT(diffuse_power_very_rough_gaussian(fvh, sigma, T, area, vz2, vxy2), 1e-250);
            continue;
        }
        EXPECT_NEAR(diffuse_power_very_rough_gaussian(fb, sigma, T, area, vz2, vxy2) / cG /
                        retro_beckmann_gaussian_very_rough(t, m),
                    1.0, 1e-12)
            << deg;
        EXPECT_NEAR(diffuse_power_very_rough_exponential(fb, sigma, T, area, vz2, vxy2) / cE /
                        retro_beckmann_exponential_very_rough(t, m),
                    1.0, 1e-12)
            << deg;
        EXPECT_NEAR(diffuse_power_very_rough_gaussian(fvh, sigma, T, area, vz2, vxy2) / cG /
                        retro_vh_gaussian_very_rough(t, m),
                    1.0, 1e-12)
            << deg;
        EXPECT_NEAR(diffuse_power_very_rough_exponential(fvh, sigma, T, area, vz2, vxy2) / cE /
                        retro_vh_exponential_very_rough(t, m),
                    1.0, 1e-12)
            << deg;
        // The σ/T-only brightness shape is Eq. 9/10 × 1/4 (q_z² = 4 cos²θ).
        EXPECT_NEAR(very_rough_brightness(g, m, Correlation::Gaussian) * 4,
                    retro_vh_gaussian_very_rough(t, m), 1e-12 * retro_vh_gaussian_very_rough(t, m));
    }
}

INSTANTIATE_TEST_SUITE_P(Slopes, RetroVeryRough, ::testing::Values(0.2, 0.4833, 0.71, 1.0, 1.8));

TEST(Retro, Eq11EqualsEq3WithVernoldHarveyFactor) {
    const double sigma = 0.1, T = 0.25, area = 1e6;
    for (double deg = 0; deg < 89.5; deg += 5) {
        const double t = deg_to_rad(deg);
        const Geometry g = retro_geometry(t);
        const ScatteringVector v = scattering_vector(g, kLambda);
        const double gg = roughness_g(sigma, v.vz);
        const double eq3 = diffuse_power_slightly_rough_gaussian(
            geometric_factor_squared(GeometricFactor::VernoldHarvey, g), T, area, gg, v.vxy2());
        const double K = kPi * T * T / area * 4 * kK * kK * sigma * sigma;
        const double eq11 = retro_vh_gaussian_slightly_rough(t, sigma, T, kLambda);
        EXPECT_NEAR(eq3, K * eq11, 1e-13 * K) << deg;
    }
}

TEST(Retro, PaperStatedAsymptotics) {
    // §3.4: Eq. 7 → 0 as θ → π/2 (the exponential wins), Eq. 8 diverges; V–H forms behave.
    const double m = 0.5, near90 = deg_to_rad(89.9);
    EXPECT_LT(retro_beckmann_gaussian_very_rough(near90, m), 1e-100);
    EXPECT_GT(retro_beckmann_exponential_very_rough(near90, m), 1e6);
    EXPECT_LT(retro_vh_exponential_very_rough(near90, m), retro_vh_exponential_very_rough(0, m));
    // All very-rough forms equal 1 at θ = 0 (normalised radiance of Figs. 3–4).
    EXPECT_DOUBLE_EQ(retro_beckmann_gaussian_very_rough(0, m), 1.0);
    EXPECT_DOUBLE_EQ(retro_vh_exponential_very_rough(0, m), 1.0);
    // Rougher surfaces are brighter off-normal (§3.4, Figs. 3–4).
    EXPECT_GT(retro_vh_gaussian_very_rough(1.0, 1.8), retro_vh_gaussian_very_rough(1.0, 0.71));
}

TEST(Retro, BadInputThrows) {
    EXPECT_THROW(retro_vh_gaussian_very_rough(kPi / 2, 0.5), InvalidArgument);
    EXPECT_THROW(retro_vh_gaussian_very_rough(0.3, 0.0), InvalidArgument);
    EXPECT_THROW(retro_beckmann_exponential_very_rough(0.3, -1.0), InvalidArgument);
    EXPECT_THROW(retro_beckmann_gaussian_very_rough(NAN, 0.5), InvalidArgument);
    EXPECT_THROW(retro_vh_exponential_very_rough(0.3, NAN), InvalidArgument);
    EXPECT_THROW(retro_vh_gaussian_slightly_rough(0.3, 0.1, 0.2, 0.0), InvalidArgument);
    EXPECT_THROW(retro_vh_gaussian_slightly_rough(0.3, -0.1, 0.2, 0.5), InvalidArgument);
}
