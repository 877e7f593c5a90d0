// The serializer (roughscope/serialize): known structs give known keys and values, unknown values
// are null (never NaN), doubles round-trip exactly through dump/parse, and the options readers
// reject bad input naming the key (each failure test beside its success test).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/serialize/comparison.hpp"
#include "roughscope/serialize/estimation.hpp"
#include "roughscope/serialize/json.hpp"
#include "roughscope/serialize/model.hpp"

using namespace roughscope;
using serialize::Json;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

TEST(SerializeJson, NumbersAreNullWhenUnknownOrNotFinite) {
    EXPECT_EQ(serialize::number(1.5), Json(1.5));
    EXPECT_TRUE(serialize::number(kNaN).is_null());
    EXPECT_TRUE(serialize::number(kInf).is_null());
    EXPECT_TRUE(serialize::number(-kInf).is_null());
    EXPECT_TRUE(serialize::number(std::optional<double>{}).is_null());
    EXPECT_EQ(serialize::number(std::optional<double>{2.0}), Json(2.0));
    const Json list = serialize::numbers({1.0, kNaN, 3.0});
    EXPECT_EQ(list.dump(), "[1.0,null,3.0]");
    EXPECT_TRUE(serialize::text_or_null("").is_null());
    EXPECT_EQ(serialize::text_or_null("x"), Json("x"));
    const std::string text = serialize::dump(Json{{"a", serialize::number(kNaN)}});
    EXPECT_EQ(text.find("nan"), std::string::npos);
    EXPECT_EQ(text.back(), '\n');
}

TEST(SerializeJson, DoublesRoundTripExactlyThroughDumpAndParse) {
    std::mt19937_64 rng(42);
    std::uniform_real_distribution<double> mantissa(1.0, 2.0);
    std::uniform_int_distribution<int> exponent(-300, 300);
    Json arr = Json::array();
    std::vector<double> values = {0.1,
                                  1.0 / 3.0,
                                  2.0 / 3.0,
                                  1e-310,
                                  1.7976931348623157e308,
                                  0.30000000000000004,
                                  123456789.123456789};
    for (int k = 0; k < 2000; ++k) values.push_back(std::ldexp(mantissa(rng), exponent(rng)));
    for (double v : values) arr.push_back(serialize::number(v));
    const Json back = Json::parse(serialize::dump(arr));
    ASSERT_EQ(back.size(), values.size());
    for (std::size_t k = 0; k < values.size(); ++k)
        EXPECT_EQ(back[k].get<double>(), values[k]) << k;  // bit-exact, no pre-rounding
}

// serialize::degrees's definition, brute force: strtod of printf's "%.*g" of the degrees at 1,
// 2, ... 17 digits, the first whose deg_to_rad is the radians.
double shortest_degrees_brute_force(double radians) {
    const double deg = rad_to_deg(radians);
    for (int digits = 1; digits <= 17; ++digits) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "%.*g", digits, deg);
        const double candidate = std::strtod(buf, nullptr);
        if (deg_to_rad(candidate) == radians) return candidate;
    }
    return deg;
}

TEST(SerializeJson, DegreesAreTheShortestDecimalThatMapsBackToTheRadians) {
    // Against the definition, brute force (the serializer skips precisions that cannot qualify
    // and builds the candidates without text).
    const auto brute_force = shortest_degrees_brute_force;
    std::mt19937_64 rng(5);
    std::uniform_int_distribution<int> tenths(-3600, 3600), places(0, 6);
    std::uniform_real_distribution<double> any(-7.0, 7.0);
    std::vector<double> radians = {
        0.0,   deg_to_rad(30.0),  deg_to_rad(45.0), deg_to_rad(89.99), deg_to_rad(0.1), 1e-300,
        1e300, -deg_to_rad(180.0)};
    for (int k = 0; k < 20000; ++k) {
        radians.push_back(deg_to_rad(tenths(rng) / std::pow(10.0, places(rng))));  // typed angles
        radians.push_back(any(rng));  // from vectors: usually 16-17 digits
        radians.push_back(std::nextafter(radians[radians.size() - 2], 10.0));
    }
    for (const double r : radians) {
        const double expected = brute_force(r);
        ASSERT_EQ(serialize::degrees(r).get<double>(), expected) << "radians " << r;
    }
    EXPECT_EQ(serialize::degrees(deg_to_rad(30.0)).get<double>(), 30.0);
    EXPECT_TRUE(serialize::degrees(kNaN).is_null());
}

