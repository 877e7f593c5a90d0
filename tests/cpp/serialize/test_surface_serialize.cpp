// The surface documents (serialize/surface.hpp): the keys in their documented order, unknown
// values null (never NaN), the input echo, the text form, the prediction document against the
// prediction it came from, and the height-map summary and image.
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/serialize/surface.hpp"
#include "roughscope/surface/height_map.hpp"
#include "roughscope/surface/predict.hpp"

using namespace roughscope;
using serialize::Json;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::vector<std::string> keys_of(const Json& j) {
    std::vector<std::string> out;
    for (auto it = j.begin(); it != j.end(); ++it) out.push_back(it.key());
    return out;
}

surface::SurfaceStatistics some_stats() {
    surface::SurfaceStatistics s;
    s.points = 100;
    s.sigma_um = 0.5;
    s.Sa_um = 0.4;
    s.Ssk = 0.1;
    s.Sku = 3.0;
    s.Sp_um = 1.5;
    s.Sv_um = 1.4;
    s.Sz_um = 2.9;
    s.T_um = 10.0;
    s.T_fit_gaussian_um = 10.5;
    s.correlation = Correlation::Gaussian;
    s.rms_slope = kNaN;  // a NaN that slipped through must still come out null
    s.warnings = {"L/T < 50"};
    s.acf_x = {{0.0, 1.0}, {1.0, 0.5}};
    return s;
}

TEST(SerializeSurface, StatisticsKeysInOrderAndNulls) {
    const surface::HeightMap map = surface::make_height_map(10, 10, 0.5, 0.25);
    surface::StatisticsOptions o;
    o.cutoff_um = 80.0;
    const auto in = serialize::statistics_input(map, o, "a.x3p", "x3p");
    const Json j = serialize::to_json(in, some_stats());
    const std::vector<std::string> expected = {"file",
                                               "format",
                                               "nx",
                                               "ny",
                                               "dx_um",
                                               "dy_um",
                                               "leveling",
                                               "polynomial_order",
                                               "cutoff_um",
                                               "acf_estimator",
                                               "points",
                                               "sigma_um",
                                               "sigma_stderr_um",
                                               "Sa_um",
                                               "Ssk",
                                               "Sku",
                                               "Sp_um",
                                               "Sv_um",
                                               "Sz_um",
                                               "T_um",
                                               "T_y_um",
                                               "T_stderr_um",
                                               "T_fit_gaussian_um",
                                               "T_fit_exponential_um",
                                               "correlation",
                                               "T_extrapolated_um",
                                               "period_um",
                                               "period_y_um",
                                               "Sal_um",
                                               "Str",
                                               "Str_note",
                                               "rms_slope",
                                               "rms_slope_y",
                                               "Sdq",
                                               "m_from_T",
                                               "warnings"};
    EXPECT_EQ(keys_of(j), expected);
    EXPECT_EQ(j["file"], "a.x3p");
    EXPECT_EQ(j["format"], "x3p");
    EXPECT_EQ(j["nx"], 10);
    EXPECT_EQ(j["dy_um"], 0.25);
    EXPECT_EQ(j["cutoff_um"], 80.0);
    EXPECT_TRUE(j["polynomial_order"].is_null());
    EXPECT_EQ(j["sigma_um"], 0.5);
    EXPECT_EQ(j["correlation"], "gaussian");
    EXPECT_TRUE(j["T_y_um"].is_null());
    EXPECT_TRUE(j["rms_slope"].is_null());
    EXPECT_EQ(j["warnings"].size(), 1u);
    EXPECT_EQ(serialize::dump(j).find("NaN"), std::string::npos);
    EXPECT_FALSE(j.contains("curves"));
    const Json c = serialize::to_json(in, some_stats(), true);
    ASSERT_TRUE(c.contains("curves"));
    EXPECT_EQ(c["curves"]["acf_x"]["lag_um"], Json::array({0.0, 1.0}));
    EXPECT_EQ(c["curves"]["acf_x"]["acf"], Json::array({1.0, 0.5}));
    EXPECT_EQ(c["curves"]["psd_x"]["frequency_per_um"], Json::array());
    // Arrays from Python: no file, no format.
    const Json p = serialize::to_json(serialize::statistics_input(map, {}), some_stats());
    EXPECT_TRUE(p["file"].is_null());
    EXPECT_TRUE(p["format"].is_null());
    EXPECT_TRUE(p["cutoff_um"].is_null());
}

TEST(SerializeSurface, StatisticsText) {
    const surface::HeightMap map = surface::make_height_map(10, 10, 0.5, 0.5);
    const std::string t = serialize::to_text(
        serialize::statistics_input(map, {}, "a.csv", "csv_matrix"), some_stats());
    EXPECT_NE(t.find("a.csv (csv_matrix): 10 x 10 points"), std::string::npos) << t;
    EXPECT_NE(t.find("sigma (Sq)"), std::string::npos);
    EXPECT_NE(t.find("0.5 um"), std::string::npos);
    EXPECT_NE(t.find("warning: L/T < 50"), std::string::npos);
    EXPECT_EQ(t.find("nan"), std::string::npos);
}

