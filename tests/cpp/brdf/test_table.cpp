// Generic BRDF tables: the CSV reader, the paper-frame conversion, and the comparison machinery on
// synthetic tables whose truth is known (no CUReT data needed).
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "roughscope/brdf/comparison.hpp"
#include "roughscope/brdf/table.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/fit/fit.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/reflectance_models.hpp"

using namespace roughscope;

namespace {

Eigen::Vector3d direction(double theta, double phi) {
    return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

// A CUReT-like set of directions: the two normal-view measurements 1 (45°) and 2 (67.5°), then a
// spread of light and view directions with both azimuths in one sample frame.
struct Direction {
    double ti, pi, tv, pv;
};
std::vector<Direction> directions() {
    std::vector<Direction> d = {{deg_to_rad(45.0), 0.3, 0.0, 0.0},
                                {deg_to_rad(67.5), 0.3, 0.0, 0.0}};
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> pol(0.0, deg_to_rad(80.0)), az(-kPi, kPi);
    for (int k = 0; k < 120; ++k) d.push_back({pol(rng), az(rng), pol(rng), az(rng)});
    return d;
}

// A table whose BRDF is f = E/cos θi with E from `model` at the paper-frame geometry.
template <class Model>
BrdfTable synthetic_table(Model&& model, double gain = 1.0) {
    BrdfTable t;
    t.name = "synthetic";
    int index = 0;
    for (const Direction& d : directions()) {
        const Geometry g = geometry_from_two_azimuths(d.ti, d.pi, d.tv, d.pv);
        const double E = gain * model(g);
        t.measurements.push_back(
            make_brdf_measurement(++index, d.ti, d.pi, d.tv, d.pv, E / std::cos(d.ti)));
    }
    return t;
}

// A noisy table (deterministic "noise" ±5%) of a very-rough V–H Gaussian lobe (σ/T = 0.35) plus an
// Oren–Nayar body (σ_ON = 0.3, ρ_ON = 0.8): no model family fits it exactly.
BrdfTable mixed_table() {
    int j = 0;
    return synthetic_table(
        [&j](const Geometry& g) {
            const double E = very_rough_brightness(g, 0.35, Correlation::Gaussian) +
                             0.3 * oren_nayar_radiance(g, {0.3, 0.8});
            return E * (1.0 + 0.05 * std::sin(1.7 * j++));
        },
        2.5);
}

std::string write_temp(const std::string& name, const std::string& text) {
    const auto path =
        std::filesystem::temp_directory_path() /
        ("roughscope_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
         "_" + name);
    std::ofstream(path) << text;
    return path.string();
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Frame conversion

TEST(BrdfTable, FrameConversionPreservesTheAngleBetweenLightAndView) {
    // L·V is invariant under the rotation about the normal that puts the light at azimuth π, so
    // the sample-frame directions and the paper-frame geometry must give the same cosine.
    for (const Direction& d : directions()) {
        const BrdfMeasurement m = make_brdf_measurement(1, d.ti, d.pi, d.tv, d.pv, 0.1);
        const double sample_frame = direction(d.ti, d.pi).dot(direction(d.tv, d.pv));
        const double paper_frame = light_direction(m.geometry).dot(view_direction(m.geometry));
        EXPECT_NEAR(sample_frame, paper_frame, 1e-12);
        EXPECT_NEAR(m.geometry.theta_s_rad, d.tv, 1e-15);
    }
}

TEST(BrdfTable, SameAzimuthIsRetroAndOppositeIsSpecularPlane) {
    // §2: φs = π is retro-reflection (view on the light's side), φs = 0 the specular half-plane.
    const BrdfMeasurement retro = make_brdf_measurement(1, 0.5, 1.2, 0.5, 1.2, 0.1);
    EXPECT_NEAR(retro.geometry.phi_s_rad, kPi, 1e-12);
    const BrdfMeasurement spec = make_brdf_measurement(2, 0.5, 1.2, 0.5, 1.2 + kPi, 0.1);
    EXPECT_NEAR(std::cos(spec.geometry.phi_s_rad), 1.0, 1e-12);
}

TEST(BrdfTable, MakeMeasurementRejectsBadInput) {
    EXPECT_THROW(make_brdf_measurement(1, deg_to_rad(90.0), 0, 0, 0, 0.1), InvalidArgument);
    EXPECT_THROW(make_brdf_measurement(1, 0.1, 0, -0.1, 0, 0.1), InvalidArgument);
    EXPECT_THROW(make_brdf_measurement(1, 0.1, 0, 0.1, 0, std::nan("")), InvalidArgument);
    EXPECT_THROW(make_brdf_measurement(1, 0.1, 0, 0.1, 0, 0.1, -1.0), InvalidArgument);
    EXPECT_THROW(make_brdf_measurement(1, 0.1, 0, 0.1, 0, 0.1, 1.0, 1.5), InvalidArgument);
    // A non-positive BRDF value is data (noise), not an error.
    EXPECT_NO_THROW(make_brdf_measurement(1, 0.1, 0, 0.1, 0, -0.004));
}

// ---------------------------------------------------------------------------------------------
// CSV reader

TEST(BrdfCsv, ReadsColumnsInAnyOrderWithCommentsAndCrlf) {
    const std::string text =
        "# a comment\r\n"
        "value, phi_s, theta_s, phi_i, theta_i, weight, note\r\n"
        "0.25, 180, 10, 180, 30, 2, first\r\n"
        "\r\n"
        "-0.001, 0, 20, 180, 40, , second\r\n";
    const BrdfTable t = parse_brdf_csv(text, "mem.csv");
    ASSERT_EQ(t.size(), 2u);
    EXPECT_EQ(t.measurements[0].index, 1);
    EXPECT_DOUBLE_EQ(t.measurements[0].value, 0.25);
    EXPECT_DOUBLE_EQ(t.measurements[0].weight, 2.0);
    EXPECT_DOUBLE_EQ(t.measurements[1].weight, 1.0);    // empty optional cell → default
    EXPECT_DOUBLE_EQ(t.measurements[1].value, -0.001);  // carried, not dropped
    // φi = 180° makes the file frame the paper's frame: φs = phi_s.
    EXPECT_NEAR(t.measurements[0].geometry.phi_s_rad, kPi, 1e-12);
    EXPECT_NEAR(t.measurements[1].geometry.phi_s_rad, 0.0, 1e-12);
    EXPECT_NEAR(t.measurements[1].geometry.theta_i_rad, deg_to_rad(40.0), 1e-15);
}

TEST(BrdfCsv, MeasurementColumnAndChannels) {
    const std::string text =
        "measurement,channel,theta_i,phi_i,theta_s,phi_s,value\n"
        "81,r,45,0,0,0,0.1\n81,g,45,0,0,0,0.2\n112,r,67.5,0,0,0,0.05\n112,g,67.5,0,0,0,0.07\n";
    BrdfCsvOptions red;
    red.channel = "r";
    const BrdfTable t = parse_brdf_csv(text, "rgb.csv", red);
    ASSERT_EQ(t.size(), 2u);
    EXPECT_EQ(t.channel, "r");
    ASSERT_TRUE(t.find(112).has_value());
    EXPECT_DOUBLE_EQ(t.measurements[*t.find(112)].value, 0.05);
    EXPECT_FALSE(t.find(7).has_value());
}

TEST(BrdfCsv, SeveralChannelsWithoutAChoiceIsAnError) {
    const std::string text =
        "channel,theta_i,phi_i,theta_s,phi_s,value\nr,45,0,0,0,0.1\n"
        "g,45,0,0,0,0.2\n";
    try {
        parse_brdf_csv(text, "rgb.csv");
        FAIL() << "expected DataError";
    } catch (const DataError& e) {
        EXPECT_NE(std::string(e.what()).find("g, r"), std::string::npos) << e.what();
    }
    BrdfCsvOptions blue;
    blue.channel = "b";
    EXPECT_THROW(parse_brdf_csv(text, "rgb.csv", blue), DataError);
}

TEST(BrdfCsv, MalformedInputNamesFileLineAndColumn) {
    auto message = [](const std::string& text) {
        try {
            parse_brdf_csv(text, "bad.csv");
        } catch (const DataError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    const std::string header = "theta_i,phi_i,theta_s,phi_s,value\n";
    EXPECT_NE(message("theta_i,phi_i,theta_s,value\n1,2,3,4\n")
                  .find("bad.csv:1: missing column(s) phi_s"),
              std::string::npos);
    EXPECT_NE(message(header + "10,0,10,0,0.1\n10,0,10,0,abc\n").find("bad.csv:3: column value"),
              std::string::npos);
    EXPECT_NE(message(header + "10,0,10,0,nan\n").find("bad.csv:2"), std::string::npos);
    EXPECT_NE(message(header + "95,0,10,0,0.1\n").find("bad.csv:2"), std::string::npos);
    EXPECT_NE(message(header + "10,0,10,0\n").find("expected 5 fields"), std::string::npos);
    EXPECT_NE(message(header).find("no data rows"), std::string::npos);
    EXPECT_NE(message("").find("no header"), std::string::npos);
    EXPECT_NE(message("measurement," + header + "3,10,0,10,0,0.1\n3,20,0,10,0,0.1\n")
                  .find("duplicate measurement 3"),
              std::string::npos);
    EXPECT_NE(message("weight," + header + "-1,10,0,10,0,0.1\n").find("bad.csv:2"),
              std::string::npos);
}

TEST(BrdfCsv, ReadsAFileAndReportsAMissingOne) {
    const std::string path =
        write_temp("table.csv", "theta_i,phi_i,theta_s,phi_s,value\n30,180,0,0,0.2\n");
    const BrdfTable t = read_brdf_csv(path);
    EXPECT_EQ(t.size(), 1u);
    std::filesystem::remove(path);
    EXPECT_THROW(read_brdf_csv(path), DataError);
}

// ---------------------------------------------------------------------------------------------
// The comparison machinery on tables with a known truth

TEST(Comparison, TwoPointEstimateRecoversTheSlopeOfAVeryRoughSurface) {
    // Brightness generated by Eq. 5 (V–H, exponential) with σ/T = 0.6: Eq. 19 on the two
    // normal-view measurements must return 0.6, and the V–H exponential model then fits the table
    // exactly (Table-4 error 0), with the winner being that model family.
    const double truth = 0.6;
    const BrdfTable t = synthetic_table(
        [&](const Geometry& g) {
            return very_rough_brightness(g, truth, Correlation::Exponential);
        },
        3.7);
    ComparisonOptions o;
    o.measurement1 = 1;
    o.measurement2 = 2;
    const Comparison c = compare_brdf(t, o);
    ASSERT_TRUE(c.two_point.available) << c.two_point.reason;
    ASSERT_TRUE(c.two_point.sigma_over_T_exponential.has_value());
    EXPECT_NEAR(*c.two_point.sigma_over_T_exponential, truth, 1e-9);
    EXPECT_LT(c.result(ComparisonModel::VhExponential).errors.paper_sse, 1e-18);
    EXPECT_LT(c.result(ComparisonModel::VhExponential).errors.gain_sse, 1e-18);
    EXPECT_GT(c.result(ComparisonModel::BkExponential).errors.paper_sse, 1e-3);
    ASSERT_TRUE(c.winner.has_value());
    EXPECT_TRUE(*c.winner == ComparisonModel::VhExponential ||
                *c.winner == ComparisonModel::VhExponentialFit);
}

TEST(Comparison, FitsRecoverKnownParametersAndGain) {
    // Each family generated with a known parameter and gain: its fit returns them.
    ComparisonOptions o;
    o.measurement1 = 1;
    o.measurement2 = 2;
    {
        const BrdfTable t = synthetic_table(
            [](const Geometry& g) {
                return very_rough_brightness(g, 0.45, Correlation::Gaussian,
                                             GeometricFactor::Beckmann);
            },
            2.0);
        const Comparison c = compare_brdf(t, o);
        const ModelResult& r = c.result(ComparisonModel::BkGaussianFit);
        ASSERT_TRUE(r.available);
        EXPECT_NEAR(*r.parameter("sigma_over_T"), 0.45, 1e-6);
        EXPECT_LT(r.errors.gain_sse, 1e-12);
        EXPECT_EQ(*r.fit_status, SolverStatus::Converged);
    }
    {
        const BrdfTable t = synthetic_table(
            [](const Geometry& g) { return lafortune_diffuse_brightness(g, 5.0); }, 0.3);
        const Comparison c = compare_brdf(t, o);
        const ModelResult& r = c.result(ComparisonModel::LafortuneFit);
        EXPECT_NEAR(*r.parameter("n"), 5.0, 1e-5);
        // The exhaustive search lands on the grid value 5.00 too.
        EXPECT_NEAR(*c.result(ComparisonModel::Lafortune).parameter("n"), 5.0, 1e-9);
    }
    {
        const OrenNayarParams truth{0.4, 0.6};
        const BrdfTable t =
            synthetic_table([&](const Geometry& g) { return oren_nayar_radiance(g, truth); }, 5.0);
        const Comparison c = compare_brdf(t, o);
        const ModelResult& r = c.result(ComparisonModel::OrenNayarFit);
        EXPECT_NEAR(*r.parameter("sigma_rad"), 0.4, 1e-4);
        EXPECT_NEAR(*r.parameter("albedo"), 0.6, 1e-3);
        EXPECT_LT(r.errors.gain_sse, 1e-12);
    }
}

TEST(ComparisonFitEngine, SyntheticFitsAgreeWithThePreviousEngine) {
    // Values of the previous engine (grid + Brent, gain eliminated, finite-difference covariance)
    // on mixed_table(), typed in: gain_sse to 1e-9, the parameter to 1e-6, the standard error to
    // 1e-4 (relative). At σ_ON = 0 albedo and gain are not separable: NotIdentifiable.
    ComparisonOptions o;
    o.measurement1 = 1;
    o.measurement2 = 2;
    const Comparison c = compare_brdf(mixed_table(), o);
    struct Old {
        ComparisonModel model;
        double gain_sse;
        const char* parameter;
        double value;
        double standard_error;  // -1: none
    };
    const Old old[] = {
        {ComparisonModel::OrenNayarFit, 3.03386127603, "sigma_rad", 0.0, -1.0},
        {ComparisonModel::LafortuneFit, 3.02708406092, "n", 0.034702485341, 0.0675388},
        {ComparisonModel::BkGaussianFit, 12.1571241783, "sigma_over_T", 0.184473787121, 0.0098881},
        {ComparisonModel::BkExponentialFit, 14.9329231036, "sigma_over_T", 0.187470382968,
         0.0198446},
        {ComparisonModel::VhGaussianFit, 0.248803226562, "sigma_over_T", 0.381346761835, 0.0051397},
        {ComparisonModel::VhExponentialFit, 0.221784450782, "sigma_over_T", 0.717301880549,
         0.0119808},
    };
    for (const Old& e : old) {
        const ModelResult& r = c.result(e.model);
        const std::string where = std::string(to_string(e.model)) + ": " + r.fit_message;
        ASSERT_TRUE(r.available && r.fit_status) << where;
        EXPECT_NEAR(r.errors.gain_sse, e.gain_sse, 1e-9 * e.gain_sse) << where;
        EXPECT_NEAR(*r.parameter(e.parameter), e.value, 1e-6 * std::max(e.value, 1e-3)) << where;
        const ModelParameter& p = r.parameters.at(0);
        if (e.standard_error > 0.0) {
            ASSERT_TRUE(p.standard_error.has_value()) << where;
            EXPECT_NEAR(*p.standard_error, e.standard_error, 1e-4 * e.standard_error) << where;
        }
        if (e.model == ComparisonModel::OrenNayarFit)
            EXPECT_EQ(*r.fit_status, SolverStatus::NotIdentifiable) << where;
        else
            EXPECT_EQ(*r.fit_status, SolverStatus::Converged) << where;
    }
}

TEST(ComparisonFitEngine, FitRoughnessAndTheComparisonFitAgreeWhenConfiguredAlike) {
    // The same data (d = f cos θi / max), weights, factor, radiometry, correlation, bounds and
    // residual definition (absolute, gain profiled out): fit_roughness (paper §4) and the
    // comparison's σ/T fit (§5.3) are one estimator.
    ComparisonOptions o;
    o.measurement1 = 1;
    o.measurement2 = 2;
    const Comparison c = compare_brdf(mixed_table(), o);
    double dmax = 0.0;
    for (double b : c.brightness) dmax = std::max(dmax, b);
    std::vector<Measurement> ms;
    for (std::size_t j = 0; j < c.brightness.size(); ++j)
        ms.push_back({c.geometry[j], c.brightness[j] / dmax, c.weight[j]});
    struct Family {
        ComparisonModel model;
        GeometricFactor factor;
        Correlation correlation;
    };
    const Family families[] = {
        {ComparisonModel::BkGaussianFit, GeometricFactor::Beckmann, Correlation::Gaussian},
        {ComparisonModel::BkExponentialFit, GeometricFactor::Beckmann, Correlation::Exponential},
        {ComparisonModel::VhGaussianFit, GeometricFactor::VernoldHarvey, Correlation::Gaussian},
        {ComparisonModel::VhExponentialFit, GeometricFactor::VernoldHarvey,
         Correlation::Exponential},
    };
    for (const Family& f : families) {
        FitOptions fo;
        fo.factor = f.factor;
        fo.correlation = f.correlation;
        fo.radiometry = o.radiometry;
        fo.residual = ResidualType::Absolute;
        fo.sigma_over_T_min = o.fit_sigma_over_T_min;
        fo.sigma_over_T_max = o.fit_sigma_over_T_max;
        fo.function_tolerance = 1e-15;
        const FitResult fr = fit_roughness(ms, fo);
        const ModelResult& r = c.result(f.model);
        const std::string where = std::string(to_string(f.model)) + ": " + fr.brief_report();
        EXPECT_EQ(fr.status, SolverStatus::Converged) << where;
        EXPECT_NEAR(fr.parameter("sigma_over_T").value, *r.parameter("sigma_over_T"),
                    1e-7 * *r.parameter("sigma_over_T"))
            << where;
        EXPECT_NEAR(fr.parameter("gain").value, *r.parameter("gain"), 1e-6 * *r.parameter("gain"))
            << where;
        EXPECT_NEAR(fr.sse, r.errors.gain_sse, 1e-10 * r.errors.gain_sse) << where;
        EXPECT_NEAR(fr.parameter("sigma_over_T").std_error, *r.parameters.at(0).standard_error,
                    1e-4 * *r.parameters.at(0).standard_error)
            << where;
    }
    // Configured differently (relative residuals), they are different estimators.
    FitOptions rel;
    rel.sigma_over_T_min = o.fit_sigma_over_T_min;
    rel.sigma_over_T_max = o.fit_sigma_over_T_max;
    const double s_rel = fit_roughness(ms, rel).parameter("sigma_over_T").value;
    EXPECT_GT(std::abs(s_rel - *c.result(ComparisonModel::VhGaussianFit).parameter("sigma_over_T")),
              1e-4);
}

TEST(Comparison, FitStandardErrorsCoverTheTruthUnderNoise) {
    // 1% multiplicative noise on a V–H Gaussian table (σ/T = 0.5): the estimate lies within
    // 3 standard errors of the truth in at least 45 of 50 seeded trials, and the standard error is
    // neither zero nor huge.
    const std::vector<Direction> dirs = directions();
    int covered = 0;
    for (int trial = 0; trial < 50; ++trial) {
        std::mt19937 rng(1000 + trial);
        std::normal_distribution<double> noise(0.0, 0.01);
        BrdfTable t;
        int index = 0;
        for (const Direction& d : dirs) {
            const Geometry g = geometry_from_two_azimuths(d.ti, d.pi, d.tv, d.pv);
            const double E =
                very_rough_brightness(g, 0.5, Correlation::Gaussian) * (1.0 + noise(rng));
            t.measurements.push_back(
                make_brdf_measurement(++index, d.ti, d.pi, d.tv, d.pv, E / std::cos(d.ti)));
        }
        ComparisonOptions o;
        o.measurement1 = 1;
        o.measurement2 = 2;
        const Comparison c = compare_brdf(t, o);
        const ModelResult& r = c.result(ComparisonModel::VhGaussianFit);
        const ModelParameter& p = r.parameters.at(0);
        ASSERT_TRUE(p.standard_error.has_value());
        EXPECT_GT(*p.standard_error, 1e-5);
        EXPECT_LT(*p.standard_error, 0.05);
        if (std::abs(p.value - 0.5) <= 3.0 * *p.standard_error) ++covered;
    }
    EXPECT_GE(covered, 45);
}

TEST(Comparison, NonPositivePairValueMakesTheEstimateUnavailableNotAnError) {
    BrdfTable t = synthetic_table(
        [](const Geometry& g) { return very_rough_brightness(g, 0.5, Correlation::Gaussian); });
    t.measurements[1].value = -0.002;  // measurement 2 of the pair
    t.measurements[7].value = 0.0;     // elsewhere: kept
    ComparisonOptions o;
    o.measurement1 = 1;
    o.measurement2 = 2;
    const Comparison c = compare_brdf(t, o);
    EXPECT_FALSE(c.two_point.available);
    EXPECT_FALSE(c.two_point.E1_over_E2.has_value());
    EXPECT_NE(c.two_point.reason.find("measurement 2 has f = -0.002"), std::string::npos)
        << c.two_point.reason;
    EXPECT_FALSE(c.result(ComparisonModel::VhGaussian).available);
    EXPECT_TRUE(c.result(ComparisonModel::VhGaussianFit).available);
    EXPECT_EQ(c.measurement.size(), t.size());  // every value kept in the sums
    ASSERT_EQ(c.data_issues.size(), 2u);
    EXPECT_EQ(c.data_issues[0].measurement, 2);
    EXPECT_EQ(c.data_issues[0].excluded_from, std::vector<std::string>{"two_point_estimate"});
    EXPECT_EQ(c.data_issues[1].measurement, 8);
    EXPECT_TRUE(c.data_issues[1].excluded_from.empty());
}

TEST(Comparison, OverflowThresholdAndZeroWeightExcludeMeasurements) {
    BrdfTable t = synthetic_table(
        [](const Geometry& g) { return very_rough_brightness(g, 0.5, Correlation::Gaussian); });
    for (auto& m : t.measurements) m.overflow_fraction = 0.0;
    t.measurements[5].overflow_fraction = 0.3;
    t.measurements[6].weight = 0.0;
    ComparisonOptions o;
    o.measurement1 = 1;
    o.measurement2 = 2;
    o.max_overflow_fraction = 0.1;
    const Comparison c = compare_brdf(t, o);
    EXPECT_EQ(c.measurement.size(), t.size() - 2);
    ASSERT_EQ(c.data_issues.size(), 2u);
    EXPECT_EQ(c.data_issues[0].issue, "saturated");
    EXPECT_EQ(c.data_issues[1].issue, "zero_weight");
    o.max_overflow_fraction.reset();
    EXPECT_EQ(compare_brdf(t, o).measurement.size(), t.size() - 1);
}

TEST(Comparison, NoPositiveDataLeavesEveryModelUnavailable) {
    BrdfTable t = synthetic_table([](const Geometry&) { return -1.0; });
    ComparisonOptions o;
    o.measurement1 = 1;
    o.measurement2 = 2;
    const Comparison c = compare_brdf(t, o);
    for (const ModelResult& r : c.models) {
        EXPECT_FALSE(r.available);
        EXPECT_FALSE(r.reason.empty());
    }
    EXPECT_FALSE(c.winner.has_value());
}

// A table that cannot determine any model parameter — one row, or every row at one geometry
// (the normalised data and every normalised model are 1 there) — gives no fit and no search
// result: every fit and the Lafortune search are NotIdentifiable with the reason, no parameter
// value is identified, and there is no winner (never "converged" with an arbitrary value).
TEST(Comparison, OneGeometryIdentifiesNoModel) {
    for (const int rows : {1, 3}) {
        BrdfTable t;
        t.name = "one geometry";
        for (int k = 1; k <= rows; ++k)
            t.measurements.push_back(make_brdf_measurement(k, 0.5, 0.0, 0.2, kPi, 0.1));
        ComparisonOptions o;
        o.measurement1 = 1;
        o.measurement2 = 2;
        const Comparison c = compare_brdf(t, o);
        const std::string where = std::to_string(rows) + " rows";
        for (const ModelResult& r : c.models) {
            EXPECT_FALSE(r.identified()) << display_name(r.model) << ", " << where;
            if (!r.available) continue;
            ASSERT_TRUE(r.fit_status.has_value()) << display_name(r.model);
            EXPECT_EQ(*r.fit_status, SolverStatus::NotIdentifiable)
                << display_name(r.model) << ", " << where << ": " << r.fit_message;
            EXPECT_NE(r.fit_message.find("1 distinct geometry"), std::string::npos)
                << r.fit_message;
            for (const ModelParameter& p : r.parameters)
                if (p.name != "gain" || is_fit(r.model)) {
                    EXPECT_FALSE(p.identified) << display_name(r.model) << " " << p.name;
                    EXPECT_FALSE(p.standard_error.has_value());
                }
        }
        EXPECT_FALSE(c.result(ComparisonModel::Lafortune).parameter("n").has_value()) << where;
        EXPECT_FALSE(c.winner.has_value()) << where;
        EXPECT_FALSE(c.winner_paper_metric.has_value()) << where;
    }
    // Two distinct geometries identify the one-parameter models again.
    BrdfTable t;
    t.name = "two geometries";
    t.measurements.push_back(make_brdf_measurement(1, 0.5, 0.0, 0.2, kPi, 0.1));
    t.measurements.push_back(make_brdf_measurement(2, 0.9, 0.0, 0.2, kPi, 0.07));
    ComparisonOptions o;
    o.measurement1 = 1;
    o.measurement2 = 2;
    const Comparison c = compare_brdf(t, o);
    EXPECT_TRUE(c.result(ComparisonModel::Lafortune).identified());
    EXPECT_TRUE(c.winner.has_value());
}

TEST(Comparison, BadOptionsAndEmptyTablesThrow) {
    const BrdfTable t = synthetic_table([](const Geometry& g) { return std::cos(g.theta_i_rad); });
    ComparisonOptions o;
    o.measurement1 = o.measurement2 = 1;
    EXPECT_THROW(compare_brdf(t, o), InvalidArgument);
    o = {};
    o.theta1_rad = deg_to_rad(95.0);
    EXPECT_THROW(compare_brdf(t, o), InvalidArgument);
    o = {};
    o.lafortune_n_step = 0.0;
    EXPECT_THROW(compare_brdf(t, o), InvalidArgument);
    o = {};
    o.fit_sigma_over_T_min = 2.0;
    o.fit_sigma_over_T_max = 1.0;
    EXPECT_THROW(compare_brdf(t, o), InvalidArgument);
    o = {};
    o.oren_nayar = OrenNayarParams{0.3, 1.5};
    EXPECT_THROW(compare_brdf(t, o), InvalidArgument);
    o = {};
    o.max_overflow_fraction = -0.1;
    EXPECT_THROW(compare_brdf(t, o), InvalidArgument);
    EXPECT_THROW(compare_brdf(BrdfTable{}, {}), InvalidArgument);
    // A pair the table lacks is reported, not thrown; so is a pair not viewed along the normal.
    BrdfTable small = t;
    small.measurements.resize(10);
    const Comparison c = compare_brdf(small, {});
    EXPECT_FALSE(c.two_point.available);
    EXPECT_NE(c.two_point.reason.find("measurement 81 is not in the table"), std::string::npos);
    ComparisonOptions off_normal;
    off_normal.measurement1 = 1;
    off_normal.measurement2 = 3;
    const Comparison d = compare_brdf(t, off_normal);
    EXPECT_FALSE(d.two_point.available);
    EXPECT_NE(d.two_point.reason.find("measurement 3 has theta_v"), std::string::npos)
        << d.two_point.reason;
}

// ---------------------------------------------------------------------------------------------
// Error measures

TEST(ErrorMeasures, HandComputedValues) {
    // data (1, 2) → (0.5, 1); model (2, 1) → (1, 0.5): Table-4 error 0.25 + 0.25 = 0.5,
    // RMSE = sqrt(0.5/2) = 0.5; optimal gain K = (2·0.5 + 1·1)/(4 + 1) = 0.4, residuals 0.3 and
    // −0.6: SSE 0.45.
    const std::vector<double> data{1.0, 2.0}, model{2.0, 1.0};
    const ErrorMeasures e = error_measures(model, data);
    EXPECT_DOUBLE_EQ(e.paper_sse, 0.5);
    EXPECT_DOUBLE_EQ(e.rmse, 0.5);
    EXPECT_NEAR(e.gain, 0.4, 1e-15);
    EXPECT_NEAR(e.gain_sse, 0.45, 1e-15);
    // Scale invariance: multiplying the model changes neither the Table-4 error nor the gain SSE.
    const ErrorMeasures s = error_measures(std::vector<double>{20.0, 10.0}, data);
    EXPECT_DOUBLE_EQ(s.paper_sse, e.paper_sse);
    EXPECT_NEAR(s.gain_sse, e.gain_sse, 1e-15);
    // Weights: a zero weight drops the second term.
    const ErrorMeasures w = error_measures(model, data, std::vector<double>{1.0, 0.0});
    EXPECT_DOUBLE_EQ(w.paper_sse, 0.25);
}

TEST(ErrorMeasures, RejectsBadInput) {
    const std::vector<double> two{1.0, 2.0}, three{1.0, 2.0, 3.0};
    EXPECT_THROW(error_measures(two, three), InvalidArgument);
    EXPECT_THROW(error_measures(std::vector<double>{}, std::vector<double>{}), InvalidArgument);
    EXPECT_THROW(error_measures(two, std::vector<double>{-1.0, 0.0}), InvalidArgument);
    EXPECT_THROW(error_measures(std::vector<double>{0.0, 0.0}, two), InvalidArgument);
    EXPECT_THROW(error_measures(two, std::vector<double>{1.0, std::nan("")}), InvalidArgument);
    EXPECT_THROW(error_measures(two, two, std::vector<double>{1.0}), InvalidArgument);
    EXPECT_THROW(error_measures(two, two, std::vector<double>{1.0, -1.0}), InvalidArgument);
}

TEST(ComparisonNames, RoundTripAndRejectUnknown) {
    for (ComparisonModel m : kComparisonModels) EXPECT_EQ(parse_comparison_model(to_string(m)), m);
    EXPECT_EQ(to_string(ComparisonModel::VhExponential), "vh_exponential");
    EXPECT_TRUE(is_fit(ComparisonModel::OrenNayarFit));
    EXPECT_FALSE(is_fit(ComparisonModel::Lafortune));
    EXPECT_THROW(parse_comparison_model("phong"), InvalidArgument);
}

// ---------------------------------------------------------------------------------------------
// Large tables: the same results with less memory

TEST(Comparison, PredictionsNotKeptGiveTheSameResults) {
    // keep_predictions = false (the CLI without --series) and a table given by value (released
    // once read) change nothing but the stored predictions.
    const BrdfTable t = mixed_table();
    const Comparison kept = compare_brdf(t, {});
    ComparisonOptions o;
    o.keep_predictions = false;
    const Comparison released = compare_brdf(BrdfTable(t), o);
    ASSERT_EQ(kept.models.size(), released.models.size());
    for (std::size_t k = 0; k < kept.models.size(); ++k) {
        const ModelResult& a = kept.models[k];
        const ModelResult& b = released.models[k];
        SCOPED_TRACE(std::string(to_string(a.model)));
        EXPECT_EQ(a.available, b.available);
        EXPECT_EQ(a.errors.paper_sse, b.errors.paper_sse);
        EXPECT_EQ(a.errors.gain_sse, b.errors.gain_sse);
        ASSERT_EQ(a.parameters.size(), b.parameters.size());
        for (std::size_t j = 0; j < a.parameters.size(); ++j)
            EXPECT_EQ(a.parameters[j].value, b.parameters[j].value);
        EXPECT_EQ(a.prediction.size(), a.available ? t.size() : 0U);
        EXPECT_TRUE(b.prediction.empty());
    }
    EXPECT_EQ(kept.winner, released.winner);
}

TEST(Comparison, LafortuneSearchOnRepeatedGeometriesIsTheDirectSearch) {
    // Each (θi, θs) measured at several azimuths (as on a grid): the search over the distinct
    // (θi, θs) must find the n of the direct search, with the direct Table-4 error.
    BrdfTable t;
    t.name = "grid";
    int index = 0;
    for (double ti_deg : {10.0, 30.0, 50.0, 70.0})
        for (double tv_deg : {0.0, 20.0, 40.0, 60.0})
            for (double pv_deg : {0.0, 90.0, 180.0, 270.0}) {
                const double ti = deg_to_rad(ti_deg), tv = deg_to_rad(tv_deg);
                const double pv = deg_to_rad(pv_deg);
                const double E = std::pow(std::cos(ti) * std::cos(tv), 2.3) * std::cos(ti) *
                                 (1.0 + 0.1 * std::sin(++index));
                t.measurements.push_back(
                    make_brdf_measurement(index, ti, kPi, tv, pv, E / std::cos(ti)));
            }
    const Comparison c = compare_brdf(t, {});
    std::vector<double> d, M(c.geometry.size());
    for (double b : c.brightness) d.push_back(b);
    double best_n = 0.0, best_err = std::numeric_limits<double>::infinity();
    for (int k = 0; k <= 1990; ++k) {
        const double n = 0.1 + k * 0.01;
        for (std::size_t j = 0; j < M.size(); ++j)
            M[j] = lafortune_diffuse_brightness(c.geometry[j], n);
        const double e = error_measures(M, d).paper_sse;
        if (e < best_err) {
            best_err = e;
            best_n = n;
        }
    }
    const ModelResult& laf = c.result(ComparisonModel::Lafortune);
    ASSERT_TRUE(laf.parameter("n").has_value());
    EXPECT_EQ(*laf.parameter("n"), best_n);
    EXPECT_NEAR(laf.errors.paper_sse, best_err, 1e-12 * best_err);
    EXPECT_NEAR(best_n, 2.3, 0.5);  // an interior minimum near the exponent of the data
}

TEST(Comparison, LafortuneSearchDoesNotDependOnTheNumberOfThreads) {
    // Distinct geometries (a sphere-like table): the grid's bands on 1, 2 and 3 threads give the
    // same n, errors and flags, bit for bit.
    BrdfTable t;
    t.name = "threads";
    int index = 0;
    for (double ti_deg = 2.0; ti_deg < 80.0; ti_deg += 3.7)
        for (double pv_deg : {10.0, 100.0, 200.0}) {
            const double ti = deg_to_rad(ti_deg), tv = deg_to_rad(0.6 * ti_deg + 1.0);
            const double E = std::pow(std::cos(ti) * std::cos(tv), 1.7) * std::cos(ti) *
                             (1.0 + 0.05 * std::sin(++index));
            t.measurements.push_back(
                make_brdf_measurement(index, ti, kPi, tv, deg_to_rad(pv_deg), E / std::cos(ti)));
        }
    ComparisonOptions o;
    o.fits = false;
    o.threads = 1;
    const ModelResult one = compare_brdf(t, o).result(ComparisonModel::Lafortune);
    ASSERT_TRUE(one.parameter("n").has_value());
    EXPECT_EQ(one.fit_status, SolverStatus::Converged);
    for (const std::size_t threads : {2U, 3U, 0U}) {
        o.threads = threads;
        const ModelResult many = compare_brdf(t, o).result(ComparisonModel::Lafortune);
        EXPECT_EQ(*many.parameter("n"), *one.parameter("n")) << threads;
        EXPECT_EQ(many.errors.paper_sse, one.errors.paper_sse);
        EXPECT_EQ(many.errors.gain_sse, one.errors.gain_sse);
        EXPECT_EQ(many.fit_status, one.fit_status);
    }
}
