// Numbers measure() must not state with confidence they do not have (image/measure.hpp,
// docs/measure.md), on synthetic captures of known roughness (simulation/capture.hpp) written as
// files and read back: T given σ comes from the form valid at the sample's g; a standard error
// the captures cannot give is unknown (NaN, null in the JSON), not 0; an exponential σ/T carries
// the note on Eq. 5.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "../io/test_files.hpp"
#include "../maps/map_captures.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/estimation/estimation.hpp"
#include "roughscope/io/output_file.hpp"
#include "roughscope/maps/maps.hpp"
#include "roughscope/measure/measure.hpp"
#include "roughscope/scattering/factors.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/serialize/measure.hpp"
#include "roughscope/simulation/capture.hpp"

namespace roughscope::image {
namespace {

namespace fs = std::filesystem;
namespace sim = roughscope::simulation;
using roughscope::testing::light_at;
using roughscope::testing::linear_camera;
using roughscope::testing::render_pair;
using roughscope::testing::Rendered;
using roughscope::testing::very_rough_truth;

// The exact diffuse brightness of σ and T at 0.555 µm: the series of Eq. 2 (the coherent term
// of Eq. 1, a finite patch's sinc² off the specular direction, is not what a photograph of a
// large sample shows, and no estimator models it).
sim::SurfaceTruth exact(double sigma_um, double T_um,
                        Correlation correlation = Correlation::Gaussian) {
    sim::SurfaceTruth truth;
    truth.model = sim::BrightnessModel::Tabulated;
    truth.sigma_um = sigma_um;
    truth.T_um = T_um;
    truth.tabulated = [sigma_um, T_um, correlation](const Geometry& g) {
        ModelOptions o;
        o.regime = Regime::Series;
        o.wavelength_um = 0.555;
        const ScatteredPower p = mean_scattered_power(g, Surface{sigma_um, T_um, correlation}, o);
        return p.diffuse * radiometric_factor(o.radiometry, g);
    };
    return truth;
}

// ---------------------------------------------------------------------------------------------
// T given σ: the form valid at the sample's g

struct PairResult {
    MeasureResult result;
    serialize::Json json;
};

// A 48 × 48 plane of the exact B–K brightness of (σ, T) lit at 30° and 45°, camera on the
// normal; σ given in the capture file, with `extra` keys.
PairResult measure_exact_pair(const fs::path& dir, double sigma_um, double T_um,
                              const std::string& extra) {
    sim::Scene scene;
    scene.width = scene.height = 48;
    const sim::SurfaceTruth truth = exact(sigma_um, T_um);
    const auto [a, b] = render_pair(dir, scene, light_at(30.0), light_at(45.0), truth, truth, 31);
    const std::string text =
        concat(R"({"roi": {"rect": [4, 4, 40, 40]}, "sigma_um": )", check::format_number(sigma_um),
               extra, R"(, "captures": [{"image": ")", a.file.string(),
               R"(", "theta_i_deg": 30, "exposure_s": 1}, {"image": ")", b.file.string(),
               R"(", "theta_i_deg": 45, "exposure_s": 1}]})");
    const MeasureRequest request = parse_capture_file(text, (dir / "c.json").string());
    PairResult out{measure(request), {}};
    out.json = serialize::to_json(out.result, request);
    return out;
}

double largest_g(double sigma_um) {
    return std::max(roughness_g(normal_view_geometry(deg_to_rad(30.0)), sigma_um, 0.555),
                    roughness_g(normal_view_geometry(deg_to_rad(45.0)), sigma_um, 0.555));
}

// g ≈ 96 (σ = 0.5 µm, T = 5 µm): far beyond the slightly rough range of Eq. 15, which gives T
// 10 % low; by default the exact series, which gives the truth, and the result says so.
TEST(MeasureCorrelationLength, LargeGUsesTheExactSeriesByDefault) {
    const fs::path dir = roughscope::testing::fresh_dir("measure_numbers_large_g");
    constexpr double kSigma = 0.5, kT = 5.0;
    ASSERT_GT(largest_g(kSigma), 90.0);
    const PairResult d = measure_exact_pair(dir, kSigma, kT, "");
    ASSERT_TRUE(d.result.correlation_length && d.result.correlation_length->T_um);
    const Estimate T = *d.result.correlation_length->T_um;
    const PairResult eq15 = measure_exact_pair(dir, kSigma, kT, R"(, "regime": "slightly_rough")");
    ASSERT_TRUE(eq15.result.correlation_length && eq15.result.correlation_length->T_um);
    const double T15 = eq15.result.correlation_length->T_um->value;
    std::printf("g = %.1f: T = %.4f ± %.4f µm by default (truth %g), Eq. 15 %.4f µm\n",
                largest_g(kSigma), T.value, T.std_error, kT, T15);
    EXPECT_LE(std::abs(T.value - kT), 4.0 * T.std_error + 0.005 * kT);
    EXPECT_GT(std::abs(T15 - kT), 0.05 * kT);  // what the default used to give
    EXPECT_EQ(d.json["T_um_regime"], "series");
    EXPECT_EQ(d.json["T_um_regime_source"], "g");
    EXPECT_EQ(eq15.json["T_um_regime"], "slightly_rough");
    EXPECT_EQ(eq15.json["T_um_regime_source"], "capture_file");
    bool said = false;
    for (const auto& w : d.result.warnings) said |= w.find("exact series") != w.npos;
    EXPECT_TRUE(said);
    fs::remove_all(dir);
}

