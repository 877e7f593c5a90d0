// The correlation descriptor (correlation.hpp), checked for every correlation function in
// kCorrelations against independent facts: ρ(0) = 1, the spectrum and the series terms as
// numerical Hankel transforms of ρ and ρⁿ (§3.1), the very-rough profile's log and derivative,
// Eq. 4 as the g → ∞ limit of Eq. 2 (and Eq. 5 not that of the exact series), and the two-angle
// ratio (Eq. 16/18) against its inverse (Eq. 17/19) over the valid range.
#include <cmath>
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/estimation/estimation.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/correlation.hpp"
#include "roughscope/scattering/retro.hpp"

using namespace roughscope;

namespace {

std::string name_of(Correlation c) { return std::string(info(c).name); }

// 2π ∫₀^∞ f(u) J0(κu) u du by composite Simpson on [0, u_max] (f decays like e^{−u} at least).
template <class F>
double hankel_2pi(F&& f, double kappa, double u_max = 80.0, int intervals = 160000) {
    const double h = u_max / intervals;
    double sum = 0.0;
    for (int i = 0; i <= intervals; ++i) {
        const double u = i * h;
        const double w = (i == 0 || i == intervals) ? 1.0 : (i % 2 ? 4.0 : 2.0);
        sum += w * f(u) * std::cyl_bessel_j(0.0, kappa * u) * u;
    }
    return 2.0 * kPi * sum * h / 3.0;
}

}  // namespace

TEST(Correlation, TableIsInEnumOrderWithDistinctNames) {
    std::set<std::string> names, letters;
    for (std::size_t k = 0; k < kCorrelationCount; ++k) {
        EXPECT_EQ(index_of(kCorrelations[k]), k);
        EXPECT_EQ(kCorrelationInfo[k].correlation, kCorrelations[k]);
        names.insert(std::string(kCorrelationInfo[k].name));
        letters.insert(std::string(kCorrelationInfo[k].letter));
        EXPECT_TRUE(is_valid(kCorrelations[k]));
    }
    EXPECT_EQ(names.size(), kCorrelationCount);
    EXPECT_EQ(letters.size(), kCorrelationCount);
    EXPECT_FALSE(is_valid(static_cast<Correlation>(kCorrelationCount)));
    EXPECT_EQ(correlation_names_text(), "gaussian or exponential");
}

TEST(Correlation, NamesRoundTripAndGenerateTheDocumentedKeys) {
    for (const Correlation c : kCorrelations) {
        EXPECT_EQ(to_string(c), info(c).name);
        EXPECT_EQ(parse_correlation(info(c).name), c);
        EXPECT_EQ(parse_correlation(std::string(info(c).adjective)), c);  // case-insensitive
    }
    // The public JSON keys (docs/estimation.md, docs/cli.md) generated from the names.
    EXPECT_EQ(correlation_key("sigma_over_T", Correlation::Gaussian), "sigma_over_T_gaussian");
    EXPECT_EQ(correlation_key("sigma_over_T", Correlation::Exponential),
              "sigma_over_T_exponential");
    EXPECT_EQ(correlation_key("valid_ratio_range", Correlation::Exponential),
              "valid_ratio_range_exponential");
    EXPECT_EQ(correlation_key("T_um", Correlation::Gaussian), "T_um_gaussian");
    EXPECT_THROW(parse_correlation("lorentzian"), InvalidArgument);
}

TEST(Correlation, AcfIsOneAtZeroDecreasingAndBelowToleranceBeyondCutoff) {
    for (const Correlation c : kCorrelations) {
        EXPECT_EQ(acf(c, 0.0), 1.0) << name_of(c);
        EXPECT_NEAR(acf(c, 1.0), std::exp(-1.0), 1e-15) << name_of(c);  // T is the 1/e length
        double previous = 1.0;
        for (double u = 0.05; u < 10.0; u += 0.05) {
            EXPECT_LT(acf(c, u), previous) << name_of(c) << " u = " << u;
            previous = acf(c, u);
        }
        const double L = 41.5;
        EXPECT_NEAR(std::log(acf(c, acf_cutoff_over_T(c, L))), -L, 1e-12) << name_of(c);
    }
}

TEST(Correlation, PowerSpectrumIsTheHankelTransformOfTheAcf) {
    for (const Correlation c : kCorrelations)
        for (const double kappa : {0.0, 0.3, 1.0, 2.5, 5.0}) {
            const double numeric = hankel_2pi([c](double u) { return acf(c, u); }, kappa);
            EXPECT_NEAR(power_spectrum(c, kappa * kappa) / numeric, 1.0, 1e-8)
                << name_of(c) << " kappa = " << kappa;
        }
}