TEST(SerializeJson, DegreesOfAGivenAngleAreTheShortestDecimalThatMapsBackToo) {
    // degrees(radians, given) against the brute-force definition for angles typed with 1 to 13
    // digits (its shortcut), typed with 16-17 digits (a shorter decimal may map to the same
    // radians: 29.999999999999996 gives 30), given degrees that do not convert to the radians,
    // and the ends of the double range.
    const auto brute_force = shortest_degrees_brute_force;
    std::mt19937_64 rng(11);
    std::uniform_int_distribution<std::int64_t> mantissa(-9'999'999'999'999, 9'999'999'999'999);
    std::uniform_int_distribution<int> places(0, 13), digits(1, 13);
    std::uniform_real_distribution<double> any(-400.0, 400.0);
    std::vector<double> given = {
        30.0, 29.999999999999996, 45.0, 1e-280, 1e300, -1e300, 1e-300, 1e301,
        0.1,  0.30000000000000004};
    for (int k = 0; k < 20000; ++k) {
        // A decimal of `digits` significant digits (or fewer) with `places` decimals.
        const std::int64_t m =
            mantissa(rng) / static_cast<std::int64_t>(std::pow(10, 13 - digits(rng)));
        given.push_back(static_cast<double>(m) / std::pow(10.0, places(rng)));
        given.push_back(any(rng));  // 16-17 digits
    }
    std::size_t shortened = 0;
    for (const double d : given) {
        const double r = deg_to_rad(d);
        const double expected = brute_force(r);
        ASSERT_EQ(serialize::degrees(r, d).get<double>(), expected) << "degrees " << d;
        shortened += expected != d;
        // Given degrees that convert to other radians: degrees(radians) itself.
        const double other = std::nextafter(r, 10.0);
        ASSERT_EQ(serialize::degrees(other, d).get<double>(), brute_force(other)) << d;
    }
    EXPECT_GT(shortened, 100U);  // the 16-17 digit angles do meet shorter decimals
    EXPECT_EQ(serialize::degrees(deg_to_rad(29.999999999999996), 29.999999999999996).get<double>(),
              brute_force(deg_to_rad(29.999999999999996)));
    EXPECT_TRUE(serialize::degrees(kNaN, 30.0).is_null());
}

TEST(SerializeEstimation, RoughnessEstimateHasTheDocumentedKeys) {
    RoughnessEstimate e;
    e.sigma_over_T = Estimate{0.5, 0.01};
    e.rms_slope = Estimate{0.5 * std::sqrt(2.0), 0.01 * std::sqrt(2.0)};
    e.theta_K_rad = Estimate{1.0, 0.1};
    e.xi_K = Estimate{kNaN, 0.0};  // an undefined value is null
    e.roughness_class = RoughnessClass::VeryRough;
    e.warnings = {"w1"};
    const Json j = serialize::to_json(e, true);
    for (const char* k : {"sigma_um", "sigma_um_stderr", "T_um", "T_um_stderr", "sigma_over_T",
                          "sigma_over_T_stderr", "theta_K_deg", "theta_K_deg_stderr", "xi_K",
                          "xi_K_stderr", "rms_slope", "rms_slope_stderr", "roughness_class",
                          "roughness_class_assumed", "g", "warnings"})
        EXPECT_TRUE(j.contains(k)) << k;
    EXPECT_EQ(j.size(), 16u);
    EXPECT_EQ(j["sigma_over_T"], 0.5);
    EXPECT_EQ(j["sigma_over_T_stderr"], 0.01);
    EXPECT_DOUBLE_EQ(j["theta_K_deg"].get<double>(), 180.0 / kPi);
    EXPECT_DOUBLE_EQ(j["theta_K_deg_stderr"].get<double>(), 18.0 / kPi);
    EXPECT_TRUE(j["sigma_um"].is_null());
    EXPECT_TRUE(j["xi_K"].is_null());
    EXPECT_TRUE(j["g"].is_null());
    EXPECT_EQ(j["roughness_class"], "very_rough");
    EXPECT_EQ(j["warnings"], Json::array({"w1"}));
    // Without standard errors the *_stderr keys are absent.
    const Json plain = serialize::to_json(e, false);
    EXPECT_FALSE(plain.contains("sigma_over_T_stderr"));
    EXPECT_EQ(plain.size(), 10u);
}