// g ≈ 0.045 (σ = 0.01 µm, T = 0.3 µm): slightly rough, so the default is the paper's Eq. 15,
// which gives the truth there.
TEST(MeasureCorrelationLength, SmallGUsesEq15ByDefault) {
    const fs::path dir = roughscope::testing::fresh_dir("measure_numbers_small_g");
    constexpr double kSigma = 0.01, kT = 0.3;
    ASSERT_LT(largest_g(kSigma), 0.1);
    const PairResult d = measure_exact_pair(dir, kSigma, kT, "");
    ASSERT_TRUE(d.result.correlation_length && d.result.correlation_length->T_um);
    const Estimate T = *d.result.correlation_length->T_um;
    std::printf("g = %.3f: T = %.4f ± %.4f µm by default (truth %g)\n", largest_g(kSigma), T.value,
                T.std_error, kT);
    EXPECT_LE(std::abs(T.value - kT), 4.0 * T.std_error + 0.01 * kT);
    EXPECT_EQ(d.json["T_um_regime"], "slightly_rough");
    EXPECT_EQ(d.json["T_um_regime_source"], "g");
    fs::remove_all(dir);
}

// A map with σ known of a very rough flat sample (g = 18, σ = 0.2 µm, T = 1 µm, the exact
// diffuse brightness): T from the exact series, the truth for both correlations (σ/(σ/T) of
// Eq. 17 gave T 4 % high, of Eq. 19 81 % low or none).
TEST(MapCorrelationLength, AVeryRoughSampleUsesTheExactSeries) {
    sim::Scene scene;
    scene.width = scene.height = 32;
    const double t1 = deg_to_rad(30.0), t2 = deg_to_rad(45.0);
    for (const Correlation c : {Correlation::Gaussian, Correlation::Exponential}) {
        const roughscope::testing::LitPair p =
            roughscope::testing::render_lit_pair(scene, {exact(0.2, 1.0, c)}, {}, {}, t1, t2, 71);
        std::vector<MapCapture> captures(2);
        captures[0].image = &p.a;
        captures[0].geometry = normal_view_geometry(t1);
        captures[1].image = &p.b;
        captures[1].geometry = normal_view_geometry(t2);
        MapOptions o;
        o.sigma_um = 0.2;
        o.correlation = c;
        const RoughnessMap map = roughness_map(captures, o);
        std::vector<float> T;
        for (std::size_t i = 0; i < map.T_um.size(); ++i) {
            EXPECT_EQ(map.roughness_class_g[i], kClassVeryRough);
            if (std::isfinite(map.T_um[i])) T.push_back(map.T_um[i]);
        }
        ASSERT_EQ(T.size(), map.width * map.height) << to_string(c);
        std::nth_element(T.begin(), T.begin() + T.size() / 2, T.end());
        std::printf("%s, g = 18: median T = %.4f µm (truth 1)\n", std::string(to_string(c)).c_str(),
                    T[T.size() / 2]);
        EXPECT_NEAR(T[T.size() / 2], 1.0, 0.005) << to_string(c);
    }
}

// ---------------------------------------------------------------------------------------------
// Standard errors the captures cannot give