TEST(Correlation, SeriesTermsAreTheHankelTransformsOfAcfPowers) {
    // D = (2π/A) F² e^{−g} ∫ [exp(g C) − 1] J0 τ dτ = Σ gⁿ/n! (T²/A) F² e^{−g} 2π ∫ ρⁿ J0 u du:
    // prefactor · h(n) must be that transform (Eq. 2).
    for (const Correlation c : kCorrelations)
        for (const int n : {1, 2, 5})
            for (const double b : {0.0, 1.0, 10.0}) {
                const double numeric =
                    hankel_2pi([c, n](double u) { return std::pow(acf(c, u), n); }, std::sqrt(b));
                EXPECT_NEAR(info(c).diffuse_prefactor * series_term_weight(c, n, b) / numeric, 1.0,
                            1e-8)
                    << name_of(c) << " n = " << n << " b = " << b;
            }
}

TEST(Correlation, SlightlyRoughTermAndSecondTermRatioAreTheFirstSeriesTerms) {
    for (const Correlation c : kCorrelations)
        for (const double b : {0.0, 0.7, 12.0})
            for (const double g : {1e-6, 0.01, 0.3}) {
                EXPECT_NEAR(power_spectrum(c, b) /
                                (info(c).diffuse_prefactor * series_term_weight(c, 1.0, b)),
                            1.0, 1e-14);
                EXPECT_NEAR(second_term_ratio(c, g, b) / (g / 2.0 * series_term_weight(c, 2.0, b) /
                                                          series_term_weight(c, 1.0, b)),
                            1.0, 1e-13)
                    << name_of(c);
                // Eq. 3 (and its exponential twin) = the n = 1 term of the summed series.
                const double F2 = 0.8, T = 2.0, area = 1e4, vxy2 = b / (T * T);
                const double series = diffuse_power_series(c, F2, T, area, g, vxy2);
                const double first = diffuse_power_slightly_rough(c, F2, T, area, g, vxy2);
                const double ratio = second_term_ratio(c, g, b);
                EXPECT_LE(std::abs(series - first), 1.01 * ratio / (1.0 - ratio) * first)
                    << name_of(c) << " g = " << g << " b = " << b;
            }
}

TEST(Correlation, VeryRoughProfileLogAndLogDerivativeAgree) {
    for (const Correlation c : kCorrelations) {
        EXPECT_EQ(very_rough_profile(c, 0.0), 1.0);
        for (const double t2 : {1e-3, 0.5, 3.0, 40.0}) {
            EXPECT_NEAR(std::log(very_rough_profile(c, t2)), log_very_rough_profile(c, t2),
                        1e-13 * std::max(1.0, std::abs(log_very_rough_profile(c, t2))))
                << name_of(c);
            // t² ∝ (σ/T)^{−2}: d ln P/d ln(σ/T) = −2 t² d ln P/d t².
            const double h = 1e-5;
            const double numeric = (log_very_rough_profile(c, t2 * std::exp(-2.0 * h)) -
                                    log_very_rough_profile(c, t2 * std::exp(2.0 * h))) /
                                   (2.0 * h);
            EXPECT_NEAR(d_log_very_rough_profile_d_log_slope(c, t2), numeric,
                        1e-7 * std::max(1.0, std::abs(numeric)))
                << name_of(c) << " t2 = " << t2;
        }
    }
}

TEST(Correlation, ClosedFormIsTheSeriesLimitExactlyWhereTheTableSaysSo) {
    // At g = 1e8 the exact series is within ~1e−8 of its g → ∞ limit (Eq. 2 → Eq. 4); Eq. 5 as
    // published differs from the exponential series' limit by O(1) off the specular direction.
    const double F2 = 0.9, T = 1.5, area = 1e6, vz2 = 4.0;
    for (const Correlation c : kCorrelations) {
        const double g = 1e8, sigma = std::sqrt(g / vz2);
        const double vxy2 = 0.3 * sigma * sigma * vz2 / (T * T);  // t² = 0.3: inside the lobe
        const double series = diffuse_power_series(c, F2, T, area, g, vxy2);
        const double limit =
            diffuse_power_very_rough_series_limit(c, F2, sigma, T, area, g, vz2, vxy2);
        const double closed = diffuse_power_very_rough(c, F2, sigma, T, area, vz2, vxy2);
        EXPECT_NEAR(series / limit, 1.0, 1e-6) << name_of(c);
        if (info(c).closed_form_is_series_limit) {
            EXPECT_NEAR(closed / series, 1.0, 1e-6) << name_of(c);
        } else {
            EXPECT_GT(std::abs(closed / series - 1.0), 1e-2) << name_of(c);
        }
    }
}

