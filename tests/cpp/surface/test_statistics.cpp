// Height statistics (statistics.hpp): moments against their definitions, the FFT row/column ACF
// against brute-force sums, T from the 1/e crossing and the AIC model choice on profiles of known
// ACF, the length extrapolation, slopes, uncertainties, names and every InvalidArgument path.
#include <cmath>
#include <cstddef>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/surface/statistics.hpp"
#include "test_statistics_data.hpp"

namespace roughscope::surface {
namespace {

using testdata::kNaN;

// ---- brute force -------------------------------------------------------------------------------
// C_j along x (rows) or y (columns) straight from the definitions (docs/surface.md).
std::vector<double> brute_acf(const HeightMap& m, bool along_y, AcfEstimator est,
                              std::vector<double>* lags_with_pairs) {
    const std::size_t n = along_y ? m.ny : m.nx;
    const std::size_t lines = along_y ? m.nx : m.ny;
    std::vector<double> S(n, 0.0), P(n, 0.0);
    for (std::size_t l = 0; l < lines; ++l)
        for (std::size_t j = 0; j < n; ++j)
            for (std::size_t k = 0; k + j < n; ++k) {
                const double a = along_y ? m.at(l, k) : m.at(k, l);
                const double b = along_y ? m.at(l, k + j) : m.at(k + j, l);
                if (std::isnan(a) || std::isnan(b)) continue;
                S[j] += a * b;
                P[j] += 1;
            }
    std::vector<double> c;
    for (std::size_t j = 0; j < n; ++j) {
        if (P[j] == 0) continue;
        lags_with_pairs->push_back(static_cast<double>(j) * (along_y ? m.dy_um : m.dx_um));
        c.push_back(est == AcfEstimator::Biased ? S[j] / S[0] : (S[j] / P[j]) / (S[0] / P[0]));
    }
    return c;
}

void expect_curves_near(const Curve& a, const Curve& b, double tol) {
    ASSERT_EQ(a.x.size(), b.x.size());
    ASSERT_EQ(a.y.size(), b.y.size());
    for (std::size_t i = 0; i < a.x.size(); ++i) {
        EXPECT_NEAR(a.x[i], b.x[i], 1e-12) << i;
        EXPECT_NEAR(a.y[i], b.y[i], tol) << i;
    }
}

// ---- ACF ----------------------------------------------------------------------------------------
TEST(SurfaceAcf, RowsAndColumnsMatchBruteForceSumsWithMissingPoints) {
    HeightMap m = testdata::noise_map(37, 23, 11, 0.15);
    m.at(0, 3) = kNaN;  // a row with a missing first point
    for (std::size_t ix = 0; ix < m.nx; ++ix) m.at(ix, 5) = kNaN;  // a fully missing row
    for (AcfEstimator est : {AcfEstimator::Unbiased, AcfEstimator::Biased}) {
        for (bool along_y : {false, true}) {
            Curve expected;
            expected.y = brute_acf(m, along_y, est, &expected.x);
            const Curve got = along_y ? acf_along_y(m, est) : acf_along_x(m, est);
            SCOPED_TRACE(to_string(est) + (along_y ? " y" : " x"));
            EXPECT_DOUBLE_EQ(got.y.at(0), 1.0);
            expect_curves_near(got, expected, 1e-12);
        }
    }
}

TEST(SurfaceAcf, FullRowsAndAProfileMatchBruteForce) {
    const HeightMap map = testdata::noise_map(64, 9, 5);
    const HeightMap profile = testdata::noise_map(101, 1, 6, 0.1);
    for (AcfEstimator est : {AcfEstimator::Unbiased, AcfEstimator::Biased}) {
        Curve e1, e2;
        e1.y = brute_acf(map, false, est, &e1.x);
        e2.y = brute_acf(profile, false, est, &e2.x);
        expect_curves_near(acf_along_x(map, est), e1, 1e-12);
        expect_curves_near(acf_along_x(profile, est), e2, 1e-12);
    }
    EXPECT_TRUE(acf_along_y(profile, AcfEstimator::Unbiased).x.empty());
}

TEST(SurfaceAcf, EstimatorsDifferByTheirNormalisation) {
    // Biased C_j = unbiased C_j · (N − j)/N for a full profile: the two must not coincide.
    const HeightMap p = testdata::noise_map(50, 1, 9);
    const Curve u = acf_along_x(p, AcfEstimator::Unbiased);
    const Curve b = acf_along_x(p, AcfEstimator::Biased);
    for (std::size_t j = 1; j < 50; ++j)
        EXPECT_NEAR(b.y[j], u.y[j] * static_cast<double>(50 - j) / 50.0, 1e-12);
}

TEST(SurfaceAcf, RejectsMalformedMaps) {
    HeightMap m = testdata::noise_map(8, 4, 1);
    m.heights_um.pop_back();
    EXPECT_THROW(acf_along_x(m, AcfEstimator::Unbiased), InvalidArgument);
    EXPECT_THROW(acf_along_y(m, AcfEstimator::Biased), InvalidArgument);
    HeightMap all_missing = make_height_map(4, 4, 1, 1);
    all_missing.heights_um.assign(16, kNaN);
    EXPECT_THROW(acf_along_x(all_missing, AcfEstimator::Unbiased), InvalidArgument);
}

// ---- T by the 1/e crossing
// -----------------------------------------------------------------------
TEST(SurfaceCorrelationLength, CrossingIsInterpolatedBetweenLags) {
    const Curve c{{0.0, 2.0, 4.0, 6.0}, {1.0, 0.5, 0.2, 0.1}};
    const double inv_e = std::exp(-1.0);
    EXPECT_DOUBLE_EQ(*correlation_length_1e(c), 2.0 + (0.5 - inv_e) / 0.3 * 2.0);
    const Curve never{{0.0, 1.0, 2.0}, {1.0, 0.9, 0.5}};
    EXPECT_FALSE(correlation_length_1e(never).has_value());
    EXPECT_FALSE(correlation_length_1e(Curve{}).has_value());
}

TEST(SurfaceCorrelationLength, SinusoidProfileCrossesWhereItsCosineAcfDoes) {
    // z = sin(2πx/Λ): C(τ) = cos(2πτ/Λ) (unbiased estimator over many periods), which falls to
    // 1/e at τ = Λ acos(1/e) / (2π).
    const std::size_t n = 200000;
    const double period_samples = 1000.0;
    HeightMap p = make_height_map(n, 1, 0.5, 0.5);
    for (std::size_t k = 0; k < n; ++k)
        p.heights_um[k] =
            std::sin(2.0 * std::numbers::pi * static_cast<double>(k) / period_samples);
    const double expected =
        period_samples * 0.5 * std::acos(std::exp(-1.0)) / (2 * std::numbers::pi);
    const auto T = correlation_length_1e(acf_along_x(p, AcfEstimator::Unbiased));
    ASSERT_TRUE(T.has_value());
    EXPECT_NEAR(*T / expected, 1.0, 2e-3);
}

// ---- fits and AIC
// --------------------------------------------------------------------------------
TEST(SurfaceAcfFit, ExactCurvesGiveTheirTAndModel) {
    Curve g, e;
    for (int j = 0; j <= 60; ++j) {
        const double tau = 0.5 * j;
        g.x.push_back(tau);
        e.x.push_back(tau);
        // Small deterministic "noise" so the RSS is not 0 for the true model.
        const double wiggle = 1e-4 * std::sin(1.7 * j);
        g.y.push_back(std::exp(-(tau / 7.0) * (tau / 7.0)) + wiggle);
        e.y.push_back(std::exp(-tau / 7.0) + wiggle);
    }
    const AcfModelFit fg = fit_acf_models(g, 21.0);
    const AcfModelFit fe = fit_acf_models(e, 21.0);
    EXPECT_EQ(fg.points, 43U);
    ASSERT_TRUE(fg.better && fe.better);
    EXPECT_EQ(*fg.better, Correlation::Gaussian);
    EXPECT_EQ(*fe.better, Correlation::Exponential);
    EXPECT_NEAR(*fg.T_um[Correlation::Gaussian], 7.0, 1e-3);
    EXPECT_NEAR(*fe.T_um[Correlation::Exponential], 7.0, 1e-3);
    EXPECT_LT(fg.aic[Correlation::Gaussian], fg.aic[Correlation::Exponential]);
    EXPECT_LT(fe.aic[Correlation::Exponential], fe.aic[Correlation::Gaussian]);
    // Too few points: no fit.
    EXPECT_FALSE(fit_acf_models(g, 0.6).better.has_value());
}

TEST(SurfaceAcfFit, RejectsBadLagRangeAndMismatchedCurve) {
    const Curve c{{0.0, 1.0, 2.0, 3.0}, {1.0, 0.6, 0.3, 0.1}};
    EXPECT_NO_THROW(fit_acf_models(c, 3.0));
    EXPECT_THROW(fit_acf_models(c, 0.0), InvalidArgument);
    EXPECT_THROW(fit_acf_models(c, -1.0), InvalidArgument);
    EXPECT_THROW(fit_acf_models(c, kNaN), InvalidArgument);
    const Curve bad{{0.0, 1.0}, {1.0}};
    EXPECT_THROW(fit_acf_models(bad, 3.0), InvalidArgument);
}

TEST(SurfaceStatistics, ExponentialProfileIsNamedExponentialWithItsT) {
    const double T = 10.0;  // samples, dx = 0.5 µm → 5 µm
    HeightMap p = testdata::ar1_map(1 << 18, 1, T, 21, 0.5);
    StatisticsOptions o;
    o.leveling = Leveling::Line;
    const SurfaceStatistics s = surface_statistics(p, o);
    ASSERT_TRUE(s.T_um && s.T_fit_exponential_um && s.correlation);
    EXPECT_EQ(*s.correlation, Correlation::Exponential);
    EXPECT_NEAR(*s.T_um / 5.0, 1.0, 0.04);
    EXPECT_NEAR(*s.T_fit_exponential_um / 5.0, 1.0, 0.04);
    EXPECT_NEAR(s.sigma_um, 1.0, 0.03);
    // Finite differences see the exponential ACF's cusp: Rdq ≫ σ√2/T.
    ASSERT_TRUE(s.rms_slope && s.m_from_T);
    EXPECT_GT(*s.rms_slope / *s.m_from_T, 2.0);
    EXPECT_TRUE(s.warnings.empty());
    ASSERT_TRUE(s.sigma_stderr_um && s.T_stderr_um);
    EXPECT_LT(std::abs(s.sigma_um - 1.0), 4 * *s.sigma_stderr_um + 0.01);
}

TEST(SurfaceStatistics, GaussianProfileIsNamedGaussianAndSlopesAgree) {
    const double T = 14.0;  // samples, dx = 1 µm
    HeightMap p = testdata::gaussian_profile(1 << 18, T, 22);
    StatisticsOptions o;
    o.leveling = Leveling::Line;
    o.acf_estimator = AcfEstimator::Biased;
    const SurfaceStatistics s = surface_statistics(p, o);
    ASSERT_TRUE(s.T_um && s.T_fit_gaussian_um && s.correlation);
    EXPECT_EQ(*s.correlation, Correlation::Gaussian);
    EXPECT_NEAR(*s.T_um / T, 1.0, 0.04);
    EXPECT_NEAR(*s.T_fit_gaussian_um / T, 1.0, 0.04);
    // Gaussian correlation: Rdq = σ√2/T up to the finite-difference bias (1 − dx²/(4T²)).
    ASSERT_TRUE(s.rms_slope && s.m_from_T);
    EXPECT_NEAR(*s.rms_slope / *s.m_from_T, 1.0, 0.03);
}

// ---- length bias and extrapolation
// ---------------------------------------------------------------
TEST(SurfaceStatistics, ShortRowsWarnAndExtrapolationRemovesMostOfTheLengthBias) {
    // 1024 independent AR(1) rows of L = 40 T, each levelled by its own mean line: the 1/e T is
    // biased low (≈ 16 %); T against 1/L over L, L/2, L/4 extrapolates most of it away (T(1/L)
    // is not yet linear at these lengths, docs/surface.md).
    const double T = 10.0;
    HeightMap m = testdata::ar1_map(400, 1024, T, 31);
    StatisticsOptions o;
    o.leveling = Leveling::Line;
    const SurfaceStatistics s = surface_statistics(m, o);
    ASSERT_TRUE(s.T_um && s.T_extrapolated_um);
    EXPECT_LT(*s.T_um / T, 0.9);
    EXPECT_GT(*s.T_extrapolated_um / T, 0.9);
    EXPECT_LT(*s.T_extrapolated_um / T, 1.02);
    EXPECT_LT(std::abs(*s.T_extrapolated_um - T), 0.5 * std::abs(*s.T_um - T));
    bool warned = false;
    for (const auto& w : s.warnings) warned = warned || w.find("below 50") != std::string::npos;
    EXPECT_TRUE(warned);
    ASSERT_TRUE(s.T_stderr_um && s.sigma_stderr_um);
    EXPECT_GT(*s.T_stderr_um, 0.0);
    EXPECT_LT(*s.T_stderr_um, 0.05 * T);
}

TEST(SurfaceStatistics, ExtrapolatedTIsWithinThreePercentAtLOverT160) {
    const double T = 10.0;
    HeightMap m = testdata::ar1_map(1600, 256, T, 32);
    StatisticsOptions o;
    o.leveling = Leveling::Line;
    const SurfaceStatistics s = surface_statistics(m, o);
    ASSERT_TRUE(s.T_um && s.T_extrapolated_um);
    EXPECT_LT(*s.T_um / T, 0.985);
    EXPECT_NEAR(*s.T_extrapolated_um / T, 1.0, 0.03);
    EXPECT_LT(std::abs(*s.T_extrapolated_um - T), std::abs(*s.T_um - T));
}

TEST(SurfaceStatistics, LongProfileDoesNotWarn) {
    HeightMap p = testdata::ar1_map(5000, 1, 10.0, 41);
    const SurfaceStatistics s = surface_statistics(p);
    ASSERT_TRUE(s.T_um);
    EXPECT_GT(p.length_x_um() / *s.T_um, 50.0);
    for (const auto& w : s.warnings) EXPECT_EQ(w.find("below 50"), std::string::npos) << w;
}

// ---- moments
// -------------------------------------------------------------------------------------
TEST(SurfaceMoments, MatchTheirDefinitions) {
    HeightMap m = make_height_map(5, 1, 1, 1);
    m.heights_um = {1.0, -1.0, 2.0, kNaN, -2.0};
    const HeightMoments h = height_moments(m);
    EXPECT_EQ(h.points, 4U);
    EXPECT_DOUBLE_EQ(h.sigma_um, std::sqrt(2.5));
    EXPECT_DOUBLE_EQ(h.Sa_um, 1.5);
    EXPECT_DOUBLE_EQ(h.Ssk, 0.0);
    EXPECT_DOUBLE_EQ(h.Sku, 8.5 / 6.25);
    EXPECT_DOUBLE_EQ(h.Sp_um, 2.0);
    EXPECT_DOUBLE_EQ(h.Sv_um, 2.0);
    EXPECT_DOUBLE_EQ(h.Sz_um, 4.0);

    // A skewed random map against two-pass sums.
    HeightMap r = testdata::noise_map(33, 17, 3, 0.1);
    for (double& z : r.heights_um) z = z * z * 0.3 + 0.1 * z;  // skewed, kurtotic
    double n = 0, s1 = 0, s2 = 0, s3 = 0, s4 = 0, hi = -1e300, lo = 1e300;
    for (double z : r.heights_um) {
        if (std::isnan(z)) continue;
        n += 1;
        s1 += std::abs(z);
        s2 += z * z;
        s3 += z * z * z;
        s4 += z * z * z * z;
        hi = std::max(hi, z);
        lo = std::min(lo, z);
    }
    const double sq = std::sqrt(s2 / n);
    const HeightMoments g = height_moments(r);
    EXPECT_EQ(static_cast<double>(g.points), n);
    EXPECT_NEAR(g.sigma_um, sq, 1e-12);
    EXPECT_NEAR(g.Sa_um, s1 / n, 1e-12);
    EXPECT_NEAR(g.Ssk, s3 / n / (sq * sq * sq), 1e-12);
    EXPECT_NEAR(g.Sku, s4 / n / (sq * sq * sq * sq), 1e-12);
    EXPECT_EQ(g.Sp_um, hi);
    EXPECT_EQ(g.Sv_um, -lo);
    EXPECT_GT(g.Ssk, 0.5);

    // surface_statistics without levelling reports the same.
    StatisticsOptions o;
    o.leveling = Leveling::None;
    const SurfaceStatistics s = surface_statistics(r, o);
    EXPECT_EQ(s.points, g.points);
    EXPECT_DOUBLE_EQ(s.sigma_um, g.sigma_um);
    EXPECT_DOUBLE_EQ(s.Sku, g.Sku);
    EXPECT_DOUBLE_EQ(s.Sz_um, g.Sz_um);
}

TEST(SurfaceMoments, FlatMapHasZeroMomentsAndNoT) {
    HeightMap flat = make_height_map(6, 3, 1, 1);
    const HeightMoments h = height_moments(flat);
    EXPECT_EQ(h.sigma_um, 0.0);
    EXPECT_EQ(h.Ssk, 0.0);
    EXPECT_EQ(h.Sku, 0.0);
    const SurfaceStatistics s = surface_statistics(flat);
    EXPECT_FALSE(s.T_um.has_value());
    EXPECT_FALSE(s.warnings.empty());
}

TEST(SurfaceMoments, RejectMapsWithoutValidPointsOrWrongSize) {
    HeightMap m = make_height_map(3, 2, 1, 1);
    m.heights_um.assign(6, kNaN);
    EXPECT_THROW(height_moments(m), InvalidArgument);
    EXPECT_THROW(surface_statistics(m), InvalidArgument);
    HeightMap short_map = make_height_map(3, 2, 1, 1);
    short_map.heights_um.resize(5);
    EXPECT_THROW(height_moments(short_map), InvalidArgument);
    EXPECT_THROW(surface_statistics(short_map), InvalidArgument);
}

// ---- surface_statistics: options and curves
// -------------------------------------------------------
TEST(SurfaceStatistics, CurvesAreKeptOnRequestAndMapsGetBothDirections) {
    HeightMap m = testdata::ar1_map(256, 64, 5.0, 51);
    const SurfaceStatistics with = surface_statistics(m);
    EXPECT_EQ(with.acf_x.x.size(), 256U);
    EXPECT_EQ(with.acf_y.x.size(), 64U);
    EXPECT_TRUE(with.T_y_um.has_value());
    EXPECT_TRUE(with.Sdq.has_value());
    StatisticsOptions o;
    o.keep_curves = false;
    const SurfaceStatistics without = surface_statistics(m, o);
    EXPECT_TRUE(without.acf_x.x.empty());
    EXPECT_TRUE(without.acf_y.x.empty());
    EXPECT_EQ(without.T_um, with.T_um);
}

TEST(SurfaceStatistics, RejectsBadOptions) {
    const HeightMap m = testdata::noise_map(32, 8, 61);
    StatisticsOptions ok;
    ok.leveling = Leveling::Polynomial;
    ok.polynomial_order = 3;
    ok.cutoff_um = 8.0;
    EXPECT_NO_THROW(surface_statistics(m, ok));
    StatisticsOptions bad_order = ok;
    bad_order.polynomial_order = 4;
    EXPECT_THROW(surface_statistics(m, bad_order), InvalidArgument);
    StatisticsOptions bad_cutoff = ok;
    bad_cutoff.cutoff_um = -1.0;
    EXPECT_THROW(surface_statistics(m, bad_cutoff), InvalidArgument);
    bad_cutoff.cutoff_um = 0.5;  // below 2 spacings (0.75 µm along y → 1.5 µm)
    EXPECT_THROW(surface_statistics(m, bad_cutoff), InvalidArgument);
}

// ---- names
// ----------------------------------------------------------------------------------------
TEST(SurfaceNames, RoundTripAndAliases) {
    for (Leveling l :
         {Leveling::None, Leveling::Mean, Leveling::Line, Leveling::Plane, Leveling::Polynomial})
        EXPECT_EQ(parse_leveling(to_string(l)), l);
    EXPECT_EQ(to_string(Leveling::Line), "line");
    EXPECT_EQ(parse_leveling(" Row "), Leveling::Line);
    EXPECT_EQ(parse_leveling("POLY"), Leveling::Polynomial);
    for (AcfEstimator e : {AcfEstimator::Unbiased, AcfEstimator::Biased})
        EXPECT_EQ(parse_acf_estimator(to_string(e)), e);
    EXPECT_EQ(to_string(AcfEstimator::Biased), "biased");
}

TEST(SurfaceNames, UnknownNamesAreRejected) {
    EXPECT_THROW(parse_leveling("tilt"), InvalidArgument);
    EXPECT_THROW(parse_leveling(""), InvalidArgument);
    EXPECT_THROW(parse_acf_estimator("fast"), InvalidArgument);
}

}  // namespace
}  // namespace roughscope::surface