// Two 1 × 1 photographs, the region their one pixel: a standard error of exactly 0 would claim
// an exact ratio; it is unknown (NaN, null in the JSON), with a warning naming the captures.
TEST(MeasureStandardErrors, AOnePixelRegionHasUnknownErrors) {
    const fs::path dir = roughscope::testing::fresh_dir("measure_numbers_one_pixel");
    sim::Scene scene;
    scene.width = scene.height = 1;
    const auto [a, b] = render_pair(dir, scene, light_at(30.0), light_at(45.0),
                                    very_rough_truth(0.4), very_rough_truth(0.4), 41);
    const std::string text =
        concat(R"({"roi": {"rect": [0, 0, 1, 1]}, "sigma_um": 2, "captures": [{"image": ")",
               a.file.string(), R"(", "theta_i_deg": 30, "exposure_s": 1}, {"image": ")",
               b.file.string(), R"(", "theta_i_deg": 45, "exposure_s": 1}]})");
    const MeasureRequest request = parse_capture_file(text, (dir / "c.json").string());
    const MeasureResult result = measure(request);
    ASSERT_TRUE(result.E1_over_E2 && result.slope_gaussian && result.slope_gaussian->sigma_over_T);
    EXPECT_TRUE(std::isfinite(result.E1_over_E2->value));
    EXPECT_TRUE(std::isnan(result.E1_over_E2->std_error));
    EXPECT_TRUE(std::isnan(result.slope_gaussian->sigma_over_T->std_error));
    const serialize::Json json = serialize::to_json(result, request);
    for (const char* key : {"E1_over_E2", "sigma_over_T_gaussian", "T_um", "theta_K_deg"}) {
        EXPECT_TRUE(json[key].is_number()) << key;
        EXPECT_TRUE(json[std::string(key) + "_stderr"].is_null()) << key;
    }
    std::size_t said = 0;
    for (const auto& w : result.warnings) said += w.find("no measurable noise") != w.npos;
    EXPECT_EQ(said, 2u);
    fs::remove_all(dir);
}

// A specular photograph without noise (a uniform disc in a uniform surround, 64 px): its σ has
// no standard error to give, nor has T given that σ; both are unknown (null), with a warning.
TEST(MeasureStandardErrors, ANoiseFreeHighlightGivesSigmaWithAnUnknownError) {
    const fs::path dir = roughscope::testing::fresh_dir("measure_numbers_highlight");
    sim::Scene scene;
    scene.width = scene.height = 64;
    std::vector<std::int32_t> labels(64 * 64, 0);
    for (std::size_t r = 0; r < 64; ++r)
        for (std::size_t c = 0; c < 64; ++c) {
            const double dx = static_cast<double>(c) + 0.5 - 32.0;
            const double dy = static_cast<double>(r) + 0.5 - 32.0;
            if (dx * dx + dy * dy <= 36.0) labels[r * 64 + c] = 1;
        }
    auto constant = [](double value) {
        sim::SurfaceTruth t;
        t.model = sim::BrightnessModel::Tabulated;
        t.tabulated = [value](const Geometry&) { return value; };
        return t;
    };
    scene.light = light_at(14.0);
    scene.view = sim::direction_from_angles(deg_to_rad(14.0), 0.0);
    sim::CaptureOptions options;
    options.threads = 1;
    const sim::Capture specular = sim::render_capture(scene, {constant(1.0), constant(2.0)}, labels,
                                                      linear_camera(2.0, 61, false), options);
    const fs::path specular_file = dir / "specular.tiff";
    io::write_file_atomic(specular_file, sim::encode_capture_tiff(specular));
    sim::Scene plane;
    plane.width = plane.height = 64;
    // The pair: the exact diffuse brightness of the σ the highlight gives (Eq. 13, R_spec = 1/2)
    // and T = 0.3 µm.
    const double sigma =
        0.555 / (4.0 * kPi * std::cos(deg_to_rad(14.0))) * std::sqrt(std::log(2.0));
    const auto [a, b] = render_pair(dir, plane, light_at(30.0), light_at(45.0), exact(sigma, 0.3),
                                    exact(sigma, 0.3), 62);
    const std::string text = concat(
        R"({"roi": {"rect": [8, 8, 48, 48]}, "highlight": {"core_radius_px": 4,
        "annulus_inner_px": 9, "annulus_outer_px": 14}, "captures": [{"image": ")",
        specular_file.string(),
        R"(", "theta_i_deg": 14, "theta_s_deg": 14, "role": "specular", "exposure_s": 1},
        {"image": ")",
        a.file.string(), R"(", "theta_i_deg": 30, "exposure_s": 1}, {"image": ")", b.file.string(),
        R"(", "theta_i_deg": 45, "exposure_s": 1}]})");
    const MeasureRequest request = parse_capture_file(text, (dir / "c.json").string());
    const MeasureResult result = measure(request);
    ASSERT_TRUE(result.sigma && result.sigma->sigma_um);
    EXPECT_GT(result.sigma->sigma_um->value, 0.0);
    EXPECT_TRUE(std::isnan(result.sigma->sigma_um->std_error));
    ASSERT_TRUE(result.correlation_length && result.correlation_length->T_um);
    EXPECT_TRUE(std::isnan(result.correlation_length->T_um->std_error));
    EXPECT_NEAR(result.correlation_length->T_um->value, 0.3, 0.01);
    // σ/T from the noisy pair keeps its error.
    EXPECT_GT(result.slope_gaussian->sigma_over_T->std_error, 0.0);
    const serialize::Json json = serialize::to_json(result, request);
    EXPECT_TRUE(json["sigma_um"].is_number());
    EXPECT_TRUE(json["sigma_um_stderr"].is_null());
    EXPECT_TRUE(json["T_um_stderr"].is_null());
    bool said = false;
    for (const auto& w : result.warnings)
        said |= w.find("the standard error of σ is unknown") != w.npos;
    EXPECT_TRUE(said);
    fs::remove_all(dir);
}

