// Maps of an object with a normal map through measure() (image/measure.hpp, docs/maps.md), on
// synthetic captures of known roughness (simulation/capture.hpp) written as files and read back:
// every finite normal is used, and a curved object's change of shading between its two lights
// is not refused as a movement of the camera.
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
#include "../photo/image_files.hpp"
#include "map_captures.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/io/output_file.hpp"
#include "roughscope/measure/measure.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/simulation/capture.hpp"

namespace roughscope::image {
namespace {

namespace fs = std::filesystem;
namespace sim = roughscope::simulation;
using roughscope::testing::light_at;
using roughscope::testing::render_pair;
using roughscope::testing::Rendered;
using roughscope::testing::very_rough_truth;

std::string vec(const Eigen::Vector3d& v) {
    return concat("[", check::format_number(v.x()), ", ", check::format_number(v.y()), ", ",
                  check::format_number(v.z()), "]");
}

// A capture file for a map of the pair with the normals in `normal_file`.
MeasureRequest normal_map_request(const fs::path& normal_file, const Rendered& a,
                                  const Eigen::Vector3d& la, const Rendered& b,
                                  const Eigen::Vector3d& lb, std::size_t window,
                                  const std::string& region) {
    return parse_capture_file(
        concat(R"({"object": {"shape": "normal_map", "file": ")", normal_file.string(),
               R"("}, "maps": {"window_px": )", std::to_string(window), R"(, "regions": [{"name":
               "r", )",
               region, R"(}]}, "captures": [{"image": ")", a.file.string(), R"(", "light": )",
               vec(la), R"(, "exposure_s": 1}, {"image": ")", b.file.string(), R"(", "light": )",
               vec(lb), R"(, "exposure_s": 1}]})"),
        (normal_file.parent_path() / "c.json").string());
}

// ---------------------------------------------------------------------------------------------
// Normal maps

// A flat sample seen through a normal map of (0, 0, 1) everywhere — as a float TIFF (n_x = n_y
// = 0 is at the reader's black level, n_z = 1 at its white level) and as a 16-bit PNG
// (32768, 32768, 65535: n_z at the white code) — is a flat sample: every pixel has its σ/T, and the
// region's σ/T is the truth.
TEST(MeasureNormalMap, AFlatNormalMapUsesEveryPixel) {
    const fs::path dir = roughscope::testing::fresh_dir("measure_numbers_flat_normals");
    constexpr double kTruth = 0.5;
    constexpr std::size_t kSide = 32;
    sim::Scene scene;
    scene.width = scene.height = kSide;
    const auto [a, b] = render_pair(dir, scene, light_at(30.0), light_at(45.0),
                                    very_rough_truth(kTruth), very_rough_truth(kTruth), 11);
    const std::size_t n = kSide * kSide;
    std::vector<float> up(3 * n, 0.0f);
    std::vector<std::uint16_t> codes(3 * n, 32768);
    for (std::size_t k = 0; k < n; ++k) {
        up[3 * k + 2] = 1.0f;
        codes[3 * k + 2] = 65535;
    }
    const fs::path tiff = dir / "normals.tiff";
    const auto tiff_bytes =
        roughscope::testing::tiff_image(kSide, kSide, 3, 32, 3, roughscope::testing::raw_bytes(up));
    io::write_file_atomic(tiff, std::string(tiff_bytes.begin(), tiff_bytes.end()));
    roughscope::testing::PngSpec png;
    png.width = png.height = kSide;
    png.color_type = PNG_COLOR_TYPE_RGB;
    png.depth = 16;
    png.samples = codes;
    const fs::path png_file = dir / "normals.png";
    const auto png_bytes = roughscope::testing::png_bytes(png);
    io::write_file_atomic(png_file, std::string(png_bytes.begin(), png_bytes.end()));
    for (const fs::path& normals : {tiff, png_file}) {
        // Per pixel: every pixel has its σ/T.
        const MeasureResult pixels = measure(normal_map_request(
            normals, a, light_at(30.0), b, light_at(45.0), 1, R"("rect": [0, 0, 32, 32])"));
        ASSERT_TRUE(pixels.map);
        EXPECT_EQ(pixels.map->valid, n) << normals.filename();
        EXPECT_EQ(pixels.map->missing, 0u) << normals.filename();
        // Tiles of 4 px (the mean of the cells' σ/T is unbiased there): the truth.
        const MeasureResult tiles = measure(normal_map_request(
            normals, a, light_at(30.0), b, light_at(45.0), 4, R"("rect": [0, 0, 32, 32])"));
        ASSERT_TRUE(tiles.map);
        EXPECT_EQ(tiles.map->valid, n / 16) << normals.filename();
        ASSERT_EQ(tiles.map->regions.size(), 1u);
        const auto& e = tiles.map->regions[0].mean_sigma_over_T_gaussian;
        ASSERT_TRUE(e) << normals.filename();
        std::printf("flat, normals %s: σ/T %.5f ± %.5f (truth %g)\n", normals.filename().c_str(),
                    e->value, e->std_error, kTruth);
        EXPECT_LE(std::abs(e->value - kTruth), 4.0 * e->std_error + 0.005 * kTruth)
            << e->value << " ± " << e->std_error;
    }
    fs::remove_all(dir);
}

// A sphere (128 px, no texture) photographed from one camera position under lights at 20° and
// 60°, its normals as a float TIFF (camera frame; NaN off the sphere): its shading moves with
// the light, which phase correlation reads as a shift of a few pixels with a peak-to-sidelobe
// ratio above the threshold (until now refused as a movement of the camera), so the pair is not
// refused; every tile whose pixels have a normal lit by both lights has its σ/T, and the
// centre's σ/T is the truth.
TEST(MeasureNormalMap, ASphereUnderTwoLightsUsesEveryNormalAndIsNotRefused) {
    const fs::path dir = roughscope::testing::fresh_dir("measure_numbers_sphere");
    constexpr double kTruth = 0.5;
    constexpr std::size_t kSide = 128, kWindow = 4;
    sim::Scene scene;
    scene.shape = sim::SceneShape::Sphere;
    scene.width = scene.height = kSide;
    const Eigen::Vector3d l1 = light_at(20.0), l2 = light_at(60.0);
    const auto [a, b] =
        render_pair(dir, scene, l1, l2, very_rough_truth(kTruth), very_rough_truth(kTruth), 21);
    const std::size_t n = kSide * kSide;
    std::vector<float> normals(3 * n, std::numeric_limits<float>::quiet_NaN());
    // Tiles whose pixels (at least half) have a normal lit by both lights and seen by the camera
    // and are not flagged in either capture.
    std::vector<std::size_t> lit(n / (kWindow * kWindow), 0);
    for (std::size_t k = 0; k < n; ++k) {
        const float* nk = a.capture.normal.data() + 3 * k;
        if (!std::isfinite(nk[0])) continue;
        for (std::size_t c = 0; c < 3; ++c) normals[3 * k + c] = nk[c];
        const Eigen::Vector3d v(nk[0], nk[1], nk[2]);
        const bool used = v.dot(l1) > 1e-12 && v.dot(l2) > 1e-12 && v.z() > 1e-12 &&
                          a.capture.dn[k] > 0 && b.capture.dn[k] > 0 && !a.capture.saturated[k] &&
                          !b.capture.saturated[k];
        if (used) ++lit[(k / kSide / kWindow) * (kSide / kWindow) + (k % kSide) / kWindow];
    }
    std::size_t expected = 0;
    for (const std::size_t count : lit)
        if (2 * count >= kWindow * kWindow) ++expected;
    const fs::path tiff = dir / "normals.tiff";
    const auto bytes = roughscope::testing::tiff_image(kSide, kSide, 3, 32, 3,
                                                       roughscope::testing::raw_bytes(normals));
    io::write_file_atomic(tiff, std::string(bytes.begin(), bytes.end()));
    const MeasureResult result =
        measure(normal_map_request(tiff, a, l1, b, l2, kWindow, R"("circle": [64, 64, 30])"));
    ASSERT_TRUE(result.map);
    const RoughnessMap& map = *result.map;
    ASSERT_TRUE(map.registration);
    std::printf(
        "sphere: registration (%.2f, %.2f) px, PSR %.1f; %zu tiles with σ/T, %zu expected\n",
        map.registration->shift_x_px, map.registration->shift_y_px,
        map.registration->peak_to_sidelobe, map.valid, expected);
    // The case in point: the change of shading reads as a shift above max_shift_px (1 px) with
    // a peak-to-sidelobe ratio above min_peak_to_sidelobe (8).
    EXPECT_GT(map.registration->magnitude_px, 1.0);
    EXPECT_GT(map.registration->peak_to_sidelobe, 8.0);
    bool said = false;
    for (const auto& w : result.warnings) said |= w.find("shading moves with the light") != w.npos;
    EXPECT_TRUE(said);
    EXPECT_GE(static_cast<double>(map.valid), 0.97 * static_cast<double>(expected));
    EXPECT_LE(map.valid, expected + kSide / kWindow);
    ASSERT_EQ(map.regions.size(), 1u);
    const auto& e = map.regions[0].mean_sigma_over_T_gaussian;
    ASSERT_TRUE(e);
    EXPECT_LE(std::abs(e->value - kTruth), 4.0 * e->std_error + 0.02 * kTruth)
        << e->value << " ± " << e->std_error;
    fs::remove_all(dir);
}

}  // namespace
}  // namespace roughscope::image