TEST(SerializeEstimation, SlopeDocumentMatchesTheEstimator) {
    SlopeInput in;
    in.E1_over_E2 = 1.880176;
    in.geom1 = make_geometry(deg_to_rad(45.0), 0.0, 0.0);
    in.geom2 = make_geometry(deg_to_rad(67.5), 0.0, 0.0);
    in.correlation = Correlation::Gaussian;
    const RoughnessEstimate eg = estimate_slope(in);
    const Json j = serialize::slope_estimate_json(in, eg, std::nullopt, false);
    EXPECT_EQ(j["estimator"], "slope ratio (Eq. 16-19)");
    EXPECT_EQ(j["sigma_over_T"].get<double>(), eg.sigma_over_T->value);
    EXPECT_EQ(j["sigma_over_T_gaussian"].get<double>(), eg.sigma_over_T->value);
    EXPECT_TRUE(j["sigma_over_T_exponential"].is_null());
    EXPECT_FALSE(j.contains("valid_ratio_range_exponential"));
    ASSERT_TRUE(j["valid_ratio_range_gaussian"].is_array());
    EXPECT_TRUE(j["valid_ratio_range_gaussian"][1].is_null());  // no upper bound: null, not inf
    EXPECT_EQ(j["geometry2"]["theta_i_deg"].get<double>(), rad_to_deg(deg_to_rad(67.5)));
    // Failure: neither estimate.
    EXPECT_THROW(serialize::slope_estimate_json(in, std::nullopt, std::nullopt, false),
                 InvalidArgument);
}

// The keys generated from the correlation names are the documented ones (docs/estimation.md), in
// the documented order, with every correlation function given.
TEST(SerializeEstimation, SlopeKeysGeneratedPerCorrelationAreTheDocumentedOnes) {
    SlopeInput in;
    in.E1_over_E2 = 1.880176;
    in.geom1 = make_geometry(deg_to_rad(45.0), 0.0, 0.0);
    in.geom2 = make_geometry(deg_to_rad(67.5), 0.0, 0.0);
    in.sigma_um = 2.0;
    PerCorrelation<std::optional<RoughnessEstimate>> estimates;
    for (const Correlation c : kCorrelations) {
        in.correlation = c;
        estimates[c] = estimate_slope(in);
    }
    const Json j = serialize::slope_estimate_json(in, estimates, true);
    std::vector<std::string> keys;
    for (const auto& item : j.items()) keys.push_back(item.key());
    const std::vector<std::string> documented{"estimator",
                                              "sigma_over_T",
                                              "sigma_over_T_stderr",
                                              "sigma_over_T_gaussian",
                                              "sigma_over_T_gaussian_stderr",
                                              "sigma_over_T_exponential",
                                              "sigma_over_T_exponential_stderr",
                                              "sigma_um",
                                              "T_um",
                                              "T_um_stderr",
                                              "T_um_gaussian",
                                              "T_um_gaussian_stderr",
                                              "T_um_exponential",
                                              "T_um_exponential_stderr"};
    ASSERT_GE(keys.size(), documented.size());
    EXPECT_EQ(std::vector<std::string>(keys.begin(), keys.begin() + documented.size()), documented);
    for (const char* k : {"valid_ratio_range_gaussian", "valid_ratio_range_exponential"})
        EXPECT_TRUE(j.contains(k)) << k;
    // Each correlation's value is its own estimator's; the two-name form gives the same document.
    for (const Correlation c : kCorrelations)
        EXPECT_EQ(j[correlation_key("sigma_over_T", c)].get<double>(),
                  estimates[c]->sigma_over_T->value);
    EXPECT_EQ(serialize::slope_estimate_json(in, estimates[Correlation::Gaussian],
                                             estimates[Correlation::Exponential], true)
                  .dump(),
              j.dump());
    EXPECT_THROW(serialize::slope_estimate_json(in, {}, false), InvalidArgument);
}