// A map region of one tile: the mean over one cell has no standard error to give (unknown,
// NaN), not 0, and a warning names the region; a region of fifteen tiles keeps a finite one.
TEST(MapStandardErrors, ARegionOfOneCellHasAnUnknownError) {
    sim::Scene scene;
    scene.width = scene.height = 32;
    const double t1 = deg_to_rad(30.0), t2 = deg_to_rad(45.0);
    const roughscope::testing::LitPair p = roughscope::testing::render_lit_pair(
        scene, {roughscope::testing::very_rough_truth(0.5)}, {}, {}, t1, t2, 7);
    std::vector<MapCapture> captures(2);
    captures[0].image = &p.a;
    captures[0].geometry = normal_view_geometry(t1);
    captures[1].image = &p.b;
    captures[1].geometry = normal_view_geometry(t2);
    std::vector<std::int32_t> labels(32 * 32, 1);
    for (std::size_t r = 0; r < 8; ++r)
        for (std::size_t c = 0; c < 8; ++c) labels[r * 32 + c] = 0;
    MapOptions o;
    o.window_px = 8;
    o.region_labels = labels;
    o.region_names = {"one", "rest"};
    const RoughnessMap map = roughness_map(captures, o);
    ASSERT_EQ(map.regions.size(), 2u);
    ASSERT_EQ(map.regions[0].count, 1u);
    ASSERT_TRUE(map.regions[0].mean_sigma_over_T_gaussian);
    EXPECT_TRUE(std::isfinite(map.regions[0].mean_sigma_over_T_gaussian->value));
    EXPECT_TRUE(std::isnan(map.regions[0].mean_sigma_over_T_gaussian->std_error));
    ASSERT_EQ(map.regions[1].count, 15u);
    EXPECT_GT(map.regions[1].mean_sigma_over_T_gaussian->std_error, 0.0);
    bool said = false;
    for (const auto& w : map.warnings) said |= w.find("region 'one'") != w.npos;
    EXPECT_TRUE(said);
}

// ---------------------------------------------------------------------------------------------
// The exponential σ/T rests on Eq. 5

// Noise-free constant captures of a given brightness ratio at 30° and 45°.
MeasureResult measure_ratio(const fs::path& dir, double ratio) {
    sim::Scene scene;
    scene.width = scene.height = 16;
    auto constant = [](double value) {
        sim::SurfaceTruth t;
        t.model = sim::BrightnessModel::Tabulated;
        t.tabulated = [value](const Geometry&) { return value; };
        return t;
    };
    const auto [a, b] = render_pair(dir, scene, light_at(30.0), light_at(45.0), constant(ratio),
                                    constant(1.0), 51, false);
    return measure(parse_capture_file(
        concat(R"({"roi": {"rect": [2, 2, 12, 12]}, "captures": [{"image": ")", a.file.string(),
               R"(", "theta_i_deg": 30, "exposure_s": 1}, {"image": ")", b.file.string(),
               R"(", "theta_i_deg": 45, "exposure_s": 1}]})"),
        (dir / "c.json").string()));
}

bool notes_eq5(const MeasureResult& r) {
    for (const auto& w : r.warnings)
        if (w.find("exact Kirchhoff series") != w.npos && w.find("Eq. 5") != w.npos) return true;
    return false;
}

// Every result with an exponential σ/T says what it rests on; one whose ratio the exponential
// model cannot produce (above its range, inside the Gaussian one) has none and no note.
TEST(MeasureExponentialNote, EveryExponentialSigmaOverTCarriesTheNote) {
    const fs::path dir = roughscope::testing::fresh_dir("measure_numbers_exponential");
    const RatioRange exp_range = ratio_range_exponential(deg_to_rad(30.0), deg_to_rad(45.0));
    const RatioRange gauss_range = ratio_range_gaussian(deg_to_rad(30.0), deg_to_rad(45.0));
    const double inside = std::sqrt(exp_range.lower * exp_range.upper);
    const MeasureResult with = measure_ratio(dir, inside);
    ASSERT_TRUE(with.slope_exponential);
    EXPECT_TRUE(notes_eq5(with));
    const double above = 1.5 * exp_range.upper;
    ASSERT_TRUE(gauss_range.contains(above));
    const MeasureResult without = measure_ratio(dir, above);
    ASSERT_TRUE(without.slope_gaussian);
    EXPECT_FALSE(without.slope_exponential);
    EXPECT_FALSE(notes_eq5(without));
    fs::remove_all(dir);
}

}  // namespace
}  // namespace roughscope::image
