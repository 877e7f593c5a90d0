// Geometry-only terms of the very-rough (Eq. 4 / Eq. 5) and Oren–Nayar models: the same values as
// the scalar functions at random geometries, the closed-form derivative against a Richardson
// central difference, and bad input named.
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/precomputed_terms.hpp"
#include "roughscope/scattering/reflectance_models.hpp"

using namespace roughscope;

namespace {

std::vector<Geometry> random_geometries(int n) {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> th(0.0, deg_to_rad(89.0)), ph(0.0, 2.0 * kPi);
    std::vector<Geometry> g;
    for (int k = 0; k < n; ++k) g.push_back({th(rng), th(rng), ph(rng)});
    g.push_back({0.0, 0.0, 0.0});                        // normal incidence and view
    g.push_back({0.5, 0.5, 0.0});                        // specular: q_xy = 0
    g.push_back({deg_to_rad(60), deg_to_rad(60), kPi});  // retro-reflection
    return g;
}

}  // namespace

TEST(VeryRoughTerms, AgreeWithTheScalarBrightness) {
    const std::vector<Geometry> geoms = random_geometries(400);
    std::vector<double> out(geoms.size());
    for (GeometricFactor f : {GeometricFactor::Beckmann, GeometricFactor::VernoldHarvey})
        for (Radiometry rad : {Radiometry::Radiance, Radiometry::Intensity}) {
            const VeryRoughTerms terms(geoms, f, rad);
            ASSERT_EQ(terms.size(), geoms.size());
            for (Correlation c : {Correlation::Gaussian, Correlation::Exponential})
                for (double m : {0.1, 0.4, 1.0, 3.0}) {
                    terms.brightness(m, c, out);
                    for (std::size_t k = 0; k < geoms.size(); ++k) {
                        const double s = very_rough_brightness(geoms[k], m, c, f, rad);
                        EXPECT_NEAR(out[k], s, 1e-13 * s + 1e-300) << k;
                    }
                }
        }
}

TEST(VeryRoughTerms, LogDerivativeMatchesRichardsonDifference) {
    const std::vector<Geometry> geoms = random_geometries(50);
    const VeryRoughTerms terms(geoms, GeometricFactor::VernoldHarvey, Radiometry::Radiance);
    const std::size_t n = geoms.size();
    std::vector<double> out(n), d(n), p1(n), m1(n), p2(n), m2(n);
    for (Correlation c : {Correlation::Gaussian, Correlation::Exponential})
        for (double m : {0.2, 0.7, 2.0}) {
            terms.brightness_and_log_derivative(m, c, out, d);
            const double h = 2e-4;  // truncation ~ (h b/m²)⁴ in the far Gaussian tail
            terms.brightness(m * std::exp(h), c, p1);
            terms.brightness(m * std::exp(-h), c, m1);
            terms.brightness(m * std::exp(2 * h), c, p2);
            terms.brightness(m * std::exp(-2 * h), c, m2);
            for (std::size_t k = 0; k < n; ++k) {
                const double fd = (8.0 * (p1[k] - m1[k]) - (p2[k] - m2[k])) / (12.0 * h);
                EXPECT_NEAR(d[k], fd, 1e-6 * (std::abs(fd) + out[k]) + 1e-300) << k;
            }
        }
}

TEST(VeryRoughTerms, RejectBadInputNamingIt) {
    const std::vector<Geometry> bad = {{0.1, 0.2, 0.0}, {deg_to_rad(90), 0.2, 0.0}};
    try {
        VeryRoughTerms t(bad, GeometricFactor::VernoldHarvey, Radiometry::Radiance);
        FAIL() << "accepted theta_i = 90 deg";
    } catch (const InvalidArgument& e) {
        EXPECT_NE(std::string(e.what()).find("geometry 1 theta_i"), std::string::npos) << e.what();
    }
    const std::vector<Geometry> ok = {{0.1, 0.2, 0.0}};
    const VeryRoughTerms t(ok, GeometricFactor::VernoldHarvey, Radiometry::Radiance);
    std::vector<double> out(1);
    EXPECT_THROW(t.brightness(0.0, Correlation::Gaussian, out), InvalidArgument);
    EXPECT_THROW(t.brightness(std::nan(""), Correlation::Exponential, out), InvalidArgument);
}

TEST(OrenNayarTerms, AgreeWithTheScalarRadianceAndSplitIntoRhoAndRhoSquared) {
    const std::vector<Geometry> geoms = random_geometries(400);
    const OrenNayarTerms terms(geoms);
    const std::size_t n = geoms.size();
    std::vector<double> out(n), A(n), B(n);
    for (double sigma : {0.0, 0.1, 0.5, 1.2})
        for (double rho : {0.0, 0.3, 1.0}) {
            terms.radiance({sigma, rho}, out);
            terms.components(sigma, A, B);
            for (std::size_t k = 0; k < n; ++k) {
                const double s = oren_nayar_radiance(geoms[k], {sigma, rho});
                EXPECT_NEAR(out[k], s, 1e-14 * std::abs(s) + 1e-300) << k;
                EXPECT_NEAR(rho * A[k] + rho * rho * B[k], s, 1e-14 * std::abs(s) + 1e-300) << k;
            }
            // σ = 0: Lambert (ρ/π cos θi), no inter-reflection term.
            if (sigma == 0.0)
                for (std::size_t k = 0; k < n; ++k) {
                    EXPECT_EQ(B[k], 0.0);
                    EXPECT_NEAR(A[k], std::cos(geoms[k].theta_i_rad) / kPi, 1e-16);
                }
        }
    EXPECT_THROW(terms.radiance({-0.1, 0.5}, out), InvalidArgument);
    EXPECT_THROW(terms.radiance({0.1, 1.5}, out), InvalidArgument);
    EXPECT_THROW(terms.components(std::nan(""), A, B), InvalidArgument);
    const std::vector<Geometry> bad = {{0.1, deg_to_rad(95), 0.0}};
    EXPECT_THROW(OrenNayarTerms{bad}, InvalidArgument);
}