TEST(SerializeEstimation, FitOptionsFromNamedValues) {
    const FitOptions o = serialize::fit_options_from(Json{{"model", "slightly_rough"},
                                                          {"correlation", "exponential"},
                                                          {"factor", "beckmann"},
                                                          {"loss", "huber"},
                                                          {"loss_scale", 0.1},
                                                          {"sigma_over_T_bounds", {0.1, 10.0}},
                                                          {"initial_sigma_um", nullptr},
                                                          {"max_iterations", 50},
                                                          {"scale_covariance", false}});
    EXPECT_EQ(o.model, FitModel::SlightlyRough);
    EXPECT_EQ(o.correlation, Correlation::Exponential);
    EXPECT_EQ(o.factor, GeometricFactor::Beckmann);
    EXPECT_EQ(o.loss, LossType::Huber);
    EXPECT_EQ(o.loss_scale, 0.1);
    EXPECT_EQ(o.sigma_over_T_min, 0.1);
    EXPECT_EQ(o.sigma_over_T_max, 10.0);
    EXPECT_FALSE(o.initial_sigma_um.has_value());
    EXPECT_EQ(o.max_iterations, 50);
    EXPECT_FALSE(o.scale_covariance);
    EXPECT_EQ(serialize::fit_options_from(Json(nullptr)).model, FitModel::VeryRough);
    // Failures name the key.
    EXPECT_THROW(serialize::fit_options_from(Json{{"modle", "very_rough"}}), InvalidArgument);
    EXPECT_THROW(serialize::fit_options_from(Json{{"loss", "l1"}}), InvalidArgument);
    EXPECT_THROW(serialize::fit_options_from(Json{{"loss_scale", "big"}}), InvalidArgument);
    EXPECT_THROW(serialize::fit_options_from(Json{{"T_bounds_um", {1.0}}}), InvalidArgument);
    EXPECT_THROW(serialize::fit_options_from(Json{{"max_iterations", 2.5}}), InvalidArgument);
    EXPECT_THROW(serialize::fit_options_from(Json::array({1})), InvalidArgument);
    try {
        serialize::fit_options_from(Json{{"loss_scale", "big"}});
    } catch (const InvalidArgument& e) {
        EXPECT_NE(std::string(e.what()).find("loss_scale"), std::string::npos) << e.what();
    }
}

TEST(SerializeEstimation, FitResultKeysAndNullsWithoutCovariance) {
    std::vector<Measurement> ms;
    for (double t : {0.0, 10.0, 20.0, 30.0, 40.0, 50.0})
        ms.push_back({make_geometry(deg_to_rad(t), 0.0, 0.0),
                      2.0 * very_rough_brightness(make_geometry(deg_to_rad(t), 0.0, 0.0), 0.4,
                                                  Correlation::Gaussian),
                      1.0});
    FitResult r = fit_roughness(ms, {});
    Json j = serialize::to_json(r, true);
    EXPECT_EQ(j["parameters"], r.num_parameters);
    EXPECT_EQ(j["parameter_table"].size(), r.parameters.size());
    EXPECT_EQ(j["parameter_table"][0]["name"], "sigma_over_T");
    EXPECT_NEAR(j["sigma_over_T"].get<double>(), 0.4, 1e-8);
    EXPECT_NEAR(j["gain"].get<double>(), 2.0, 1e-8);
    EXPECT_EQ(j["residuals"].size(), ms.size());
    EXPECT_EQ(j["predicted"].size(), ms.size());
    EXPECT_EQ(j["status"], std::string(to_string(r.status)));
    r.covariance_available = false;
    r.aicc = kInf;
    j = serialize::to_json(r, false);
    EXPECT_TRUE(j["covariance"].is_null());
    EXPECT_TRUE(j["sigma_over_T_stderr"].is_null());
    EXPECT_TRUE(j["gain_stderr"].is_null());
    EXPECT_TRUE(j["aicc"].is_null());
    EXPECT_FALSE(j.contains("residuals"));
}

TEST(SerializeModel, ScatteredPowerKeys) {
    ScatteredPower p;
    p.coherent = 0.25;
    p.diffuse = 0.5;
    p.total = 0.75;
    p.brightness = kNaN;
    p.g = 3.0;
    p.regime = Regime::Series;
    p.roughness_class = RoughnessClass::ModeratelyRough;
    p.method = DiffuseMethod::LargeGExpansion;
    p.relative_error_bound = 0.125;
    const Json j = serialize::to_json(p);
    EXPECT_EQ(j.dump(), R"({"brightness":null,"coherent":0.25,"diffuse":0.5,"total":0.75,"g":3.0,)"
                        R"("regime":"series","roughness_class":"moderately_rough",)"
                        R"("method":"large_g_expansion","relative_error_bound":0.125})");
}

