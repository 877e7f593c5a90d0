// A lamp and a camera at a finite distance (docs/measure.md "A lamp and a camera at a finite
// distance"): a flat very-rough sample, a region 50 mm wide, a point lamp 500 mm (ten region
// widths) from the region's centre at 30° and 45°. Every pixel is rendered here at its own
// geometry: its plane point X (the mapping written out below), L = (P − X)/|P − X| and
// V = (C − X)/|C − X| (or +z for a camera at infinity), the library's forward very-rough
// brightness (very_rough_brightness: Eq. 4 / Eq. 5 with the Vernold–Harvey factor, radiance) at
// that geometry, times the point lamp's 1/|P − X|². The images are 32-bit float TIFFs.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../io/test_files.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/io/output_file.hpp"
#include "roughscope/measure/measure.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/simulation/capture.hpp"

namespace roughscope::image {
namespace {

namespace fs = std::filesystem;
namespace sim = roughscope::simulation;
using nlohmann::json;

constexpr std::size_t kSize = 80;              // pixels
constexpr double kPixelMm = 50.0 / 64.0;       // the 64-pixel region is 50 mm wide
constexpr double kTrueSlope = 0.3;             // σ/T
constexpr double kLampMm = 500.0;              // ten region widths
const json kRoi = {{"rect", {8, 8, 64, 64}}};  // centred: its centroid is X = 0

Eigen::Vector3d light_toward(double theta_deg) {  // the paper's light azimuth, φi = π
    const double t = deg_to_rad(theta_deg);
    return {-std::sin(t), 0.0, std::cos(t)};
}

// The centre of pixel (column, row) on the sample's plane: origin at the image centre, image y
// down, plane y up.
Eigen::Vector3d plane_point(std::size_t column, std::size_t row) {
    const double half = static_cast<double>(kSize) / 2;
    return {(static_cast<double>(column) + 0.5 - half) * kPixelMm,
            -(static_cast<double>(row) + 0.5 - half) * kPixelMm, 0.0};
}

struct Render {
    Correlation correlation = Correlation::Gaussian;
    double lamp_mm = kLampMm;
    std::optional<double> camera_mm;  // on the normal above the region's centre; else infinity
};

// Brightness (before the common scale) of every pixel for a lamp at theta_deg.
std::vector<double> brightness(const Render& r, double theta_deg) {
    const Eigen::Vector3d P = r.lamp_mm * light_toward(theta_deg);
    std::vector<double> out;
    for (std::size_t row = 0; row < kSize; ++row)
        for (std::size_t column = 0; column < kSize; ++column) {
            const Eigen::Vector3d X = plane_point(column, row);
            const Eigen::Vector3d L = (P - X).normalized();
            const Eigen::Vector3d V = r.camera_mm
                                          ? (Eigen::Vector3d(0, 0, *r.camera_mm) - X).normalized()
                                          : Eigen::Vector3d::UnitZ();
            const Geometry g = *geometry_from_vectors(Eigen::Vector3d::UnitZ(), L, V);
            out.push_back(very_rough_brightness(g, kTrueSlope, r.correlation) /
                          (P - X).squaredNorm());
        }
    return out;
}

// Writes the 30° and 45° captures (one lamp, one exposure: one scale for both) into `dir`.
void write_pair(const fs::path& dir, const Render& r) {
    const std::vector<double> b1 = brightness(r, 30.0), b2 = brightness(r, 45.0);
    double peak = 0.0;
    for (const auto* b : {&b1, &b2})
        for (const double v : *b) peak = std::max(peak, v);
    const double scale = 0.8 / peak;  // a float TIFF holds 1 at full scale
    for (const auto& [name, b] : {std::pair{"c30", &b1}, std::pair{"c45", &b2}}) {
        sim::Capture c;
        c.width = c.height = kSize;
        c.bit_depth = 16;
        c.dn.assign(kSize * kSize, 0);
        for (const double v : *b) c.expected_dn.push_back(static_cast<float>(v * scale));
        io::write_file_atomic(dir / concat(name, ".tiff"), sim::encode_capture_tiff_float(c));
    }
}

json position(const Eigen::Vector3d& p) { return {{"position_mm", {p.x(), p.y(), p.z()}}}; }

// The capture file: the light as a position (positions = true) or as the nominal direction from
// the region's centre; the view likewise.
json capture_file(const Render& r, bool positions) {
    json doc = {{"format", "roughscope-measure"},
                {"response", "linear"},
                {"black_level_dn", 0},
                {"exposures_equal", true},
                {"roi", kRoi},
                {"sample_plane", {{"pixel_size_mm", kPixelMm}}}};
    for (const double theta : {30.0, 45.0}) {
        const Eigen::Vector3d L = light_toward(theta);
        json c = {{"image", concat(theta == 30.0 ? "c30" : "c45", ".tiff")}};
        c["light"] = positions ? position(r.lamp_mm * L) : json{L.x(), L.y(), L.z()};
        c["view"] =
            positions && r.camera_mm ? position({0.0, 0.0, *r.camera_mm}) : json{0.0, 0.0, 1.0};
        doc["captures"].push_back(c);
    }
    return doc;
}

MeasureResult measure_file(const fs::path& dir, const json& doc) {
    const fs::path file = dir / "capture.json";
    io::write_file_atomic(file, doc.dump());
    return measure(read_capture_file(file.string()));
}

double slope(const MeasureResult& r, Correlation c) {
    const auto& e = c == Correlation::Gaussian ? r.slope_gaussian : r.slope_exponential;
    return e.value().sigma_over_T.value().value;
}

struct Case {
    const char* name;
    Correlation correlation;
    std::optional<double> camera_mm;
    double nominal_bias;  // σ/T measured with the nominal angles, relative (as measured)
};

class FiniteDistance : public ::testing::TestWithParam<Case> {};

// (a) the nominal angles are biased by several per cent; (b) the positions remove it; (d) both
// correlations; a camera at infinity and at 400 mm.
TEST_P(FiniteDistance, PositionsRemoveTheBiasOfTheNominalAngles) {
    const Case& k = GetParam();
    const fs::path dir = testing::fresh_dir(concat("finite_distance_", k.name));
    const Render r{k.correlation, kLampMm, k.camera_mm};
    write_pair(dir, r);
    const MeasureResult nominal = measure_file(dir, capture_file(r, false));
    const MeasureResult located = measure_file(dir, capture_file(r, true));
    const double bias = slope(nominal, k.correlation) / kTrueSlope - 1.0;
    const double error = slope(located, k.correlation) / kTrueSlope - 1.0;
    std::printf("%s: nominal angles %+.4f %%, positions %+.2e\n", k.name, 100 * bias, error);
    // Both lamps are 500 mm from the region's centre: the inverse square and the angles vary
    // across the region, to first order symmetrically about the centroid, so the nominal bias is
    // the second-order part, a few tenths of a per cent to about one per cent.
    EXPECT_NEAR(bias, k.nominal_bias, 0.1 * std::abs(k.nominal_bias)) << k.name;
    EXPECT_GT(std::abs(bias), 100 * std::abs(error)) << k.name;
    EXPECT_LT(std::abs(error), 1e-6) << k.name;
    // The nominal geometry is the centroid's, and the result says how far the lamp was.
    const CaptureMeasurement& c1 = located.captures[0];
    ASSERT_TRUE(c1.finite_distance);
    EXPECT_NEAR(rad_to_deg(c1.spec.geometry.theta_i_rad), 30.0, 1e-9);
    EXPECT_NEAR(*c1.finite_distance->lamp_distance_mm, kLampMm, 1e-9);
    EXPECT_LT(c1.finite_distance->theta_i_min_deg, 28.0);
    EXPECT_GT(c1.finite_distance->theta_i_max_deg, 32.0);
    EXPECT_TRUE(k.correlation == Correlation::Gaussian
                    ? c1.finite_distance->correction_gaussian
                    : c1.finite_distance->correction_exponential);
    // The budget holds the correction fixed: its σ/T is the corrected one.
    ASSERT_TRUE(located.uncertainty);
}

INSTANTIATE_TEST_SUITE_P(
    Measure, FiniteDistance,
    ::testing::Values(Case{"gaussian_orthographic", Correlation::Gaussian, std::nullopt, 0.00365},
                      Case{"exponential_orthographic", Correlation::Exponential, std::nullopt,
                           0.00347},
                      Case{"gaussian_camera_400mm", Correlation::Gaussian, 400.0, 0.00656},
                      Case{"exponential_camera_400mm", Correlation::Exponential, 400.0, 0.0127}),
    [](const auto& p) { return std::string(p.param.name); });

// (c) A lamp ten thousand kilometres away is a collimated light.
TEST(FiniteDistanceLimit, AFarLampGivesTheDirectionResult) {
    const fs::path dir = testing::fresh_dir("finite_distance_far");
    const Render r{Correlation::Gaussian, 1e7, std::nullopt};
    write_pair(dir, r);
    const MeasureResult nominal = measure_file(dir, capture_file(r, false));
    const MeasureResult located = measure_file(dir, capture_file(r, true));
    for (const Correlation c : {Correlation::Gaussian, Correlation::Exponential})
        EXPECT_NEAR(slope(located, c) / slope(nominal, c), 1.0, 1e-6);
    EXPECT_NEAR(slope(located, Correlation::Gaussian), kTrueSlope, 1e-5);
}

// (e) T given σ with positions (σ known; the very-rough regime the images are rendered with).
TEST(FiniteDistanceLimit, TGivenSigmaWithPositions) {
    const fs::path dir = testing::fresh_dir("finite_distance_T");
    const Render r{Correlation::Gaussian, kLampMm, std::nullopt};
    write_pair(dir, r);
    const double sigma_um = 3.0;  // T = σ/(σ/T) = 10 µm
    for (const bool positions : {false, true}) {
        json doc = capture_file(r, positions);
        doc["sigma_um"] = sigma_um;
        doc["regime"] = "very_rough";
        const MeasureResult result = measure_file(dir, doc);
        const double T = result.correlation_length.value().T_um.value().value;
        const double error = T / (sigma_um / kTrueSlope) - 1.0;
        std::printf("T given sigma, %s: %+.4f %%\n", positions ? "positions" : "nominal",
                    100 * error);
        if (positions) {
            EXPECT_LT(std::abs(error), 1e-6);
            EXPECT_TRUE(result.captures[1].finite_distance->correction_T);
        } else {
            EXPECT_NEAR(error, -0.00364, 0.0004);  // as measured
        }
    }
}

// (f) Bad keys are data errors naming the key.
void expect_error(const json& doc, const std::string& key, const std::string& words) {
    const fs::path dir = testing::fresh_dir("finite_distance_errors");
    write_pair(dir, Render{});
    try {
        (void)measure_file(dir, doc);
        ADD_FAILURE() << "no error for " << key;
    } catch (const DataError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find(key), std::string::npos) << what;
        EXPECT_NE(what.find(words), std::string::npos) << what;
    }
}

TEST(FiniteDistanceErrors, BadKeysNameTheKey) {
    const Render r;
    json below = capture_file(r, true);
    below["captures"][0]["light"]["position_mm"][2] = 0.0;
    expect_error(below, "captures[0].light.position_mm", "must be > 0");
    json no_plane = capture_file(r, true);
    no_plane.erase("sample_plane");
    expect_error(no_plane, "captures[0].light.position_mm", "sample_plane");
    json bad_size = capture_file(r, true);
    bad_size["sample_plane"]["pixel_size_mm"] = -1.0;
    expect_error(bad_size, "sample_plane.pixel_size_mm", "must be in");
    json mixed = capture_file(r, true);
    mixed["captures"][1]["light"] = json{0.0, 0.0, 1.0};
    expect_error(mixed, "captures[1].light", "every diffuse capture");
    json sphere = capture_file(r, true);
    sphere["captures"][0]["light"]["mirror_sphere"] = json::object();
    expect_error(sphere, "captures[0].light", "not both");
}

}  // namespace
}  // namespace roughscope::image