TEST(Correlation, RatioAndInverseAreInverseOverTheValidRange) {
    const NormalViewPair pairs[] = {{0.1, 0.7, 1.3}, {0.9, 0.05, 0.6}, {0.0, 0.4, 1.0}};
    for (const Correlation c : kCorrelations)
        for (const NormalViewPair& p : pairs) {
            const RatioRange range = normal_view_ratio_range(c, p);
            for (double s = 0.05; s < 20.0; s *= 1.37) {
                const double r = normal_view_ratio(c, p, s);
                EXPECT_TRUE(range.contains(r) || r == range.lower || r == range.upper)
                    << name_of(c) << " s = " << s << " r = " << r;
                if (!range.contains(r)) continue;  // rounded onto a limit
                EXPECT_NEAR(sigma_over_T_from_normal_view_ratio(c, p, r) / s, 1.0, 1e-9)
                    << name_of(c) << " s = " << s;
                // d(σ/T)/d ln r against a central difference of the inverse.
                const double h = 1e-6;
                const double numeric =
                    (sigma_over_T_from_normal_view_ratio(c, p, r * std::exp(h)) -
                     sigma_over_T_from_normal_view_ratio(c, p, r * std::exp(-h))) /
                    (2.0 * h);
                EXPECT_NEAR(d_sigma_over_T_d_log_ratio(c, p, r, s), numeric,
                            1e-5 * std::abs(numeric) + 1e-12)
                    << name_of(c) << " s = " << s;
            }
            // Outside the range: no solution (NaN), never a number.
            if (range.lower > 0.0) {
                EXPECT_TRUE(
                    std::isnan(sigma_over_T_from_normal_view_ratio(c, p, 0.5 * range.lower)))
                    << name_of(c);
            }
            if (std::isfinite(range.upper)) {
                EXPECT_TRUE(
                    std::isnan(sigma_over_T_from_normal_view_ratio(c, p, 2.0 * range.upper)))
                    << name_of(c);
            }
        }
}

TEST(Correlation, EstimatorsInvertTheModelRatioForEveryCorrelation) {
    // Eq. 17/19 through the validated API against the forward model of beckmann.hpp.
    const double t1 = deg_to_rad(10.0), t2 = deg_to_rad(55.0);
    for (const Correlation c : kCorrelations)
        for (const double s : {0.2, 0.5, 1.0, 3.0}) {
            const double r =
                model_ratio_very_rough(normal_view_geometry(t1), normal_view_geometry(t2), s, c);
            EXPECT_TRUE(ratio_range(c, t1, t2).contains(r)) << name_of(c);
            EXPECT_NEAR(sigma_over_T_from_ratio(c, r, t1, t2) / s, 1.0, 1e-10) << name_of(c);
            EXPECT_NEAR(sigma_over_T_two_geometries(r, normal_view_geometry(t1),
                                                    normal_view_geometry(t2), c) /
                            s,
                        1.0, 1e-10)
                << name_of(c);
        }
    for (const Correlation c : kCorrelations) {
        const RatioRange range = ratio_range(c, t1, t2);
        EXPECT_THROW(sigma_over_T_from_ratio(c, 0.5 * range.lower, t1, t2), NoSolution);
    }
}

TEST(Correlation, RetroFormsAreTheVeryRoughShapeAtRetroGeometry) {
    // Eq. 7–10 = very_rough_shape at θi = θs = θ, φs = π up to a θ-independent constant.
    for (const Correlation c : kCorrelations)
        for (const GeometricFactor f :
             {GeometricFactor::Beckmann, GeometricFactor::VernoldHarvey}) {
            double constant = 0.0;
            for (double deg = 0.0; deg < 80.0; deg += 7.5) {
                const Geometry g = retro_geometry(deg_to_rad(deg));
                const double shape = very_rough_shape(c, geometric_factor_squared(f, g),
                                                      scattering_direction(g), 0.8);
                const double ratio = shape / retro_very_rough(c, f, deg_to_rad(deg), 0.8);
                if (constant == 0.0) constant = ratio;
                EXPECT_NEAR(ratio / constant, 1.0, 1e-12) << name_of(c) << " " << deg;
            }
        }
    EXPECT_THROW(retro_very_rough(Correlation::Gaussian, GeometricFactor::Ogilvy, 0.3, 1.0),
                 InvalidArgument);
}