BrdfTable small_table() {
    BrdfTable t;
    t.name = "synthetic";
    int k = 1;
    for (double ti : {0.0, 20.0, 40.0, 60.0})
        for (double ts : {0.0, 15.0, 30.0, 45.0})
            for (double ps : {0.0, 90.0, 180.0}) {
                const Geometry g = make_geometry(deg_to_rad(ti), deg_to_rad(ts), deg_to_rad(ps));
                const double E = very_rough_brightness(g, 0.7, Correlation::Gaussian);
                t.measurements.push_back(
                    make_brdf_measurement(k++, deg_to_rad(ti), deg_to_rad(180.0), deg_to_rad(ts),
                                          deg_to_rad(ps), E / std::cos(deg_to_rad(ti)), 1.0));
            }
    return t;
}

TEST(SerializeComparison, OptionsFromNamedValues) {
    const ComparisonOptions o =
        serialize::comparison_options_from(Json{{"theta1_deg", 45.0},
                                                {"theta2_deg", 67.5},
                                                {"pair", {1, 2}},
                                                {"fits", false},
                                                {"on_sigma_rad", 0.3},
                                                {"on_albedo", 0.8},
                                                {"radiometry", "intensity"}});
    EXPECT_EQ(o.measurement1, 1);
    EXPECT_EQ(o.measurement2, 2);
    EXPECT_FALSE(o.fits);
    EXPECT_EQ(o.radiometry, Radiometry::Intensity);
    ASSERT_TRUE(o.oren_nayar.has_value());
    EXPECT_EQ(o.oren_nayar->sigma_rad, 0.3);
    EXPECT_EQ(o.oren_nayar_source, "given");
    EXPECT_DOUBLE_EQ(*o.theta2_rad, deg_to_rad(67.5));
    EXPECT_THROW(serialize::comparison_options_from(Json{{"theta1_deg", 45.0}}), InvalidArgument);
    EXPECT_THROW(serialize::comparison_options_from(Json{{"on_albedo", 0.5}}), InvalidArgument);
    EXPECT_THROW(serialize::comparison_options_from(Json{{"pair", {0, 2}}}), InvalidArgument);
    EXPECT_THROW(serialize::comparison_options_from(Json{{"pair", {1, 2, 3}}}), InvalidArgument);
    EXPECT_THROW(serialize::comparison_options_from(Json{{"radiometry", "watts"}}),
                 InvalidArgument);
    EXPECT_THROW(serialize::comparison_options_from(Json{{"max_overflow", 2.0}}), InvalidArgument);
    EXPECT_THROW(serialize::comparison_options_from(Json{{"thetal_deg", 1.0}}), InvalidArgument);
}

TEST(SerializeComparison, JsonCsvMarkdownOfAKnownTable) {
    ComparisonOptions o = serialize::comparison_options_from(
        Json{{"pair", {1, 13}}, {"fits", false}});  // θi = 0° and 20°, viewer on the normal
    const Comparison c = compare_brdf(small_table(), o);
    const Json j = serialize::to_json(c, true);
    for (const char* key :
         {"sample", "name", "channel", "measurements", "used", "E1_over_E2",
          "sigma_over_T_gaussian", "sigma_over_T_exponential", "two_point", "sse", "rmse",
          "sse_gain", "winner", "winner_paper_metric", "models", "data_issues", "series"})
        EXPECT_TRUE(j.contains(key)) << key;
    EXPECT_TRUE(j["sample"].is_null());
    EXPECT_EQ(j["name"], "synthetic");
    EXPECT_EQ(j["measurements"], 48);
    EXPECT_EQ(j["series"]["data"].size(), 48u);
    EXPECT_EQ(j["models"]["vh_gaussian"]["label"], "V–H–B–K(G)");
    EXPECT_TRUE(j["sse"]["vh_gaussian_fit"].is_null());  // fits not requested
    const std::string text = serialize::dump(serialize::to_json(std::vector<Comparison>{c, c}));
    EXPECT_EQ(text.find("nan"), std::string::npos);
    EXPECT_EQ(Json::parse(text).size(), 2u);
    EXPECT_FALSE(serialize::to_json(c, false).contains("series"));

    const std::string csv = serialize::to_csv({c, c});
    EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 3);
    EXPECT_EQ(csv.rfind(serialize::csv_header(), 0), 0u);
    EXPECT_NE(csv.find("sse_vh_exponential"), std::string::npos);
    EXPECT_EQ(serialize::csv_row(c).find(",synthetic,"), 0u);
    const std::string md = serialize::to_markdown({c});
    EXPECT_NE(md.find("| synthetic |"), std::string::npos) << md;
}

}  // namespace
