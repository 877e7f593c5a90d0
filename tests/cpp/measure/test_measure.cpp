// End to end: photographs → σ, T, σ/T (image/measure.hpp). The captures are synthetic
// (simulation/capture.hpp: a flat sample of known σ/T under the very-rough model, photon shot
// noise, read noise, quantisation and the camera's response), written as files in the formats
// people have (8-bit sRGB PNG, 16-bit linear TIFF, DNG) and read back by the image reader. The
// checks: the recovered values lie inside their reported 2σ interval in ≥ 90 % of seeded pairs;
// images with the paper's printed brightness ratios (Tables 1 and 2) give back the printed σ/T;
// the capture file's keys and its failures.
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../io/shared_data.hpp"
#include "../io/test_files.hpp"
#include "../photo/image_files.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/estimation/estimation.hpp"
#include "roughscope/io/output_file.hpp"
#include "roughscope/measure/measure.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/serialize/measure.hpp"
#include "roughscope/simulation/capture.hpp"

namespace roughscope::image {
namespace {

namespace fs = std::filesystem;
namespace sim = roughscope::simulation;

struct FileKind {
    const char* name;
    sim::CaptureFormat format;
    int bits;
    Response response;
    double black_level_dn;
};

constexpr FileKind kSrgb8{"srgb8", sim::CaptureFormat::Png, 8, Response::Srgb, 0.0};
constexpr FileKind kLinear16{"linear16", sim::CaptureFormat::Tiff, 16, Response::Linear, 64.0};
constexpr FileKind kDng{"dng", sim::CaptureFormat::Dng, 14, Response::Linear, 64.0};

constexpr std::size_t kSize = 64;  // pixels; the region is [8, 8, 48, 48]
constexpr double kElectronsPerUnitS = 20000.0;
constexpr double kFullWell = 60000.0;

Geometry normal_view(double theta_i_deg) { return Geometry{deg_to_rad(theta_i_deg), 0.0, 0.0}; }

sim::CameraModel camera_for(const FileKind& kind, double exposure_s, std::uint64_t seed) {
    sim::CameraModel camera;
    camera.electrons_per_unit_s = kElectronsPerUnitS;
    camera.full_well_e = kFullWell;
    camera.exposure_s = exposure_s;
    camera.bit_depth = kind.bits;
    camera.response = kind.response;
    camera.black_level_dn = kind.black_level_dn;
    // The full well lies 5 % above the white level (as in most cameras): a pixel that fills it
    // is clipped at the white level, where the reader flags it.
    camera.gain_dn_per_e =
        1.05 * (std::ldexp(1.0, kind.bits) - 1.0 - kind.black_level_dn) / kFullWell;
    camera.seed = seed;
    return camera;
}

// Renders one capture of a plane lit at θi (camera on the normal) and writes it to dir/name.
fs::path write_capture(const fs::path& dir, const std::string& name, const FileKind& kind,
                       const Geometry& geom, const std::vector<sim::SurfaceTruth>& truths,
                       const std::vector<std::int32_t>& labels, double exposure_s,
                       std::uint64_t seed, bool noise = true) {
    sim::Scene scene;
    scene.width = kSize;
    scene.height = kSize;
    scene.light = sim::direction_from_angles(geom.theta_i_rad, kPi);
    scene.view = sim::direction_from_angles(geom.theta_s_rad, geom.phi_s_rad);
    sim::CameraModel camera = camera_for(kind, exposure_s, seed);
    if (!noise) {
        camera.shot_noise = false;
        camera.read_noise_e = 0.0;
    }
    sim::CaptureOptions options;
    options.keep_geometry = false;
    options.threads = 1;
    const sim::Capture capture = sim::render_capture(scene, truths, labels, camera, options);
    const fs::path path = dir / concat(name, ".", sim::file_extension(kind.format));
    io::write_file_atomic(path, sim::encode_capture(capture, camera, kind.format));
    return path;
}

sim::SurfaceTruth very_rough(double sigma_over_T, Correlation correlation) {
    sim::SurfaceTruth truth;
    truth.model = sim::BrightnessModel::VeryRough;
    truth.sigma_um = sigma_over_T;
    truth.T_um = 1.0;
    truth.correlation = correlation;
    return truth;
}

sim::SurfaceTruth constant(double brightness) {
    sim::SurfaceTruth truth;
    truth.model = sim::BrightnessModel::Tabulated;
    truth.tabulated = [brightness](const Geometry&) { return brightness; };
    return truth;
}

MeasureRequest request_for(const FileKind& kind) {
    MeasureRequest request;
    request.read.response = kind.response;
    if (kind.format != sim::CaptureFormat::Dng)  // a RAW file carries its own black level
        request.read.black_level_dn = std::vector<double>{kind.black_level_dn};
    request.roi = RectangleRegion{8.0, 8.0, 48.0, 48.0};
    return request;
}

CaptureSpec diffuse_capture(const fs::path& image, const Geometry& geom, double exposure_s) {
    CaptureSpec spec;
    spec.image = image.string();
    spec.geometry = geom;
    spec.exposure_s = exposure_s;
    return spec;
}

struct Coverage {
    int trials = 0;
    int slope_inside = 0;
    int ratio_inside = 0;
    int partly_saturated = 0;
};

// One seeded pair: the paper's 30°/45° (camera on the normal) with the second capture at half
// the exposure; every fourth pair with a saturated patch inside the region.
void run_pair(const FileKind& kind, int trial, const fs::path& dir, Coverage& coverage) {
    const Correlation correlation =
        trial % 2 == 0 ? Correlation::Gaussian : Correlation::Exponential;
    const double sigma_over_T = 0.15 + 0.05 * (trial % 9);
    const sim::SurfaceTruth truth = very_rough(sigma_over_T, correlation);
    const Geometry g1 = normal_view(30.0), g2 = normal_view(45.0);
    const double b1 = sim::surface_brightness(truth, g1);
    const double b2 = sim::surface_brightness(truth, g2);
    // The first capture's mean at 40 % of the full well, the second at half its exposure.
    const double t1 = 0.4 * kFullWell / (kElectronsPerUnitS * b1);
    const double t2 = 0.5 * t1;

    std::vector<sim::SurfaceTruth> truths{truth};
    std::vector<std::int32_t> labels;
    const bool saturate = trial % 4 == 3;
    if (saturate) {  // a 6 × 6 patch inside the region, far beyond the full well
        truths.push_back(constant(1e3 * b1));
        labels.assign(kSize * kSize, 0);
        for (std::size_t r = 20; r < 26; ++r)
            for (std::size_t c = 30; c < 36; ++c) labels[r * kSize + c] = 1;
    }
    const auto seed = static_cast<std::uint64_t>(1000 * trial + 7);
    const fs::path f1 = write_capture(dir, concat("c1_", std::to_string(trial)), kind, g1, truths,
                                      labels, t1, seed);
    const fs::path f2 = write_capture(dir, concat("c2_", std::to_string(trial)), kind, g2, truths,
                                      labels, t2, seed + 1);
    MeasureRequest request = request_for(kind);
    request.captures = {diffuse_capture(f1, g1, t1), diffuse_capture(f2, g2, t2)};
    const MeasureResult result = measure(request);

    ++coverage.trials;
    ASSERT_TRUE(result.E1_over_E2);
    const double ratio = b1 / b2;
    if (std::abs(result.E1_over_E2->value - ratio) <= 2.0 * result.E1_over_E2->std_error)
        ++coverage.ratio_inside;
    const auto& slope =
        correlation == Correlation::Gaussian ? result.slope_gaussian : result.slope_exponential;
    ASSERT_TRUE(slope && slope->sigma_over_T) << kind.name << " trial " << trial;
    const Estimate& s = *slope->sigma_over_T;
    EXPECT_GT(s.std_error, 0.0);
    if (std::abs(s.value - sigma_over_T) <= 2.0 * s.std_error) ++coverage.slope_inside;
    if (saturate) {
        // The patch is left out (never averaged) and said so.
        EXPECT_EQ(result.captures[0].region.pixels_saturated, 36u);
        EXPECT_EQ(result.captures[0].region.pixels_used, 48u * 48u - 36u);
        EXPECT_FALSE(result.warnings.empty());
        ++coverage.partly_saturated;
    }
}

void check_coverage(const FileKind& kind) {
    const fs::path dir = roughscope::testing::fresh_dir(concat("measure_", kind.name));
    Coverage coverage;
    for (int trial = 0; trial < 100; ++trial) {
        run_pair(kind, trial, dir, coverage);
        if (::testing::Test::HasFatalFailure()) return;
    }
    std::filesystem::remove_all(dir);
    EXPECT_EQ(coverage.trials, 100);
    EXPECT_EQ(coverage.partly_saturated, 25);
    // A 2σ interval holds the truth 95 % of the time; ≥ 90 of 100 fails with probability < 3 %
    // only if the reported errors are right.
    EXPECT_GE(coverage.slope_inside, 90) << kind.name;
    EXPECT_GE(coverage.ratio_inside, 90) << kind.name;
    // Not vacuous: the errors are not so large that everything is inside.
    ::testing::Test::RecordProperty(concat("slope_inside_", kind.name), coverage.slope_inside);
}

TEST(MeasureEndToEnd, Srgb8PngPairsCoverTheTruth) { check_coverage(kSrgb8); }
TEST(MeasureEndToEnd, Linear16TiffPairsCoverTheTruth) { check_coverage(kLinear16); }
TEST(MeasureEndToEnd, DngPairsCoverTheTruth) { check_coverage(kDng); }

// More than two diffuse captures: the least-squares fit of both correlations recovers σ/T (and
// prefers the true correlation) from four captures at 20°, 35°, 50° and 65° with different
// exposures.
TEST(MeasureEndToEnd, FourCapturesAreFittedByLeastSquares) {
    const fs::path dir = roughscope::testing::fresh_dir("measure_fit");
    const sim::SurfaceTruth truth = very_rough(0.35, Correlation::Exponential);
    MeasureRequest request = request_for(kLinear16);
    int k = 0;
    for (const double theta : {20.0, 35.0, 50.0, 65.0}) {
        const Geometry g = normal_view(theta);
        const double t =
            (0.2 + 0.1 * k) * kFullWell / (kElectronsPerUnitS * sim::surface_brightness(truth, g));
        const fs::path f = write_capture(dir, concat("c", std::to_string(k)), kLinear16, g, {truth},
                                         {}, t, static_cast<std::uint64_t>(77 + k));
        request.captures.push_back(diffuse_capture(f, g, t));
        ++k;
    }
    const MeasureResult result = measure(request);
    ASSERT_TRUE(result.fit);
    const FitResult& fit = result.fit->exponential;
    ASSERT_FALSE(fit.parameters.empty());
    EXPECT_EQ(fit.parameters[0].name, "sigma_over_T");
    EXPECT_NEAR(fit.parameters[0].value, 0.35, std::max(3.0 * fit.parameters[0].std_error, 0.01));
    EXPECT_EQ(result.fit->preferred, Correlation::Exponential);
    EXPECT_EQ(fit.num_measurements, 4);
}

// The reported error is not inflated: with a wrong exposure time for one capture (10 % off), the
// interval must miss the truth.
TEST(MeasureEndToEnd, AWrongExposureIsOutsideTheInterval) {
    const fs::path dir = roughscope::testing::fresh_dir("measure_wrong_exposure");
    const sim::SurfaceTruth truth = very_rough(0.4, Correlation::Gaussian);
    const Geometry g1 = normal_view(30.0), g2 = normal_view(45.0);
    const double t1 = 0.4 * kFullWell / (kElectronsPerUnitS * sim::surface_brightness(truth, g1));
    const fs::path f1 = write_capture(dir, "c1", kLinear16, g1, {truth}, {}, t1, 1);
    const fs::path f2 = write_capture(dir, "c2", kLinear16, g2, {truth}, {}, t1, 2);
    MeasureRequest request = request_for(kLinear16);
    request.captures = {diffuse_capture(f1, g1, t1), diffuse_capture(f2, g2, 1.1 * t1)};
    const MeasureResult result = measure(request);
    const Estimate& s = *result.slope_gaussian->sigma_over_T;
    EXPECT_GT(std::abs(s.value - 0.4), 2.0 * s.std_error);
}

// ---------------------------------------------------------------------------------------------
// The paper's printed ratios rendered as images give back the printed σ/T (and σ, T).

nlohmann::json load_tables() {
    const auto path = roughscope::testing::paper_tables();
    if (!path) return nullptr;
    std::ifstream in(*path);
    if (!in) return nullptr;
    return nlohmann::json::parse(in);
}

// A noise-free 16-bit linear pair whose brightness ratio is `ratio` (equal exposures).
MeasureRequest pair_with_ratio(const fs::path& dir, const std::string& name, double ratio) {
    const Geometry g1 = normal_view(30.0), g2 = normal_view(45.0);
    const fs::path f1 = write_capture(dir, concat(name, "_1"), kLinear16, g1,
                                      {constant(2.0 * ratio)}, {}, 1.0, 1, false);
    const fs::path f2 =
        write_capture(dir, concat(name, "_2"), kLinear16, g2, {constant(2.0)}, {}, 1.0, 2, false);
    MeasureRequest request = request_for(kLinear16);
    request.captures = {diffuse_capture(f1, g1, 1.0), diffuse_capture(f2, g2, 1.0)};
    return request;
}

TEST(MeasurePaperTables, Table2RatiosGiveThePrintedSlopes) {
    const nlohmann::json tables = load_tables();
    ROUGHSCOPE_NEED_SHARED(!tables.is_null(), io::kPaperTablesRelative);
    const fs::path dir = roughscope::testing::fresh_dir("measure_table2");
    int rows = 0;
    for (const auto& row : tables["table2_very_rough"]["rows"]) {
        const double ratio = row["E1_over_E2"].get<double>();
        const MeasureResult result =
            measure(pair_with_ratio(dir, concat("row", std::to_string(rows++)), ratio));
        EXPECT_NEAR(result.E1_over_E2->value, ratio, 1e-4 * ratio);
        // The printed slopes come from the printed (rounded) ratio: within 1 % (test_estimation
        // bounds the rounding box).
        const double g = row["sigma_over_T_G"].get<double>();
        const double e = row["sigma_over_T_E"].get<double>();
        EXPECT_NEAR(result.slope_gaussian->sigma_over_T->value, g, 0.01 * g) << row["surface"];
        EXPECT_NEAR(result.slope_exponential->sigma_over_T->value, e, 0.01 * e) << row["surface"];
        EXPECT_NEAR(rad_to_deg(result.slope_gaussian->theta_K_rad->value),
                    row["theta_K_deg"].get<double>(), 0.6)
            << row["surface"];
    }
    EXPECT_EQ(rows, 7);
}

// Table 1: a specular capture at 14° whose highlight is R_spec brighter than its surround
// (R_spec = 1 − Ẽ_dif/Ẽ_tot, Eq. 13 with R0 = 1 at λ = 0.555 µm) gives σ; the 30°/45° pair then
// gives T and σ/T. The printed σ of two rows is the rounding of an unprinted R_spec (see
// test_estimation.cpp), hence 2.5 %.
TEST(MeasurePaperTables, Table1SpecularAndPairGiveThePrintedSigmaAndT) {
    const nlohmann::json tables = load_tables();
    ROUGHSCOPE_NEED_SHARED(!tables.is_null(), io::kPaperTablesRelative);
    const fs::path dir = roughscope::testing::fresh_dir("measure_table1");
    int rows = 0;
    for (const auto& row : tables["table1_slightly_rough"]["rows"]) {
        const std::string name = concat("row", std::to_string(rows++));
        const double r_spec = row["R_spec"].get<double>();
        const double e_tot = 2.0, e_dif = e_tot * (1.0 - r_spec);
        // Highlight: a disc of radius 6 px at (32, 30) in a uniform surround.
        std::vector<std::int32_t> labels(kSize * kSize, 0);
        for (std::size_t r = 0; r < kSize; ++r)
            for (std::size_t c = 0; c < kSize; ++c) {
                const double dx = static_cast<double>(c) + 0.5 - 32.0;
                const double dy = static_cast<double>(r) + 0.5 - 30.0;
                if (dx * dx + dy * dy <= 36.0) labels[r * kSize + c] = 1;
            }
        const Geometry gs{deg_to_rad(14.0), deg_to_rad(14.0), 0.0};
        const fs::path fs_path =
            write_capture(dir, concat(name, "_spec"), kLinear16, gs,
                          {constant(e_dif), constant(e_tot)}, labels, 1.0, 3, false);
        MeasureRequest request = pair_with_ratio(dir, name, row["E1_over_E2"].get<double>());
        CaptureSpec spec;
        spec.image = fs_path.string();
        spec.geometry = gs;
        spec.exposure_s = 1.0;
        spec.role = CaptureRole::Specular;
        request.captures.insert(request.captures.begin(), spec);
        request.R0 = 1.0;
        // The printed T are Eq. 15's (g = 3–6 here: by default the exact series).
        request.regime = Regime::SlightlyRough;
        request.highlight.core_radius_px = 4.0;
        request.highlight.annulus_inner_px = 9.0;
        request.highlight.annulus_outer_px = 14.0;
        const MeasureResult result = measure(request);
        ASSERT_TRUE(result.sigma && result.sigma->sigma_um) << row["surface"];
        const double sigma = row["sigma_um"].get<double>();
        EXPECT_NEAR(result.sigma->sigma_um->value, sigma, 0.025 * sigma) << row["surface"];
        ASSERT_TRUE(result.correlation_length && result.correlation_length->T_um);
        const double T = row["T_um"].get<double>();
        EXPECT_NEAR(result.correlation_length->T_um->value, T, 0.025 * T) << row["surface"];
        const double s_over_t = row["sigma_over_T"].get<double>();
        EXPECT_NEAR(result.correlation_length->sigma_over_T->value, s_over_t, 0.01 * s_over_t)
            << row["surface"];
        // The highlight was found where it was drawn.
        ASSERT_TRUE(result.captures[0].highlight);
        EXPECT_NEAR(result.captures[0].highlight->centre_x_px, 32.0, 1.0);
        EXPECT_NEAR(result.captures[0].highlight->centre_y_px, 30.0, 1.0);
    }
    EXPECT_EQ(rows, 3);
}

// ---------------------------------------------------------------------------------------------
// Unknown responses: a curve recovered from an exposure bracket (Debevec–Malik), and captures
// that are brackets merged into HDR images.

constexpr FileKind kGamma8{"gamma8", sim::CaptureFormat::Png, 8, Response::Gamma, 0.0};

// A bracket of a Lambertian sphere (brightness from 0 to 1 across the image) for calibration.
std::vector<BracketShot> calibration_bracket(const fs::path& dir) {
    std::vector<BracketShot> shots;
    for (const double t : {0.25, 1.0, 4.0, 16.0}) {
        sim::Scene scene;
        scene.shape = sim::SceneShape::Sphere;
        scene.width = 96;
        scene.height = 96;
        scene.background_radiance = 0.002;
        scene.light = sim::direction_from_angles(deg_to_rad(40.0), kPi);
        sim::SurfaceTruth lambert;
        lambert.model = sim::BrightnessModel::Lambert;
        sim::CameraModel camera = camera_for(kGamma8, t / kElectronsPerUnitS * kFullWell * 0.25,
                                             static_cast<std::uint64_t>(100 * t));
        camera.gamma = 2.2;
        const sim::Capture capture = sim::render_capture(scene, {lambert}, {}, camera);
        const fs::path path = dir / concat("calibration_", std::to_string(shots.size()), ".png");
        io::write_file_atomic(path, sim::encode_capture(capture, camera, kGamma8.format));
        shots.push_back(BracketShot{path.string(), t});
    }
    return shots;
}

TEST(MeasureUnknownResponse, ACurveFromABracketGivesTheBrightnessRatio) {
    const fs::path dir = roughscope::testing::fresh_dir("measure_debevec");
    const sim::SurfaceTruth truth = very_rough(0.4, Correlation::Gaussian);
    const Geometry g1 = normal_view(30.0), g2 = normal_view(45.0);
    const double b1 = sim::surface_brightness(truth, g1), b2 = sim::surface_brightness(truth, g2);
    const double t1 = 0.4 * kFullWell / (kElectronsPerUnitS * b1);
    auto gamma_capture = [&](const std::string& name, const Geometry& g, double t, int seed) {
        sim::Scene scene;
        scene.width = kSize;
        scene.height = kSize;
        scene.light = sim::direction_from_angles(g.theta_i_rad, kPi);
        sim::CameraModel camera = camera_for(kGamma8, t, static_cast<std::uint64_t>(seed));
        camera.gamma = 2.2;
        const sim::Capture capture = sim::render_capture(scene, {truth}, {}, camera);
        const fs::path path = dir / name;
        io::write_file_atomic(path, sim::encode_capture(capture, camera, kGamma8.format));
        return path;
    };
    MeasureRequest request = request_for(kGamma8);
    request.read = ReadOptions{};
    request.response_bracket = calibration_bracket(dir);
    request.captures = {diffuse_capture(gamma_capture("c1.png", g1, t1, 1), g1, t1),
                        diffuse_capture(gamma_capture("c2.png", g2, t1, 2), g2, t1)};
    const MeasureResult result = measure(request);
    // The ratio through the recovered curve: within 1 % of the truth (the curve is known to a
    // few per cent over its range, and far better between two nearby codes).
    EXPECT_NEAR(result.E1_over_E2->value / (b1 / b2), 1.0, 0.01);
    // Read as if linear (the wrong response), the ratio is far off: the curve matters.
    request.response_bracket.clear();
    request.read.response = Response::Linear;
    const MeasureResult wrong = measure(request);
    EXPECT_GT(std::abs(wrong.E1_over_E2->value / (b1 / b2) - 1.0), 0.03);
}

TEST(MeasureUnknownResponse, BracketCapturesAreMergedPerSecond) {
    const fs::path dir = roughscope::testing::fresh_dir("measure_hdr_capture");
    const sim::SurfaceTruth truth = very_rough(0.3, Correlation::Exponential);
    const Geometry g1 = normal_view(30.0), g2 = normal_view(45.0);
    const double b1 = sim::surface_brightness(truth, g1), b2 = sim::surface_brightness(truth, g2);
    const double t0 = 0.4 * kFullWell / (kElectronsPerUnitS * b1);
    auto bracket = [&](const std::string& name, const Geometry& g, int seed) {
        std::vector<BracketShot> shots;
        for (const double f : {0.5, 1.0, 2.0}) {
            const fs::path p = write_capture(dir, concat(name, "_", std::to_string(shots.size())),
                                             kSrgb8, g, {truth}, {}, f * t0,
                                             static_cast<std::uint64_t>(seed * 10) + shots.size());
            shots.push_back(BracketShot{p.string(), f * t0});
        }
        return shots;
    };
    MeasureRequest request = request_for(kSrgb8);
    CaptureSpec c1, c2;
    c1.bracket = bracket("b1", g1, 1);
    c1.image = c1.bracket.front().image;
    c1.geometry = g1;
    c2.bracket = bracket("b2", g2, 2);
    c2.image = c2.bracket.front().image;
    c2.geometry = g2;
    request.captures = {c1, c2};
    const MeasureResult result = measure(request);
    EXPECT_NEAR(result.E1_over_E2->value / (b1 / b2), 1.0, 0.005);
    EXPECT_EQ(result.captures[0].exposure_scale, 1.0);
    // The merged image is per second: Ẽ = mean/1 is the brightness per second of exposure,
    // ∝ b1 with the camera's k · gain / full-scale factor.
    const double expected = b1 * kElectronsPerUnitS * 1.05 / kFullWell;
    EXPECT_NEAR(result.captures[0].brightness / expected, 1.0, 0.02);
}

// A response declared against the file's own evidence (a RAW file declared sRGB) is never a
// silently different number: the result carries a warning naming the file.
TEST(MeasureResponseEvidence, ARawDeclaredSrgbGivesAWarning) {
    const fs::path dir = roughscope::testing::fresh_dir("measure_evidence");
    const sim::SurfaceTruth truth = very_rough(0.4, Correlation::Gaussian);
    const Geometry g1 = normal_view(30.0), g2 = normal_view(45.0);
    const fs::path f1 = write_capture(dir, "c1", kDng, g1, {truth}, {}, 1.0, 1);
    const fs::path f2 = write_capture(dir, "c2", kDng, g2, {truth}, {}, 1.0, 2);
    MeasureRequest request = request_for(kDng);
    request.read.response = Response::Srgb;
    request.captures = {diffuse_capture(f1, g1, 1.0), diffuse_capture(f2, g2, 1.0)};
    const MeasureResult result = measure(request);
    bool named = false;
    for (const auto& w : result.warnings) named = named || w.find("c1.dng") != std::string::npos;
    EXPECT_TRUE(named) << "no warning names c1.dng";
    // Declared linear (what the file says): no such warning.
    request.read.response = Response::Linear;
    const MeasureResult agreed = measure(request);
    for (const auto& w : agreed.warnings) EXPECT_EQ(w.find("srgb"), std::string::npos) << w;
}

// ---------------------------------------------------------------------------------------------
// σ per colour channel (§4.1.1 at each channel's wavelength) and their agreement.

// An RGB float TIFF of a highlight at 14°: a disc of radius 6 px at (32, 30) whose excess over
// the surround in channel c is R_spec,c = exp(−g_c), g_c = (4π σ_c cos θ / λ_c)², with 0.2 %
// Gaussian pixel noise (seeded).
fs::path rgb_highlight(const fs::path& dir, const std::string& name,
                       const std::array<double, 3>& sigma_um) {
    const double cos_theta = std::cos(deg_to_rad(14.0));
    std::mt19937_64 rng(42);
    std::normal_distribution<double> noise(0.0, 0.002);
    std::vector<float> pixels(kSize * kSize * 3);
    for (std::size_t r = 0; r < kSize; ++r)
        for (std::size_t x = 0; x < kSize; ++x) {
            const double dx = static_cast<double>(x) + 0.5 - 32.0;
            const double dy = static_cast<double>(r) + 0.5 - 30.0;
            const bool in = dx * dx + dy * dy <= 36.0;
            for (std::size_t c = 0; c < 3; ++c) {
                const double k =
                    4.0 * kPi * sigma_um[c] * cos_theta / kDefaultChannelWavelengthsUm[c];
                const double e_tot = 0.5, e_dif = e_tot * (1.0 - std::exp(-k * k));
                pixels[(r * kSize + x) * 3 + c] =
                    static_cast<float>((in ? e_tot : e_dif) * (1.0 + noise(rng)));
            }
        }
    const auto bytes = roughscope::testing::tiff_image(kSize, kSize, 3, 32, 3,
                                                       roughscope::testing::raw_bytes(pixels));
    const fs::path path = dir / name;
    io::write_file_atomic(path, std::string(bytes.begin(), bytes.end()));
    return path;
}

MeasureResult measure_rgb_highlight(const fs::path& image) {
    MeasureRequest request;
    request.read.response = Response::Linear;
    request.roi = RectangleRegion{4.0, 4.0, 56.0, 56.0};
    request.R0 = 1.0;
    request.highlight.core_radius_px = 4.0;
    request.highlight.annulus_inner_px = 9.0;
    request.highlight.annulus_outer_px = 14.0;
    CaptureSpec spec;
    spec.image = image.string();
    spec.geometry = Geometry{deg_to_rad(14.0), deg_to_rad(14.0), 0.0};
    spec.role = CaptureRole::Specular;
    request.captures = {spec};
    return measure(request);
}

TEST(MeasureChannels, OneSigmaSeenThroughThreeWavelengthsAgrees) {
    const fs::path dir = roughscope::testing::fresh_dir("measure_channels");
    const MeasureResult result =
        measure_rgb_highlight(rgb_highlight(dir, "same.tiff", {0.08, 0.08, 0.08}));
    ASSERT_EQ(result.specular_sigma.size(), 4u);  // R, G, B, average
    for (std::size_t c = 0; c < 3; ++c) {
        const Estimate& s = *result.specular_sigma[c].estimate.sigma_um;
        EXPECT_NEAR(s.value, 0.08, 3.0 * s.std_error) << result.specular_sigma[c].channel;
        EXPECT_GT(s.std_error, 0.0);
    }
    ASSERT_TRUE(result.channel_sigma_chi2);
    EXPECT_LE(*result.channel_sigma_chi2, 9.21);
    for (const auto& w : result.warnings) EXPECT_EQ(w.find("channels"), std::string::npos) << w;
}

TEST(MeasureChannels, ChannelsThatDisagreeAreFlagged) {
    const fs::path dir = roughscope::testing::fresh_dir("measure_channels_bad");
    // σ not following λ (a response or colour error): channel σ of 0.06, 0.08, 0.10 µm.
    const MeasureResult result =
        measure_rgb_highlight(rgb_highlight(dir, "differ.tiff", {0.06, 0.08, 0.10}));
    ASSERT_TRUE(result.channel_sigma_chi2);
    EXPECT_GT(*result.channel_sigma_chi2, 9.21);
    bool flagged = false;
    for (const auto& w : result.warnings)
        flagged = flagged || w.find("differs between the R, G and B") != std::string::npos;
    EXPECT_TRUE(flagged);
}

// A 16-bit TIFF capture two pixels wider than the others (other.tiff in dir).
fs::path write_wider_capture(const fs::path& dir) {
    sim::Scene scene;
    scene.width = kSize + 2;
    scene.height = kSize;
    sim::CameraModel camera = camera_for(kLinear16, 1.0, 1);
    const sim::Capture capture = sim::render_capture(scene, {constant(1.0)}, {}, camera);
    const fs::path other = dir / "other.tiff";
    io::write_file_atomic(other, sim::encode_capture(capture, camera, sim::CaptureFormat::Tiff));
    return other;
}

// ---------------------------------------------------------------------------------------------
// Failures: each a named error.

TEST(MeasureFailures, CapturesOfDifferentSizesAreADataError) {
    const fs::path dir = roughscope::testing::fresh_dir("measure_sizes");
    MeasureRequest request = pair_with_ratio(dir, "a", 1.05);
    const fs::path other = write_wider_capture(dir);
    request.captures[1].image = other.string();
    try {
        (void)measure(request);
        FAIL() << "no error";
    } catch (const DataError& e) {
        EXPECT_NE(std::string(e.what()).find("same size"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("other.tiff"), std::string::npos) << e.what();
    }
}

// ---------------------------------------------------------------------------------------------
// Captures measured in parallel: the same result and the same error as one at a time.

TEST(MeasureThreads, OneAndSeveralThreadsGiveTheSameResult) {
    const fs::path dir = roughscope::testing::fresh_dir("measure_threads");
    const Geometry g1 = normal_view(20.0), g2 = normal_view(35.0), g3 = normal_view(50.0);
    MeasureRequest request = request_for(kLinear16);
    request.captures = {
        diffuse_capture(write_capture(dir, "c1", kLinear16, g1,
                                      {very_rough(0.3, Correlation::Gaussian)}, {}, 1.0, 1),
                        g1, 1.0),
        diffuse_capture(write_capture(dir, "c2", kLinear16, g2,
                                      {very_rough(0.3, Correlation::Gaussian)}, {}, 1.0, 2),
                        g2, 1.0),
        diffuse_capture(write_capture(dir, "c3", kLinear16, g3,
                                      {very_rough(0.3, Correlation::Gaussian)}, {}, 1.0, 3),
                        g3, 1.0)};
    request.threads = 1;
    const std::string one = serialize::to_json(measure(request), request).dump();
    for (const std::size_t threads : {2U, 3U, 8U}) {
        request.threads = threads;
        EXPECT_EQ(serialize::to_json(measure(request), request).dump(), one) << threads;
    }
}

TEST(MeasureThreads, TheFirstFailingCaptureGivesTheError) {
    const fs::path dir = roughscope::testing::fresh_dir("measure_threads_errors");
    MeasureRequest request = pair_with_ratio(dir, "a", 1.05);
    // Capture 1 missing, capture 2 of another size: capture 1's error whatever the threads.
    const fs::path other = write_wider_capture(dir);
    CaptureSpec third = request.captures[1];
    third.image = other.string();
    request.captures[1].image = (dir / "nope.tiff").string();
    request.captures.push_back(third);
    const auto expect_error_naming = [&](const std::string& needle) {
        for (const std::size_t threads : {1U, 2U, 3U}) {
            request.threads = threads;
            try {
                (void)measure(request);
                ADD_FAILURE() << "no error with " << threads << " threads";
            } catch (const DataError& e) {
                EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
            }
        }
    };
    expect_error_naming("nope.tiff");
    // Capture 0 missing: its own error (not the others' wait for its size).
    request.captures[0].image = (dir / "first_missing.tiff").string();
    expect_error_naming("first_missing");
}

TEST(MeasureFailures, AMissingImageIsADataErrorNamingIt) {
    const fs::path dir = roughscope::testing::fresh_dir("measure_missing");
    MeasureRequest request = pair_with_ratio(dir, "a", 1.05);
    request.captures[1].image = (dir / "nope.png").string();
    EXPECT_THROW((void)measure(request), DataError);
}

TEST(MeasureFailures, ARegionOutsideTheImageIsInvalid) {
    const fs::path dir = roughscope::testing::fresh_dir("measure_outside");
    MeasureRequest request = pair_with_ratio(dir, "a", 1.05);
    request.roi = RectangleRegion{40.0, 40.0, 48.0, 48.0};
    EXPECT_THROW((void)measure(request), InvalidArgument);
}

TEST(MeasureFailures, AMostlySaturatedRegionIsInvalid) {
    const fs::path dir = roughscope::testing::fresh_dir("measure_saturated");
    const Geometry g1 = normal_view(30.0), g2 = normal_view(45.0);
    const fs::path f1 = write_capture(dir, "c1", kLinear16, g1, {constant(1e3)}, {}, 1.0, 1);
    const fs::path f2 = write_capture(dir, "c2", kLinear16, g2, {constant(0.5)}, {}, 1.0, 2);
    MeasureRequest request = request_for(kLinear16);
    request.captures = {diffuse_capture(f1, g1, 1.0), diffuse_capture(f2, g2, 1.0)};
    try {
        (void)measure(request);
        FAIL() << "no error";
    } catch (const InvalidArgument& e) {
        EXPECT_NE(std::string(e.what()).find("saturated"), std::string::npos) << e.what();
    }
}

TEST(MeasureFailures, OneDiffuseCaptureGivesNoEstimate) {
    const fs::path dir = roughscope::testing::fresh_dir("measure_one");
    MeasureRequest request = pair_with_ratio(dir, "a", 1.05);
    request.captures.pop_back();
    EXPECT_THROW((void)measure(request), InvalidArgument);
}

TEST(MeasureFailures, ARatioNoModelProducesIsNoSolution) {
    const fs::path dir = roughscope::testing::fresh_dir("measure_nosolution");
    // E1/E2 < 1 with the light at 30° and 45°: the very-rough forms never give it.
    EXPECT_THROW((void)measure(pair_with_ratio(dir, "a", 0.8)), NoSolution);
}

// ---------------------------------------------------------------------------------------------
// The capture file.

TEST(CaptureFile, EveryDocumentedKeyIsRead) {
    const MeasureRequest r = parse_capture_file(R"({
        "format": "roughscope-measure",
        "wavelength_um": 0.55,
        "channel_wavelengths_um": [0.61, 0.54, 0.47],
        "response": {"gamma": 2.0},
        "black_level_dn": 16,
        "dark_frame": "dark.png",
        "roi": {"circle": [30, 31, 12]},
        "correlation": "exponential",
        "sigma_um": 0.1, "sigma_um_stderr": 0.01,
        "captures": [
            {"image": "a.png", "theta_i_deg": 30, "theta_s_deg": 0, "phi_s_deg": 0,
             "exposure_s": 0.01, "role": "diffuse"},
            {"image": "sub/b.png", "light": [0, 0, 1], "view": [0.5, 0, 0.8660254037844386]},
            {"image": "s.png", "theta_i_deg": 14, "theta_s_deg": 14, "role": "specular"}
        ]})",
                                                "dir/capture.json");
    EXPECT_DOUBLE_EQ(r.wavelength_um, 0.55);
    EXPECT_DOUBLE_EQ(r.channel_wavelengths_um[2], 0.47);
    EXPECT_EQ(r.read.response, Response::Gamma);
    EXPECT_DOUBLE_EQ(r.read.gamma, 2.0);
    ASSERT_TRUE(r.read.black_level_dn);
    EXPECT_DOUBLE_EQ(r.read.black_level_dn->at(0), 16.0);
    ASSERT_TRUE(r.dark_frame);
    EXPECT_EQ(fs::path(*r.dark_frame), fs::path("dir/dark.png"));
    ASSERT_TRUE(r.roi && std::holds_alternative<CircleRegion>(*r.roi));
    EXPECT_DOUBLE_EQ(std::get<CircleRegion>(*r.roi).radius_px, 12.0);
    EXPECT_EQ(r.correlation, Correlation::Exponential);
    ASSERT_EQ(r.captures.size(), 3u);
    EXPECT_EQ(fs::path(r.captures[1].image), fs::path("dir/sub/b.png"));
    EXPECT_NEAR(r.captures[0].geometry.theta_i_rad, deg_to_rad(30.0), 1e-15);
    // light on the normal, view at 30° in the XZ plane: θi = 0, θs = 30°.
    EXPECT_NEAR(r.captures[1].geometry.theta_i_rad, 0.0, 1e-12);
    EXPECT_NEAR(r.captures[1].geometry.theta_s_rad, deg_to_rad(30.0), 1e-9);
    EXPECT_EQ(r.captures[2].role, CaptureRole::Specular);
    EXPECT_FALSE(r.captures[2].exposure_s);
}

void expect_capture_file_error(const std::string& text, const std::string& fragment) {
    try {
        (void)parse_capture_file(text, "c.json");
        FAIL() << "no error for " << text;
    } catch (const DataError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("c.json"), std::string::npos) << what;
        EXPECT_NE(what.find(fragment), std::string::npos) << what;
    }
}

