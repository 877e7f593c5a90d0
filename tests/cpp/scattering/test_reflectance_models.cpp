// Comparison models (Lambert, Oren–Nayar, Lafortune) and the validity quantities of §3.5.
#include <cmath>

#include <gtest/gtest.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/scattering/reflectance_models.hpp"
#include "roughscope/scattering/validity.hpp"

using namespace roughscope;

TEST(Lambert, IsCosine) {
    EXPECT_DOUBLE_EQ(lambert_brightness(0.0), 1.0);
    EXPECT_NEAR(lambert_brightness(deg_to_rad(60)), 0.5, 1e-15);
    EXPECT_THROW(lambert_brightness(deg_to_rad(90)), InvalidArgument);
}

TEST(OrenNayar, ZeroRoughnessIsLambert) {
    for (double ti : {0.0, 0.3, 1.2})
        for (double ts : {0.0, 0.7, 1.4})
            for (double ps : {0.0, 1.0, kPi}) {
                const Geometry g{ti, ts, ps};
                const double lam = 0.8 / kPi * std::cos(ti);
                EXPECT_NEAR(oren_nayar_radiance(g, {0.0, 0.8}), lam, 1e-15);
                EXPECT_NEAR(oren_nayar_qualitative_radiance(g, {0.0, 0.8}), lam, 1e-15);
            }
}

TEST(OrenNayar, RetroBrighteningAndReciprocityOfTheQualitativeModel) {
    const OrenNayarParams p{0.4, 0.6};
    const double t = 1.0;
    // Rough matte surfaces look brighter towards the source (Oren & Nayar; paper §1).
    EXPECT_GT(oren_nayar_radiance(retro_geometry(t), p),
              oren_nayar_radiance(specular_geometry(t), p));
    // The qualitative model's BRDF (radiance / cos θi) is symmetric in θi ↔ θs.
    const Geometry a{0.3, 0.9, kPi}, b{0.9, 0.3, kPi};
    EXPECT_NEAR(oren_nayar_qualitative_radiance(a, p) / std::cos(0.3),
                oren_nayar_qualitative_radiance(b, p) / std::cos(0.9), 1e-14);
    // In the specular half-plane (cos(φr − φi) = −1) the qualitative model reduces to A.
    const double s2 = p.sigma_rad * p.sigma_rad;
    EXPECT_NEAR(oren_nayar_qualitative_radiance(Geometry{0.5, 0.5, 0.0}, p),
                p.albedo / kPi * std::cos(0.5) * (1 - 0.5 * s2 / (s2 + 0.33)), 1e-15);
}

TEST(OrenNayar, InterreflectionTermAddsLightProportionalToAlbedoSquared) {
    // L2 ∝ ρ²: (L(ρ) − ρ L(1))/(ρ² − ρ) is independent of ρ.
    const Geometry g{0.6, 0.2, 0.4};
    const double s = 0.35;
    const double L1 = oren_nayar_radiance(g, {s, 1.0});
    auto l2 = [&](double rho) {
        return (oren_nayar_radiance(g, {s, rho}) - rho * L1) / (rho * rho - rho);
    };
    EXPECT_NEAR(l2(0.2), l2(0.7), 1e-14);
    EXPECT_GT(l2(0.5), 0.0);  // the inter-reflected light is positive
}

TEST(OrenNayar, BadParametersThrow) {
    const Geometry g{0.2, 0.2, 0.0};
    EXPECT_THROW(oren_nayar_radiance(g, {-0.1, 0.5}), InvalidArgument);
    EXPECT_THROW(oren_nayar_radiance(g, {0.1, 1.5}), InvalidArgument);
    EXPECT_THROW(oren_nayar_qualitative_radiance(g, {NAN, 0.5}), InvalidArgument);
    EXPECT_THROW(oren_nayar_radiance(Geometry{0.2, kPi / 2, 0}, {0.1, 0.5}), InvalidArgument);
}

