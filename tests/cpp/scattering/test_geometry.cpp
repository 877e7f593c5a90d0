// Geometry of §2: angles from N, L, V; the CUReT-style frame; special cases.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/scattering/geometry.hpp"

using namespace roughscope;

namespace {
Eigen::Vector3d spherical(double theta, double phi) {
    return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}
}  // namespace

TEST(Geometry, VectorsRoundTripThroughPaperFrame) {
    // Build L and V in the paper's frame from known angles, rotate the whole scene by a random
    // rotation (the angles must not change), and recover θi, θs, φs.
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> pol(0.01, 1.5), az(0.0, kPi);
    for (int trial = 0; trial < 200; ++trial) {
        const Geometry truth{pol(rng), pol(rng), az(rng)};
        const Eigen::Matrix3d R =
            Eigen::Quaterniond(Eigen::Vector4d::Random().normalized()).toRotationMatrix();
        const auto got = geometry_from_vectors(
            R * Eigen::Vector3d::UnitZ(), R * light_direction(truth), R * view_direction(truth));
        ASSERT_TRUE(got.has_value());
        EXPECT_NEAR(got->theta_i_rad, truth.theta_i_rad, 1e-12);
        EXPECT_NEAR(got->theta_s_rad, truth.theta_s_rad, 1e-12);
        EXPECT_NEAR(got->phi_s_rad, truth.phi_s_rad, 1e-7);  // acos near 0/π: √eps
    }
}

TEST(Geometry, LightAzimuthIsPiByConstruction) {
    // The projection of L onto the tangent plane points along −X0 (Fig. 2).
    const Eigen::Vector3d L = light_direction(Geometry{0.7, 0.2, 0.3});
    EXPECT_LT(L.x(), 0.0);
    EXPECT_DOUBLE_EQ(L.y(), 0.0);
    EXPECT_NEAR(L.norm(), 1.0, 1e-15);
}

TEST(Geometry, SpecialCasesFromVectors) {
    const Eigen::Vector3d N = Eigen::Vector3d::UnitZ();
    const double t = deg_to_rad(35.0);
    const Eigen::Vector3d L = spherical(t, kPi);
    // Retro: V = L → θi = θs, φs = π.
    auto retro = geometry_from_vectors(N, L, L);
    ASSERT_TRUE(retro);
    EXPECT_NEAR(retro->phi_s_rad, kPi, 1e-12);
    EXPECT_NEAR(retro->theta_s_rad, t, 1e-12);
    // Specular: V is the mirror image of L → φs = 0.
    auto spec = geometry_from_vectors(N, L, spherical(t, 0.0));
    ASSERT_TRUE(spec);
    EXPECT_NEAR(spec->phi_s_rad, 0.0, 1e-7);
    // Normal view: V = N → θs = 0, φs = 0 by convention.
    auto nv = geometry_from_vectors(N, L, N);
    ASSERT_TRUE(nv);
    EXPECT_DOUBLE_EQ(nv->theta_s_rad, 0.0);
    EXPECT_DOUBLE_EQ(nv->phi_s_rad, 0.0);
    EXPECT_NEAR(nv->theta_i_rad, t, 1e-12);
}

TEST(Geometry, BelowHorizonIsAPhysicalZeroNotAnError) {
    const Eigen::Vector3d N = Eigen::Vector3d::UnitZ();
    EXPECT_FALSE(geometry_from_vectors(N, spherical(deg_to_rad(100.0), 0.0), N).has_value());
    EXPECT_FALSE(geometry_from_vectors(N, N, spherical(deg_to_rad(90.0), 1.0)).has_value());
}

TEST(Geometry, VectorsMustBeUnitAndFinite) {
    const Eigen::Vector3d N = Eigen::Vector3d::UnitZ();
    EXPECT_THROW(geometry_from_vectors(2.0 * N, N, N), InvalidArgument);
    EXPECT_THROW(geometry_from_vectors(N, Eigen::Vector3d(0, 0, NAN), N), InvalidArgument);
    EXPECT_THROW(geometry_from_vectors(N, N, Eigen::Vector3d::Zero()), InvalidArgument);
    try {
        geometry_from_vectors(N, Eigen::Vector3d(0, 0, 1.5), N);
        FAIL();
    } catch (const InvalidArgument& e) {
        EXPECT_NE(std::string(e.what()).find("L (light direction)"), std::string::npos);
        EXPECT_NE(std::string(e.what()).find("unit vector"), std::string::npos);
    }
}

TEST(Geometry, TwoAzimuthFrameMatchesVectorGeometry) {
    // CUReT frame: both azimuths given. φs = φv − φi + π must agree with the geometry computed
    // from the same directions as vectors (paper §2), for φs folded into [0, π].
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> pol(0.05, 1.5), az(-kPi, 3 * kPi);
    for (int trial = 0; trial < 200; ++trial) {
        const double ti = pol(rng), tv = pol(rng), pi = az(rng), pv = az(rng);
        const Geometry g = geometry_from_two_azimuths(ti, pi, tv, pv);
        const auto w =
            geometry_from_vectors(Eigen::Vector3d::UnitZ(), spherical(ti, pi), spherical(tv, pv));
        ASSERT_TRUE(w);
        EXPECT_NEAR(g.theta_i_rad, w->theta_i_rad, 1e-12);
        EXPECT_NEAR(g.theta_s_rad, w->theta_s_rad, 1e-12);
        const double folded = g.phi_s_rad > kPi ? 2 * kPi - g.phi_s_rad : g.phi_s_rad;
        EXPECT_NEAR(folded, w->phi_s_rad, 1e-7);
        EXPECT_GE(g.phi_s_rad, 0.0);
        EXPECT_LT(g.phi_s_rad, 2 * kPi);
    }
    // CUReT measurement 81: θv = 0, θi = 45°, φi = 0 → the paper's normal-view case.
    const Geometry m81 = geometry_from_two_azimuths(deg_to_rad(45), 0.0, 0.0, 0.0);
    EXPECT_NEAR(m81.phi_s_rad, kPi, 1e-15);  // irrelevant at θs = 0, but defined
    EXPECT_DOUBLE_EQ(m81.theta_s_rad, 0.0);
}

TEST(Geometry, MakeGeometryValidatesPolarAnglesAndWrapsAzimuth) {
    const Geometry g = make_geometry(0.1, 0.2, -kPi / 2);
    EXPECT_NEAR(g.phi_s_rad, 1.5 * kPi, 1e-15);
    EXPECT_THROW(make_geometry(kPi / 2, 0.1, 0.0), InvalidArgument);
    EXPECT_THROW(make_geometry(-0.01, 0.1, 0.0), InvalidArgument);
    EXPECT_THROW(make_geometry(0.1, NAN, 0.0), InvalidArgument);
    EXPECT_THROW(make_geometry(0.1, 0.1, INFINITY), InvalidArgument);
    EXPECT_THROW(retro_geometry(deg_to_rad(90.0)), InvalidArgument);
    try {
        make_geometry(deg_to_rad(95.0), 0.0, 0.0);
        FAIL();
    } catch (const InvalidArgument& e) {
        EXPECT_STREQ(e.what(), "theta_i = 95 deg is outside the valid range [0, 90) deg");
    }
}
