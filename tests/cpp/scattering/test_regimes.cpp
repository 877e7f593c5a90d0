// Limits and identities between the B–K regimes (paper §3.1, Eq. 1–5) through
// mean_scattered_power and the diffuse_power_* functions:
//  * Eq. 2 → Eq. 3 as g → 0 (error ∝ g) and Eq. 2 → Eq. 4 as g → ∞ (error ∝ 1/g, with the
//    predicted coefficient) at fixed σ/T, at in-plane and off-plane geometries;
//  * the exact exponential series → g/(g² + T²v_xy²)^{3/2} as g → ∞, and Eq. 5 is NOT that limit
//    (Eq. 5 / series ≈ g/(1 + T²v_xy²/σ²v_z²)^{3/2}; see docs/exponential-correlation.md);
//  * both series against the direct numerical Kirchhoff integral (diffuse_power_quadrature);
//  * coherent term, regime reporting, radiometry and geometric-factor selection;
//  * bad input for every argument of mean_scattered_power.
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/factors.hpp"
#include "roughscope/scattering/geometry.hpp"

namespace {

using namespace roughscope;

constexpr double kLambda = 0.555;  // µm, the library default
constexpr double kPatch = 500.0;   // µm, the library default half-size: A = 4XY = 1e6 µm²

Geometry deg_geometry(double theta_i_deg, double theta_s_deg, double phi_s_deg) {
    return make_geometry(deg_to_rad(theta_i_deg), deg_to_rad(theta_s_deg), deg_to_rad(phi_s_deg));
}

ScatteredPower power(const Geometry& geom, double sigma_um, double T_um, Correlation c,
                     Regime regime, GeometricFactor factor = GeometricFactor::VernoldHarvey,
                     Radiometry radiometry = Radiometry::Radiance) {
    ModelOptions options;
    options.regime = regime;
    options.factor = factor;
    options.radiometry = radiometry;
    options.wavelength_um = kLambda;
    options.patch_x_um = options.patch_y_um = kPatch;
    return mean_scattered_power(geom, Surface{sigma_um, T_um, c}, options);
}

// The scattering vector written out from §3.1 (independent of scattering_vector()).
struct HandVector {
    double vx, vy, vz;
};
HandVector hand_vector(const Geometry& g) {
    const double k = 2.0 * std::numbers::pi / kLambda;
    return {k * (std::sin(g.theta_i_rad) - std::sin(g.theta_s_rad) * std::cos(g.phi_s_rad)),
            -k * std::sin(g.theta_s_rad) * std::sin(g.phi_s_rad),
            -k * (std::cos(g.theta_i_rad) + std::cos(g.theta_s_rad))};
}

// Eq. 6 written out.
double hand_F_beckmann(const Geometry& g) {
    const double si = std::sin(g.theta_i_rad), ci = std::cos(g.theta_i_rad);
    const double ss = std::sin(g.theta_s_rad), cs = std::cos(g.theta_s_rad);
    return (1.0 + ci * cs - si * ss * std::cos(g.phi_s_rad)) / (ci * (ci + cs));
}

const std::vector<Geometry>& test_geometries() {
    static const std::vector<Geometry> geoms = {
        deg_geometry(30, 30, 0),    // specular: v_xy = 0
        deg_geometry(45, 20, 0),    // in the specular half-plane
        deg_geometry(30, 60, 90),   // off-plane
        deg_geometry(60, 40, 135),  // off-plane, towards retro
        deg_geometry(10, 70, 250),  // off-plane, other side
        deg_geometry(50, 50, 180),  // retro-reflection
    };
    return geoms;
}

// ---------------------------------------------------------------------------------------------
// Eq. 2 → Eq. 3 as g → 0.

TEST(RegimeLimits, SeriesTendsToSlightlyRoughLinearlyInG) {
    for (const Geometry& geom : test_geometries()) {
        const HandVector v = hand_vector(geom);
        const double vxy2 = v.vx * v.vx + v.vy * v.vy;
        const double T = 0.3;  // µm; X = T² v_xy² ≤ ~40
        const double X = T * T * vxy2;
        for (Correlation c : {Correlation::Gaussian, Correlation::Exponential}) {
            // Predicted relative error: second term / first term = (g/2) f(2)/f(1).
            const double per_g = c == Correlation::Gaussian ? 0.25 * std::exp(X / 8.0)
                                                            : std::pow((1.0 + X) / (4.0 + X), 1.5);
            double previous = 0.0;
            for (double g = 1e-1; g >= 0.99e-6; g /= 10.0) {
                const double sigma = std::sqrt(g) / std::abs(v.vz);
                const double series = power(geom, sigma, T, c, Regime::Series).diffuse;
                const double one_term = power(geom, sigma, T, c, Regime::SlightlyRough).diffuse;
                const double err = series / one_term - 1.0;
                EXPECT_GT(err, 0.0);
                // err = g·per_g·(1 + O(g e^{X/5})): the ratio to the prediction tends to 1.
                EXPECT_NEAR(err / (g * per_g), 1.0, 3.0 * g * std::exp(X / 5.0) + 1e-8)
                    << to_string(c) << " g=" << g << " X=" << X;
                if (previous > 0.0) {
                    EXPECT_NEAR(previous / err, 10.0, 2.0) << "g=" << g;
                }
                previous = err;
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Eq. 2 → Eq. 4 as g → ∞ at fixed c = T²v_xy²/(σ²v_z²) (i.e. fixed σ/T, v_xy T/√g fixed).
// With N ~ Poisson(g), S_G = E[exp(−cg/4N)/N] and a second-order expansion about N = g gives
//   Eq.2/Eq.4 − 1 = K/g + O(1/g²),   K = (c²/16 − c + 2)/2.
// (c is kept away from the zeros of K, c = 8 ± 4√2.)

TEST(RegimeLimits, GaussianSeriesTendsToEq4AsOneOverG) {
    for (const Geometry& geom : test_geometries()) {
        const HandVector v = hand_vector(geom);
        const double vxy2 = v.vx * v.vx + v.vy * v.vy;
        const bool specular = vxy2 < 1e-20;
        for (double c : specular ? std::vector<double>{0.0} : std::vector<double>{0.5, 4.0, 30.0}) {
            // σ/T from c; at the specular direction (v_xy = 0) T is free.
            const double sigma_over_T = specular ? 0.2 : std::sqrt(vxy2 / (c * v.vz * v.vz));
            const double K = (c * c / 16.0 - c + 2.0) / 2.0;
            double previous = 0.0;
            for (double g = 10.0; g <= 1.01e6; g *= 10.0) {
                const double sigma = std::sqrt(g) / std::abs(v.vz);
                const double T = sigma / sigma_over_T;
                const ScatteredPower series =
                    power(geom, sigma, T, Correlation::Gaussian, Regime::Series);
                const ScatteredPower eq4 =
                    power(geom, sigma, T, Correlation::Gaussian, Regime::VeryRough);
                EXPECT_NEAR(series.g / g, 1.0, 1e-12);
                EXPECT_EQ(eq4.regime, Regime::VeryRough);
                const double err = series.diffuse / eq4.diffuse - 1.0;
                if (g >= 100.0) {
                    EXPECT_NEAR(g * err, K, 40.0 * (1.0 + std::abs(K)) / g + 1e-8 * g)
                        << "c=" << c << " g=" << g << " phi_s=" << geom.phi_s_rad;
                    EXPECT_LT(std::abs(err), 0.2 * std::abs(previous)) << "c=" << c << " g=" << g;
                }
                previous = err;
            }
            EXPECT_LT(std::abs(previous), 2e-5 * (1.0 + std::abs(K)));  // at g = 1e6
        }
    }
}

TEST(RegimeLimits, GaussianSeriesLimitRegimeIsEq4) {
    for (const Geometry& geom : test_geometries()) {
        const ScatteredPower a = power(geom, 2.0, 5.0, Correlation::Gaussian, Regime::VeryRough);
        const ScatteredPower b =
            power(geom, 2.0, 5.0, Correlation::Gaussian, Regime::VeryRoughSeriesLimit);
        EXPECT_DOUBLE_EQ(a.diffuse, b.diffuse);
        EXPECT_EQ(b.regime, Regime::VeryRoughSeriesLimit);
    }
}

// ---------------------------------------------------------------------------------------------
// Exponential correlation: series → g/(g² + T²v_xy²)^{3/2} at fixed d = T²v_xy²/g².
// With h(u) = (1+u)/((1+u)² + d)^{3/2}: series/limit − 1 = K/g + O(1/g²), K = (h''/h)(0)/2,
// (h''/h)(0) = (1 − 3/(1+d))² − 1 − 3(d − 1)/(1 + d)².

TEST(RegimeLimits, ExponentialSeriesTendsToItsSeriesLimitAsOneOverG) {
    for (const Geometry& geom : test_geometries()) {
        const HandVector v = hand_vector(geom);
        const double vxy = std::hypot(v.vx, v.vy);
        const bool specular = vxy < 1e-10;
        for (double d : specular ? std::vector<double>{0.0} : std::vector<double>{0.3, 2.0}) {
            const double a1 = 1.0 - 3.0 / (1.0 + d);
            const double K = (a1 * a1 - 1.0 - 3.0 * (d - 1.0) / ((1.0 + d) * (1.0 + d))) / 2.0;
            double previous = 0.0;
            for (double g = 10.0; g <= 1.01e6; g *= 10.0) {
                const double sigma = std::sqrt(g) / std::abs(v.vz);
                const double T = specular ? 3.0 : std::sqrt(d) * g / vxy;
                const double series =
                    power(geom, sigma, T, Correlation::Exponential, Regime::Series).diffuse;
                const ScatteredPower limit =
                    power(geom, sigma, T, Correlation::Exponential, Regime::VeryRoughSeriesLimit);
                EXPECT_EQ(limit.regime, Regime::VeryRoughSeriesLimit);
                const double err = series / limit.diffuse - 1.0;
                if (g >= 100.0) {
                    EXPECT_NEAR(g * err, K, 40.0 * (1.0 + std::abs(K)) / g + 1e-8 * g)
                        << "d=" << d << " g=" << g;
                    EXPECT_LT(std::abs(err), 0.2 * std::abs(previous)) << "d=" << d << " g=" << g;
                }
                previous = err;
            }
        }
    }
}

// Eq. 5 as published against the exact series at fixed c = T²v_xy²/(σ²v_z²) (fixed σ/T, Eq. 5's
// own variable). In units of 2πT²F²/A:
//   Eq. 5 = 1/(g (1+c)^{3/2}),  series limit = g/(g² + cg)^{3/2},
// so Eq.5 / limit = g^{−1/2} ((g + c)/(1 + c))^{3/2} exactly, ≈ g/(1+c)^{3/2} for g ≫ c:
// Eq. 5 overestimates the very-rough exponential diffuse term by a factor growing like g.
TEST(RegimeLimits, Eq5IsNotTheLargeGLimitOfTheExponentialSeries) {
    for (const Geometry& geom : test_geometries()) {
        const HandVector v = hand_vector(geom);
        const double vxy2 = v.vx * v.vx + v.vy * v.vy;
        const bool specular = vxy2 < 1e-20;
        for (double c : specular ? std::vector<double>{0.0} : std::vector<double>{0.5, 4.0}) {
            const double sigma_over_T = specular ? 0.2 : std::sqrt(vxy2 / (c * v.vz * v.vz));
            for (double g : {1.0, 10.0, 100.0, 1e4, 1e6}) {
                const double sigma = std::sqrt(g) / std::abs(v.vz);
                const double T = sigma / sigma_over_T;
                const double eq5 =
                    power(geom, sigma, T, Correlation::Exponential, Regime::VeryRough).diffuse;
                const double limit =
                    power(geom, sigma, T, Correlation::Exponential, Regime::VeryRoughSeriesLimit)
                        .diffuse;
                const double series =
                    power(geom, sigma, T, Correlation::Exponential, Regime::Series).diffuse;
                const double exact_ratio = std::pow((g + c) / (1.0 + c), 1.5) / std::sqrt(g);
                EXPECT_NEAR(eq5 / limit / exact_ratio, 1.0, 1e-12) << "c=" << c << " g=" << g;
                if (g >= 100.0) {
                    // Far from 1, and ≈ g/(1+c)^{3/2} within O(1/g).
                    const double ratio = eq5 / series;
                    EXPECT_GT(ratio, 5.0) << "c=" << c << " g=" << g;
                    EXPECT_NEAR(ratio / (g / std::pow(1.0 + c, 1.5)), 1.0, 30.0 / g)
                        << "c=" << c << " g=" << g;
                }
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Both series against the direct numerical Kirchhoff integral.

TEST(RegimeQuadrature, ExponentialSeriesMatchesKirchhoffIntegral) {
    const double F2 = 0.8, T = 2.0, area = 1e6;
    double worst = 0.0;
    for (double g : {0.01, 0.1, 0.5, 1.0, 3.0, 10.0, 30.0}) {
        for (double Tv : {0.0, 0.5, 2.0, 5.0, 10.0, 20.0}) {
            const double vxy2 = (Tv / T) * (Tv / T);
            const double series = diffuse_power_exponential_series(F2, T, area, g, vxy2);
            const double quad =
                diffuse_power_quadrature(Correlation::Exponential, F2, T, area, g, vxy2);
            const double err = std::abs(series / quad - 1.0);
            worst = std::max(worst, err);
            EXPECT_LE(err, 1e-7) << "g=" << g << " T*v_xy=" << Tv;
        }
    }
    char worst_text[32];
    std::snprintf(worst_text, sizeof worst_text, "%.2e", worst);
    RecordProperty("worst_relative_error", worst_text);
}

TEST(RegimeQuadrature, GaussianSeriesMatchesKirchhoffIntegral) {
    const double F2 = 1.3, T = 2.0, area = 1e6;
    int compared = 0;
    for (double g : {0.01, 0.1, 0.5, 1.0, 3.0, 10.0, 30.0}) {
        for (double Tv : {0.0, 0.5, 2.0, 5.0, 10.0, 20.0}) {
            const double vxy2 = (Tv / T) * (Tv / T);
            const double series = diffuse_power_gaussian_series(F2, T, area, g, vxy2);
            // The Gaussian lobe is e^{−T²v²/4n} small at large T·v and small g; the quadrature
            // of an oscillating O(1) integrand cannot resolve values far below its own rounding
            // (~1e−16 of the lobe peak), so those points are not compared.
            const double peak = diffuse_power_gaussian_series(F2, T, area, g, 0.0);
            if (series < 1e-8 * peak) continue;
            const double quad =
                diffuse_power_quadrature(Correlation::Gaussian, F2, T, area, g, vxy2);
            EXPECT_LE(std::abs(series / quad - 1.0), 1e-7) << "g=" << g << " T*v_xy=" << Tv;
            ++compared;
        }
    }
    EXPECT_GE(compared, 30);  // of 42: only the far tails at small g are left out
}

TEST(RegimeQuadrature, BadInputThrows) {
    EXPECT_THROW(diffuse_power_quadrature(Correlation::Gaussian, 1.0, 1.0, 1.0, -1.0, 0.0),
                 InvalidArgument);
    EXPECT_THROW(diffuse_power_quadrature(Correlation::Gaussian, 1.0, 0.0, 1.0, 1.0, 0.0),
                 InvalidArgument);
    EXPECT_THROW(diffuse_power_quadrature(Correlation::Exponential, 1.0, 1.0, -2.0, 1.0, 0.0),
                 InvalidArgument);
    EXPECT_THROW(diffuse_power_quadrature(Correlation::Exponential, 1.0, 1.0, 1.0, 1.0,
                                          std::numeric_limits<double>::quiet_NaN()),
                 InvalidArgument);
}

// ---------------------------------------------------------------------------------------------
// Coherent term ρ0² e^{−g} (Eq. 1).

TEST(RegimeCoherent, SpecularDirectionHasRho0OneAndCoherentEqualsExpMinusG) {
    for (double theta_deg : {0.0, 10.0, 45.0, 80.0}) {
        const Geometry geom = specular_geometry(deg_to_rad(theta_deg));
        const ScatteringVector v = scattering_vector(geom, kLambda);
        EXPECT_EQ(specular_amplitude_rho0(v.vx, v.vy, kPatch, kPatch), 1.0);
        for (double sigma : {0.005, 0.05, 0.2}) {
            for (Correlation c : {Correlation::Gaussian, Correlation::Exponential}) {
                const ScatteredPower p = power(geom, sigma, 1.0, c, Regime::Series);
                const double k = 2.0 * std::numbers::pi / kLambda;
                const double g =
                    sigma * sigma * 4.0 * k * k * std::pow(std::cos(deg_to_rad(theta_deg)), 2);
                EXPECT_NEAR(p.g / g, 1.0, 1e-14);
                EXPECT_NEAR(p.coherent / std::exp(-g), 1.0, 1e-14) << theta_deg << " " << sigma;
                EXPECT_DOUBLE_EQ(p.total, p.coherent + p.diffuse);
            }
        }
    }
}

TEST(RegimeCoherent, OffSpecularCoherentIsSincSquaredTimesExpMinusG) {
    for (const Geometry& geom : test_geometries()) {
        const HandVector v = hand_vector(geom);
        auto sinc = [](double x) { return x == 0.0 ? 1.0 : std::sin(x) / x; };
        const double rho0 = sinc(v.vx * kPatch) * sinc(v.vy * kPatch);
        const double sigma = 0.03;
        const ScatteredPower p = power(geom, sigma, 1.0, Correlation::Gaussian, Regime::Series);
        const double g = sigma * sigma * v.vz * v.vz;
        EXPECT_NEAR(p.coherent, rho0 * rho0 * std::exp(-g), 1e-12 * std::exp(-g));
        if (v.vx * v.vx + v.vy * v.vy > 1e-6) {
            EXPECT_LT(p.coherent, 1e-6 * std::exp(-g));
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Regime reporting.

TEST(RegimeAuto, PicksSeriesUnlessTheSecondTermIsBelowTolerance) {
    const Geometry spec = specular_geometry(deg_to_rad(20.0));
    const HandVector v = hand_vector(spec);
    for (Correlation c : {Correlation::Gaussian, Correlation::Exponential}) {
        // g ≈ 5e−15: the second term is ~1e−15 of the first → SlightlyRough.
        {
            const double sigma = std::sqrt(5e-15) / std::abs(v.vz);
            const ScatteredPower p = power(spec, sigma, 1.0, c, Regime::Auto);
            EXPECT_EQ(p.regime, Regime::SlightlyRough) << to_string(c);
            EXPECT_NEAR(p.g, 5e-15, 1e-27);
            const double series = power(spec, sigma, 1.0, c, Regime::Series).diffuse;
            EXPECT_NEAR(p.diffuse / series, 1.0, 1e-12);
        }
        for (double g : {1e-6, 0.05, 1.0, 40.0, 1e4}) {
            const double sigma = std::sqrt(g) / std::abs(v.vz);
            const ScatteredPower p = power(spec, sigma, 1.0, c, Regime::Auto);
            EXPECT_EQ(p.regime, Regime::Series) << to_string(c) << " g=" << g;
            EXPECT_NEAR(p.g / g, 1.0, 1e-13);
            EXPECT_EQ(p.roughness_class, roughness_class(g));
            EXPECT_EQ(p.diffuse, power(spec, sigma, 1.0, c, Regime::Series).diffuse);
        }
        // A looser tolerance lets Auto use the first term; the error stays within it.
        ModelOptions loose;
        loose.auto_tolerance = 0.01;
        const double sigma = std::sqrt(1e-3) / std::abs(v.vz);
        const ScatteredPower p = mean_scattered_power(spec, Surface{sigma, 1.0, c}, loose);
        EXPECT_EQ(p.regime, Regime::SlightlyRough);
        const double series = power(spec, sigma, 1.0, c, Regime::Series).diffuse;
        EXPECT_LT(std::abs(p.diffuse / series - 1.0), 0.01);
        EXPECT_GT(std::abs(p.diffuse / series - 1.0), 1e-5);
    }
}

TEST(RegimeAuto, ExplicitRegimesAreReportedAsRequestedAndClassFollowsG) {
    const Geometry geom = deg_geometry(30, 45, 60);
    for (Regime r :
         {Regime::Series, Regime::SlightlyRough, Regime::VeryRough, Regime::VeryRoughSeriesLimit}) {
        EXPECT_EQ(power(geom, 0.1, 1.0, Correlation::Gaussian, r).regime, r);
        EXPECT_EQ(power(geom, 0.1, 1.0, Correlation::Exponential, r).regime, r);
    }
    const HandVector v = hand_vector(geom);
    auto sigma_for = [&](double g) { return std::sqrt(g) / std::abs(v.vz); };
    EXPECT_EQ(
        power(geom, sigma_for(0.05), 1.0, Correlation::Gaussian, Regime::Auto).roughness_class,
        RoughnessClass::SlightlyRough);
    EXPECT_EQ(power(geom, sigma_for(1.0), 1.0, Correlation::Gaussian, Regime::Auto).roughness_class,
              RoughnessClass::ModeratelyRough);
    EXPECT_EQ(
        power(geom, sigma_for(50.0), 1.0, Correlation::Gaussian, Regime::Auto).roughness_class,
        RoughnessClass::VeryRough);
}

// ---------------------------------------------------------------------------------------------
// Options: radiometry and geometric factor.

TEST(RegimeOptions, IntensityIsRadianceOverCosThetaS) {
    for (const Geometry& geom : test_geometries()) {
        for (Regime r : {Regime::Series, Regime::VeryRough}) {
            for (Correlation c : {Correlation::Gaussian, Correlation::Exponential}) {
                const ScatteredPower rad =
                    power(geom, 0.2, 2.0, c, r, GeometricFactor::Beckmann, Radiometry::Radiance);
                const ScatteredPower inten =
                    power(geom, 0.2, 2.0, c, r, GeometricFactor::Beckmann, Radiometry::Intensity);
                EXPECT_DOUBLE_EQ(rad.brightness, rad.total);
                EXPECT_DOUBLE_EQ(inten.total, rad.total);
                EXPECT_NEAR(inten.brightness * std::cos(geom.theta_s_rad) / rad.brightness, 1.0,
                            1e-14);
            }
        }
    }
}

TEST(RegimeOptions, FactorSelectionScalesDiffuseByRatioOfFSquared) {
    for (const Geometry& geom : test_geometries()) {
        const double ci = std::cos(geom.theta_i_rad), cs = std::cos(geom.theta_s_rad);
        const double fb = hand_F_beckmann(geom);
        const std::vector<std::pair<GeometricFactor, double>> factors = {
            {GeometricFactor::VernoldHarvey, ci},
            {GeometricFactor::Beckmann, fb * fb},
            {GeometricFactor::Ogilvy, fb * fb * ci * ci},
            {GeometricFactor::Kirchhoff, fb * fb * ci * ci / (cs * cs)},
        };
        for (Regime r : {Regime::Series, Regime::SlightlyRough, Regime::VeryRough,
                         Regime::VeryRoughSeriesLimit}) {
            for (Correlation c : {Correlation::Gaussian, Correlation::Exponential}) {
                const ScatteredPower ref = power(geom, 0.15, 1.5, c, r, factors[0].first);
                for (const auto& [factor, F2] : factors) {
                    const ScatteredPower p = power(geom, 0.15, 1.5, c, r, factor);
                    EXPECT_NEAR(p.diffuse / ref.diffuse, F2 / factors[0].second, 1e-13 * F2 / ci)
                        << to_string(factor) << " " << to_string(r) << " " << to_string(c);
                    EXPECT_EQ(p.coherent, ref.coherent);  // F multiplies the diffuse term only
                }
            }
        }
    }
}

// very_rough_brightness is Eq. 4 / Eq. 5 without the constants πT²/(Aσ²k²) (2π for Eq. 5).
TEST(RegimeOptions, VeryRoughBrightnessIsEq4AndEq5WithoutConstants) {
    const double sigma = 3.0, T = 7.5, area = 4.0 * kPatch * kPatch;
    const double k = 2.0 * std::numbers::pi / kLambda;
    for (const Geometry& geom : test_geometries()) {
        for (Radiometry rad : {Radiometry::Radiance, Radiometry::Intensity}) {
            const double scale = std::numbers::pi * T * T / (area * sigma * sigma * k * k);
            const ScatteredPower g4 = power(geom, sigma, T, Correlation::Gaussian,
                                            Regime::VeryRough, GeometricFactor::Ogilvy, rad);
            const ScatteredPower e5 = power(geom, sigma, T, Correlation::Exponential,
                                            Regime::VeryRough, GeometricFactor::Ogilvy, rad);
            const double bg = very_rough_brightness(geom, sigma / T, Correlation::Gaussian,
                                                    GeometricFactor::Ogilvy, rad);
            const double be = very_rough_brightness(geom, sigma / T, Correlation::Exponential,
                                                    GeometricFactor::Ogilvy, rad);
            const double rf = radiometric_factor(rad, geom);
            EXPECT_NEAR(scale * bg / (g4.diffuse * rf), 1.0, 1e-12);
            EXPECT_NEAR(2.0 * scale * be / (e5.diffuse * rf), 1.0, 1e-12);
        }
    }
    EXPECT_THROW(very_rough_brightness(deg_geometry(10, 10, 0), 0.0, Correlation::Gaussian),
                 InvalidArgument);
    EXPECT_THROW(very_rough_brightness(Geometry{kPi / 2, 0.1, 0.0}, 0.3, Correlation::Gaussian),
                 InvalidArgument);
}

// ---------------------------------------------------------------------------------------------
// Bad input: each argument of mean_scattered_power, message starting with its name.

void expect_invalid_named(const Geometry& geom, const Surface& surface, const ModelOptions& opt,
                          const std::string& name, const std::string& what) {
    try {
        mean_scattered_power(geom, surface, opt);
        ADD_FAILURE() << what << ": no exception";
    } catch (const InvalidArgument& e) {
        EXPECT_EQ(std::string(e.what()).rfind(name + " ", 0), 0u)
            << what << ": message '" << e.what() << "' does not start with '" << name << " '";
    } catch (const std::exception& e) {
        ADD_FAILURE() << what << ": wrong exception type: " << e.what();
    }
}

TEST(RegimeBadInput, EveryArgumentOfMeanScatteredPowerIsValidated) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    const Geometry good{deg_to_rad(30), deg_to_rad(40), deg_to_rad(20)};
    const Surface surf{0.2, 1.0, Correlation::Gaussian};
    const ModelOptions opt;
    // The good inputs work.
    EXPECT_GT(mean_scattered_power(good, surf, opt).total, 0.0);

    expect_invalid_named({kPi / 2, 0.3, 0.0}, surf, opt, "theta_i", "theta_i = 90 deg");
    expect_invalid_named({-0.01, 0.3, 0.0}, surf, opt, "theta_i", "theta_i < 0");
    expect_invalid_named({nan, 0.3, 0.0}, surf, opt, "theta_i", "theta_i nan");
    expect_invalid_named({0.3, kPi / 2, 0.0}, surf, opt, "theta_s", "theta_s = 90 deg");
    expect_invalid_named({0.3, -1.0, 0.0}, surf, opt, "theta_s", "theta_s < 0");
    expect_invalid_named({0.3, 0.3, nan}, surf, opt, "phi_s", "phi_s nan");
    expect_invalid_named({0.3, 0.3, inf}, surf, opt, "phi_s", "phi_s inf");
    for (double bad : {0.0, -0.1, nan, inf}) {
        const std::string b = std::to_string(bad);
        expect_invalid_named(good, {bad, 1.0, Correlation::Gaussian}, opt, "sigma", "sigma " + b);
        expect_invalid_named(good, {0.2, bad, Correlation::Exponential}, opt, "T", "T " + b);
        ModelOptions o = opt;
        o.wavelength_um = bad;
        expect_invalid_named(good, surf, o, "wavelength", "wavelength " + b);
        o = opt;
        o.patch_x_um = bad;
        expect_invalid_named(good, surf, o, "patch_x", "patch_x " + b);
        o = opt;
        o.patch_y_um = bad;
        expect_invalid_named(good, surf, o, "patch_y", "patch_y " + b);
    }
    for (double bad : {0.0, 1.0, -1e-3, nan}) {
        ModelOptions o = opt;
        o.auto_tolerance = bad;
        expect_invalid_named(good, surf, o, "auto_tolerance", "auto_tolerance");
    }
}

}  // namespace