TEST(SerializeSurface, StatisticsTextLabelsEachSlopeAndSaysWhyStrIsMissing) {
    const surface::HeightMap map = surface::make_height_map(10, 10, 0.5, 0.5);
    surface::SurfaceStatistics s = some_stats();
    s.rms_slope = 0.25;
    s.rms_slope_y = 0.125;
    s.Sdq = 0.375;
    s.period_um = 32.5;
    s.Str_note = "the ACF stays above 0.2";
    const auto in = serialize::statistics_input(map, {}, "a.csv", "csv_matrix");
    const Json j = serialize::to_json(in, s);
    EXPECT_EQ(j["Sdq"], 0.375);
    EXPECT_EQ(j["rms_slope_y"], 0.125);
    EXPECT_EQ(j["period_um"], 32.5);
    EXPECT_TRUE(j["period_y_um"].is_null());
    EXPECT_EQ(j["Str_note"], "the ACF stays above 0.2");
    EXPECT_TRUE(serialize::to_json(in, some_stats())["Str_note"].is_null());
    const std::string t = serialize::to_text(in, s);
    EXPECT_NE(t.find("RMS slope along x (Rdq)  0.25\n"), std::string::npos) << t;
    EXPECT_NE(t.find("RMS slope along y (Rdq)  0.125\n"), std::string::npos) << t;
    EXPECT_NE(t.find("RMS gradient (Sdq)       0.375\n"), std::string::npos) << t;
    EXPECT_NE(t.find("period (ACF, x)          32.5 um\n"), std::string::npos) << t;
    EXPECT_NE(t.find("Str                      - (the ACF stays above 0.2)\n"), std::string::npos)
        << t;
    EXPECT_EQ(t.find("RMS slope (Sdq)"), std::string::npos);
}

TEST(SerializeSurface, PredictionDocumentMatchesThePrediction) {
    const auto p = surface::predict_brightness(
        Surface{0.3, 3.0, Correlation::Exponential},
        {make_geometry(deg_to_rad(30.0), deg_to_rad(10.0), deg_to_rad(20.0))});
    const Json j = serialize::to_json(p, ModelOptions{}, "m.x3p", "T_um");
    EXPECT_EQ(j["source"], "m.x3p");
    EXPECT_EQ(j["T_source"], "T_um");
    EXPECT_EQ(j["correlation"], "exponential");
    EXPECT_EQ(j["roughness_class"], "very_rough");
    EXPECT_EQ(j["g_normal"].get<double>(), p.g_normal);
    EXPECT_EQ(j["theta_K_deg"].get<double>(), rad_to_deg(p.theta_K_rad));
    ASSERT_EQ(j["points"].size(), 1u);
    const Json& q = j["points"][0];
    EXPECT_EQ(q["theta_i_deg"], 30.0);  // echoed as entered, not 29.999999999999996
    EXPECT_EQ(q["brightness"].get<double>(), p.points[0].power.brightness);
    EXPECT_EQ(q["very_rough_brightness"].get<double>(), p.points[0].very_rough_brightness);
    EXPECT_EQ(q["regime"], "series");
    EXPECT_FALSE(q["beyond_theta_K"].get<bool>());
    const Json given = serialize::to_json(p, ModelOptions{});
    EXPECT_EQ(given["source"], "given");
    EXPECT_TRUE(given["T_source"].is_null());
    const std::string t = serialize::to_text(p, ModelOptions{});
    EXPECT_NE(t.find("very_rough"), std::string::npos);
    EXPECT_NE(t.find("exponential correlation"), std::string::npos);
}

TEST(SerializeSurface, SummaryAndImage) {
    surface::HeightMap map = surface::make_height_map(5, 3, 2.0, 1.0);
    for (std::size_t i = 0; i < map.size(); ++i) map.heights_um[i] = static_cast<double>(i);
    map.heights_um[4] = kNaN;
    const Json s = serialize::summary_json(map);
    EXPECT_EQ(s["points"], 14);
    EXPECT_EQ(s["missing"], 1);
    EXPECT_EQ(s["min_um"], 0.0);
    EXPECT_EQ(s["max_um"], 14.0);
    EXPECT_EQ(s["length_x_um"], 10.0);
    EXPECT_TRUE(s["title"].is_null());

    const Json full = serialize::height_image_json(map, 512);
    EXPECT_EQ(full["stride"], 1);
    EXPECT_EQ(full["heights_um"].size(), 3u);
    EXPECT_TRUE(full["heights_um"][0][4].is_null());  // the missing point
    EXPECT_EQ(full["heights_um"][2][1], 11.0);
    const Json small = serialize::height_image_json(map, 2);  // stride 3: columns 0, 3; row 0
    EXPECT_EQ(small["stride"], 3);
    EXPECT_EQ(small["nx"], 2);
    EXPECT_EQ(small["ny"], 1);
    EXPECT_EQ(small["dx_um"], 6.0);
    EXPECT_EQ(small["heights_um"][0], Json::array({0.0, 3.0}));
}

TEST(SerializeSurface, ImageRejectsZeroSide) {
    EXPECT_THROW(serialize::height_image_json(surface::make_height_map(2, 2, 1, 1), 0),
                 InvalidArgument);
}

}  // namespace
