// The capture sidecar (serialize/capture.hpp): the truth, geometry and camera read back from the
// written JSON equal the inputs; nothing is written when the image cannot be encoded.
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../io/test_files.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/serialize/capture.hpp"

namespace roughscope::serialize {
namespace {

namespace fs = std::filesystem;

CaptureRecord two_region_sphere() {
    CaptureRecord r;
    r.scene.shape = simulation::SceneShape::Sphere;
    r.scene.width = 40;
    r.scene.height = 30;
    r.scene.light = simulation::direction_from_angles(deg_to_rad(30.0), kPi);
    r.scene.view = simulation::direction_from_angles(deg_to_rad(10.0), 0.0);
    simulation::SurfaceTruth a, b;
    a.sigma_um = 0.5;
    a.T_um = 2.0;
    b.sigma_um = 1.5;
    b.T_um = 2.0;
    b.correlation = Correlation::Exponential;
    r.truths = {a, b};
    r.labels.resize(40 * 30);
    for (std::size_t i = 0; i < r.labels.size(); ++i) r.labels[i] = (i % 40) < 20 ? 0 : 1;
    r.camera.seed = 99;
    r.camera.bit_depth = 12;
    return r;
}

TEST(CaptureSidecar, WrittenJsonHoldsTheTruthGeometryAndCamera) {
    const CaptureRecord r = two_region_sphere();
    const auto c = simulation::render_capture(r.scene, r.truths, r.labels, r.camera);
    const fs::path dir = roughscope::testing::fresh_dir("capture_sidecar");
    const CaptureFiles files = write_capture_files(c, r, simulation::CaptureFormat::Png, dir);
    EXPECT_EQ(files.image, dir / "capture.png");
    ASSERT_TRUE(fs::exists(files.image));
    const auto doc = nlohmann::json::parse(roughscope::testing::slurp(files.sidecar));
    EXPECT_EQ(doc["files"]["image"], "capture.png");
    EXPECT_EQ(doc["scene"]["shape"], "sphere");
    EXPECT_NEAR(doc["scene"]["light"]["theta_deg"].get<double>(), 30.0, 1e-12);
    EXPECT_NEAR(doc["scene"]["light"]["phi_deg"].get<double>(), 180.0, 1e-12);
    EXPECT_NEAR(doc["scene"]["view"]["theta_deg"].get<double>(), 10.0, 1e-12);
    EXPECT_NEAR(doc["scene"]["radius_um"].get<double>(), 0.4 * 30 * 10.0, 1e-12);
    ASSERT_EQ(doc["truth"]["regions"].size(), 2U);
    EXPECT_EQ(doc["truth"]["regions"][1]["sigma_over_T"].get<double>(), 0.75);
    EXPECT_EQ(doc["truth"]["regions"][1]["correlation"], "exponential");
    // Region pixels add up to the object; the left region ends at column 19.
    const auto p0 = doc["truth"]["regions"][0]["pixels"].get<std::size_t>();
    const auto p1 = doc["truth"]["regions"][1]["pixels"].get<std::size_t>();
    EXPECT_EQ(p0 + p1, c.object_count);
    EXPECT_EQ(doc["truth"]["regions"][0]["bbox"][2].get<int>(), 19);
    EXPECT_EQ(doc["camera"]["seed"].get<std::uint64_t>(), 99U);
    EXPECT_EQ(doc["camera"]["white_level_dn"].get<double>(), 4095.0);
    EXPECT_TRUE(doc["camera"]["gamma"].is_null());
    EXPECT_EQ(doc["statistics"]["object_pixels"].get<std::size_t>(), c.object_count);
    EXPECT_EQ(roughscope::testing::slurp(files.sidecar).find("NaN"), std::string::npos);
}

TEST(CaptureSidecar, NothingWrittenWhenTheImageCannotBeEncoded) {
    CaptureRecord r = two_region_sphere();
    r.camera.response = simulation::Response::Gamma;
    const auto c = simulation::render_capture(r.scene, r.truths, r.labels, r.camera);
    const fs::path dir = roughscope::testing::fresh_dir("capture_sidecar_fail");
    EXPECT_THROW(write_capture_files(c, r, simulation::CaptureFormat::Dng, dir), InvalidArgument);
    EXPECT_TRUE(fs::is_empty(dir));
}

}  // namespace
}  // namespace roughscope::serialize