TEST(Lafortune, DiffuseLobeAndGeneralLobeAgree) {
    const Geometry g{0.4, 0.8, 2.0};
    const double n = 3.5;
    const double ci = std::cos(0.4), cs = std::cos(0.8);
    EXPECT_NEAR(lafortune_diffuse_brightness(g, n), std::pow(ci * cs, n) * ci, 1e-15);
    EXPECT_NEAR(lafortune_brdf(g, {{0, 0, 1, n, 1}}) * ci, lafortune_diffuse_brightness(g, n),
                1e-15);
    // A mirror-like lobe (Cx = Cy = −1, Cz = 1) peaks in the specular direction: the bracket
    // equals L·R(V) which is 1 there.
    const LafortuneLobe mirror{-1, -1, 1, 20, 1};
    EXPECT_NEAR(lafortune_brdf(specular_geometry(0.5), {mirror}), 1.0, 1e-12);
    EXPECT_LT(lafortune_brdf(Geometry{0.5, 0.5, 0.3}, {mirror}), 1.0);
    // Negative lobe cosine is a physical zero (retro at θ = 1 rad: cos²θ − sin²θ < 0);
    // rho_d adds a Lambertian ρd/π.
    EXPECT_DOUBLE_EQ(lafortune_brdf(retro_geometry(1.0), {mirror}, 0.0), 0.0);
    EXPECT_NEAR(lafortune_brdf(retro_geometry(0.5), {}, 0.5), 0.5 / kPi, 1e-16);
}

TEST(Lafortune, BadParametersThrow) {
    const Geometry g{0.4, 0.8, 2.0};
    EXPECT_THROW(lafortune_diffuse_brightness(g, 0.0), InvalidArgument);
    EXPECT_THROW(lafortune_brdf(g, {{0, 0, 1, -1, 1}}), InvalidArgument);
    EXPECT_THROW(lafortune_brdf(g, {{NAN, 0, 1, 1, 1}}), InvalidArgument);
    EXPECT_THROW(lafortune_brdf(g, {}, -0.1), InvalidArgument);
}

TEST(Validity, CaronQuantitiesReproduceTable2) {
    // Table 2: σ/T_G → θK (deg, rounded) and ξK (%, 1 decimal).
    struct Row {
        double m;
        int theta_K;
        double xi_K;
    };
    for (Row r : {Row{0.9126, 38, 25.9}, Row{0.4833, 56, 65.7}, Row{0.7104, 45, 39.1},
                  Row{0.7654, 43, 34.7}, Row{0.6332, 48, 46.4}, Row{0.6483, 47, 44.8},
                  Row{0.6964, 45, 40.3}}) {
        EXPECT_EQ(std::lround(rad_to_deg(caron_theta_K_rad(r.m))), r.theta_K) << r.m;
        EXPECT_NEAR(100 * caron_xi_K(r.m), r.xi_K, 0.05 + 1e-9) << r.m;
    }
    // §5.2 quotes the sandpapers to more digits: θK = 48.16° and 47.48°, ξK = 46.40 %, 44.83 %.
    EXPECT_NEAR(rad_to_deg(caron_theta_K_rad(0.6332)), 48.16, 0.005);
    EXPECT_NEAR(rad_to_deg(caron_theta_K_rad(0.6483)), 47.48, 0.005);
    EXPECT_NEAR(100 * caron_xi_K(0.6332), 46.40, 0.005);
    EXPECT_NEAR(100 * caron_xi_K(0.6483), 44.83, 0.005);
    EXPECT_NEAR(rms_slope(1.0), std::sqrt(2.0), 1e-15);
}

TEST(Validity, RoughnessClassThresholds) {
    EXPECT_EQ(roughness_class(0.01), RoughnessClass::SlightlyRough);
    EXPECT_EQ(roughness_class(1.0), RoughnessClass::ModeratelyRough);
    EXPECT_EQ(roughness_class(100.0), RoughnessClass::VeryRough);
    EXPECT_EQ(to_string(roughness_class(kVeryRoughMinG + 1)), "very_rough");
}