TEST(CaptureFile, BadDocumentsNameTheKey) {
    const std::string captures =
        R"("captures": [{"image": "a.png", "theta_i_deg": 30}, {"image": "b.png", "theta_i_deg": 45}])";
    expect_capture_file_error("{", "not valid JSON");
    expect_capture_file_error(R"({"wavelength_um": 1e999999})", "not valid JSON");  // overflow
    expect_capture_file_error(
        concat(R"({"roi": {"rect": [0, 0, 4, 4]}, "colour": 1, )", captures, "}"), "colour");
    expect_capture_file_error(concat("{", captures, "}"), "roi");
    expect_capture_file_error(R"({"roi": {"rect": [0, 0, 4, 4]}, "captures": []})", "captures");
    expect_capture_file_error(concat(R"({"roi": {"rect": [0, 0, 4]}, )", captures, "}"),
                              "roi.rect");
    expect_capture_file_error(
        concat(R"({"roi": {"rect": [0, 0, 4, 4]}, "response": "film", )", captures, "}"),
        "response");
    expect_capture_file_error(
        concat(R"({"roi": {"rect": [0, 0, 4, 4]}, "response": {"gamma": 50}, )", captures, "}"),
        "response.gamma");
    expect_capture_file_error(
        R"({"roi": {"rect": [0, 0, 4, 4]}, "captures": [{"image": "a.png", "theta_i_deg": 95}]})",
        "theta_i_deg");
    expect_capture_file_error(
        R"({"roi": {"rect": [0, 0, 4, 4]}, "captures": [{"image": "a.png", "light": [0, 0, -1], "view": [0, 0, 1]}]})",
        "below");
    expect_capture_file_error(
        R"({"roi": {"rect": [0, 0, 4, 4]}, "captures": [{"image": "a.png", "theta_i_deg": 30, "role": "glint"}]})",
        "role");
    expect_capture_file_error(
        R"({"roi": {"rect": [0, 0, 4, 4]}, "captures": [{"image": "a.png", "theta_i_deg": 30, "exposure_s": -1}]})",
        "exposure_s");
}

TEST(CaptureFile, AMissingFileIsADataError) {
    EXPECT_THROW((void)read_capture_file("/nonexistent/capture.json"), DataError);
    const fs::path dir = roughscope::testing::fresh_dir("capture_file_dir");
    EXPECT_THROW((void)read_capture_file(dir.string()), DataError);
}

}  // namespace
}  // namespace roughscope::image
