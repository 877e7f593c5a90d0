// Scattering vector, g and the geometric factors of §3.1–3.2.
#include <cmath>

#include <gtest/gtest.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/scattering/factors.hpp"

using namespace roughscope;

TEST(ScatteringVector, IsKTimesLightPlusViewDifference) {
    // Independent fact: with L, V pointing away from the surface and the incident wave
    // travelling along −L, the scattering vector is k(V − (−L)) up to sign conventions:
    // v = −k (L + V) in the x and z components and −k V_y in y (paper §3.1 definitions).
    const Geometry g{0.4, 0.9, 2.1};
    const double lambda = 0.555, k = 2 * kPi / lambda;
    const Eigen::Vector3d L = light_direction(g), V = view_direction(g);
    const ScatteringVector v = scattering_vector(g, lambda);
    EXPECT_NEAR(v.vx, -k * (L.x() + V.x()), 1e-12);
    EXPECT_NEAR(v.vy, -k * (L.y() + V.y()), 1e-12);
    EXPECT_NEAR(v.vz, -k * (L.z() + V.z()), 1e-12);
}

TEST(ScatteringVector, SpecularAndRetroSpecialCases) {
    const double t = 0.6, lambda = 0.5, k = 2 * kPi / lambda;
    const ScatteringVector s = scattering_vector(specular_geometry(t), lambda);
    EXPECT_NEAR(s.vxy2(), 0.0, 1e-20);  // v_xy = 0 in the specular direction (§3.1)
    const ScatteringVector r = scattering_vector(retro_geometry(t), lambda);
    EXPECT_NEAR(std::sqrt(r.vxy2()), 2 * k * std::sin(t), 1e-12);  // §3.4: v_xy = 2k sin θ
    EXPECT_NEAR(r.vz, -2 * k * std::cos(t), 1e-12);                // §3.4: v_z = −2k cos θ
    // §4.1.2, normal view: v_xy = k sin θi, v_z = −k(1 + cos θi).
    const ScatteringVector n = scattering_vector(normal_view_geometry(t), lambda);
    EXPECT_NEAR(std::sqrt(n.vxy2()), k * std::sin(t), 1e-12);
    EXPECT_NEAR(n.vz, -k * (1 + std::cos(t)), 1e-12);
}

TEST(RoughnessG, MatchesEq12Exponent) {
    // Eq. 12: g(θ, θ) = (4πσ cos θ / λ)².
    const double sigma = 0.1, lambda = 0.555, t = deg_to_rad(14);
    EXPECT_NEAR(roughness_g(specular_geometry(t), sigma, lambda),
                std::pow(4 * kPi * sigma * std::cos(t) / lambda, 2), 1e-12);
}

TEST(GeometricFactor, NormalIncidenceAndRetroValues) {
    const Geometry normal{0.0, 0.0, 0.0};
    for (auto f : {GeometricFactor::Beckmann, GeometricFactor::VernoldHarvey,
                   GeometricFactor::Ogilvy, GeometricFactor::Kirchhoff})
        EXPECT_NEAR(geometric_factor_squared(f, normal), 1.0, 1e-15) << to_string(f);
    const double t = 0.8;
    // §3.4: F_Beck(θ, θ, π) = 1/cos²θ.
    EXPECT_NEAR(geometric_factor_beckmann(retro_geometry(t)), 1 / std::pow(std::cos(t), 2), 1e-12);
    // §4.1.2: F(θi, 0, 0) = 1/cos θi for the normal view.
    EXPECT_NEAR(geometric_factor_beckmann(normal_view_geometry(t)), 1 / std::cos(t), 1e-12);
}

TEST(GeometricFactor, RelationsBetweenFactors) {
    const Geometry g{0.5, 1.1, 0.7};
    const double fb2 = geometric_factor_squared(GeometricFactor::Beckmann, g);
    const double ci = std::cos(g.theta_i_rad), cs = std::cos(g.theta_s_rad);
    EXPECT_NEAR(geometric_factor_squared(GeometricFactor::Ogilvy, g), fb2 * ci * ci, 1e-12);
    EXPECT_NEAR(geometric_factor_squared(GeometricFactor::Kirchhoff, g), fb2 * ci * ci / (cs * cs),
                1e-12);
    EXPECT_DOUBLE_EQ(geometric_factor_squared(GeometricFactor::VernoldHarvey, g), ci);
}

TEST(GeometricFactor, BeckmannFactorIsHalfTheSquaredScatteringVectorOverCosines) {
    // Independent identity: 1 + cos θi cos θs − sin θi sin θs cos φs = |v|²/(2k²), so
    // F_Beck = |v|² / (2k² cos θi (cos θi + cos θs)).
    const Geometry g{0.3, 0.9, 2.5};
    const ScatteringDirection q = scattering_direction(g);
    const double v2 = q.qxy2() + q.qz2();
    const double ci = std::cos(g.theta_i_rad), cs = std::cos(g.theta_s_rad);
    EXPECT_NEAR(geometric_factor_beckmann(g), v2 / (2 * ci * (ci + cs)), 1e-12);
}

TEST(Radiometry, IntensityDividesByCosThetaS) {
    const Geometry g{0.3, 1.0, 0.0};
    EXPECT_DOUBLE_EQ(radiometric_factor(Radiometry::Radiance, g), 1.0);
    EXPECT_NEAR(radiometric_factor(Radiometry::Intensity, g), 1 / std::cos(1.0), 1e-15);
}

TEST(Names, ParseAndPrintRoundTrip) {
    for (auto f : {GeometricFactor::Beckmann, GeometricFactor::VernoldHarvey,
                   GeometricFactor::Ogilvy, GeometricFactor::Kirchhoff})
        EXPECT_EQ(parse_geometric_factor(to_string(f)), f);
    EXPECT_EQ(parse_geometric_factor("Vernold-Harvey"), GeometricFactor::VernoldHarvey);
    EXPECT_EQ(parse_radiometry("intensity"), Radiometry::Intensity);
    try {
        parse_geometric_factor("lambert");
        FAIL();
    } catch (const InvalidArgument& e) {
        EXPECT_NE(std::string(e.what()).find("valid values: vh, beckmann"), std::string::npos);
    }
    EXPECT_THROW(parse_radiometry(""), InvalidArgument);
}
