// Synthetic captures (simulation/capture.hpp) against independent facts: the model's brightness
// at the known geometry of a plane, the photon-transfer relation of Poisson + read noise, the
// clipping rule, the IEC 61966-2-1 sRGB values, the geometry of the sphere's centre and the
// cylinder's symmetry, and reproducibility from the seed.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/scattering/reflectance_models.hpp"
#include "roughscope/simulation/capture.hpp"

namespace roughscope::simulation {
namespace {

CameraModel noiseless_camera() {
    CameraModel camera;
    camera.shot_noise = false;
    camera.read_noise_e = 0.0;
    camera.bit_depth = 16;
    camera.black_level_dn = 100.0;
    camera.gain_dn_per_e = 0.5;
    camera.full_well_e = 1e9;
    camera.electrons_per_unit_s = 20000.0;
    return camera;
}

Scene plane_scene(double theta_i_deg, double theta_v_deg, double phi_v_deg) {
    Scene scene;
    scene.shape = SceneShape::Plane;
    scene.width = 16;
    scene.height = 12;
    scene.light = direction_from_angles(deg_to_rad(theta_i_deg), kPi);
    scene.view = direction_from_angles(deg_to_rad(theta_v_deg), deg_to_rad(phi_v_deg));
    return scene;
}

TEST(CaptureScene, PlaneGivesTheModelBrightnessExactlyWithoutNoise) {
    const Scene scene = plane_scene(30.0, 20.0, 0.0);  // specular half-plane: φs = 0
    SurfaceTruth truth;
    truth.sigma_um = 1.0;
    truth.T_um = 3.0;
    const CameraModel camera = noiseless_camera();
    const Capture c = render_capture(scene, {truth}, {}, camera);
    const Geometry geom = make_geometry(deg_to_rad(30.0), deg_to_rad(20.0), 0.0);
    const double expected = very_rough_brightness(geom, 1.0 / 3.0, Correlation::Gaussian);
    ASSERT_GT(expected, 0.0);
    EXPECT_EQ(c.object_count, 16U * 12U);
    for (std::size_t i = 0; i < c.dn.size(); ++i) {
        ASSERT_FLOAT_EQ(c.radiance[i], static_cast<float>(expected));
        EXPECT_NEAR(c.theta_i_rad[i], deg_to_rad(30.0), 1e-6);
        EXPECT_NEAR(c.theta_s_rad[i], deg_to_rad(20.0), 1e-6);
        EXPECT_NEAR(c.phi_s_rad[i], 0.0, 1e-6);
        const double signal = 0.5 * 20000.0 * expected + 100.0;
        EXPECT_EQ(c.dn[i], static_cast<std::uint16_t>(std::floor(signal + 0.5)));
        EXPECT_EQ(c.saturated[i], 0);
    }
}

TEST(CaptureScene, LambertPlaneIsCosineOfIncidenceAndRetroViewIsPhiPi) {
    // The light at azimuth π and the view at azimuth π on the same side: retro half-plane.
    const Scene scene = plane_scene(60.0, 40.0, 180.0);
    SurfaceTruth truth;
    truth.model = BrightnessModel::Lambert;
    const Capture c = render_capture(scene, {truth}, {}, noiseless_camera());
    EXPECT_NEAR(c.radiance[0], 0.5, 1e-7);  // cos 60°
    EXPECT_NEAR(c.phi_s_rad[0], kPi, 1e-6);
}

TEST(CaptureScene, SphereCentreSeesTheAngleBetweenViewAndLight) {
    Scene scene;
    scene.shape = SceneShape::Sphere;
    scene.width = 101;
    scene.height = 101;
    scene.pixel_size_um = 2.0;
    scene.radius_um = 80.0;
    scene.view = direction_from_angles(deg_to_rad(20.0), 0.0);
    scene.light = direction_from_angles(deg_to_rad(40.0), kPi);
    SurfaceTruth truth;
    truth.model = BrightnessModel::Lambert;
    const Capture c = render_capture(scene, {truth}, {}, noiseless_camera());
    const std::size_t centre = 50 * 101 + 50;
    EXPECT_NEAR(c.theta_s_rad[centre], 0.0, 1e-6);
    EXPECT_NEAR(c.theta_i_rad[centre], deg_to_rad(60.0), 1e-6);  // 20° + 40°
    EXPECT_NEAR(c.radiance[centre], 0.5, 1e-6);
    for (int k = 0; k < 3; ++k)
        EXPECT_NEAR(c.normal[3 * centre + static_cast<std::size_t>(k)], scene.view[k], 1e-6);
    // The disc covers π R² / s² pixels (to the pixelation of its rim, ~ 2π R / s).
    const double disc = kPi * 40.0 * 40.0;
    EXPECT_NEAR(static_cast<double>(c.object_count), disc, 2.0 * kPi * 40.0);
    EXPECT_EQ(c.label[0], -1);  // a corner is background
    EXPECT_TRUE(std::isnan(c.theta_i_rad[0]));
    EXPECT_EQ(c.radiance[0], 0.0F);
}

TEST(CaptureScene, CylinderIsConstantAlongItsAxis) {
    Scene scene;
    scene.shape = SceneShape::Cylinder;
    scene.width = 64;
    scene.height = 40;
    scene.view = direction_from_angles(deg_to_rad(10.0), 0.0);  // in the XZ plane: axis = image up
    scene.light = direction_from_angles(deg_to_rad(35.0), kPi);
    SurfaceTruth truth;
    truth.sigma_um = 1.0;
    truth.T_um = 2.0;
    const Capture c = render_capture(scene, {truth}, {}, noiseless_camera());
    std::size_t varying_columns = 0;
    for (std::size_t col = 0; col < 64; ++col) {
        for (std::size_t row = 1; row < 40; ++row)
            ASSERT_EQ(c.radiance[row * 64 + col], c.radiance[col]) << "column " << col;
        if (col > 0 && c.radiance[col] != c.radiance[col - 1]) ++varying_columns;
    }
    EXPECT_GT(varying_columns, 20U);  // but it varies across the axis
    // Seen along Z, the normal at image x is (x/R, 0, √(1 − x²/R²)).
    scene.view = Eigen::Vector3d::UnitZ();
    const Capture top = render_capture(scene, {truth}, {}, noiseless_camera());
    const double R = scene_radius_um(scene);
    for (std::size_t col = 20; col < 44; ++col) {
        const double x = (static_cast<double>(col) + 0.5 - 32.0) * scene.pixel_size_um;
        EXPECT_NEAR(top.normal[3 * (5 * 64 + col)], x / R, 1e-6);
        EXPECT_NEAR(top.normal[3 * (5 * 64 + col) + 1], 0.0, 1e-6);
        EXPECT_NEAR(top.normal[3 * (5 * 64 + col) + 2], std::sqrt(1.0 - x * x / (R * R)), 1e-6);
    }
    // Background at the sides: radius 0.4 · 40 · 10 µm = 160 µm = 16 pixels of 64.
    EXPECT_EQ(c.label[0], -1);
    EXPECT_EQ(c.label[32], 0);
}

TEST(CaptureCamera, FlatFieldFollowsPhotonTransfer) {
    Scene scene = plane_scene(0.0, 0.0, 0.0);
    scene.width = 200;
    scene.height = 200;
    SurfaceTruth truth;
    truth.model = BrightnessModel::Lambert;  // E = 1 at normal incidence
    CameraModel camera;
    camera.electrons_per_unit_s = 1000.0;
    camera.exposure_s = 1.0;
    camera.gain_dn_per_e = 0.5;
    camera.read_noise_e = 3.0;
    camera.black_level_dn = 64.0;
    camera.bit_depth = 16;
    camera.seed = 7;
    const Capture c = render_capture(scene, {truth}, {}, camera);
    double sum = 0.0, sum2 = 0.0;
    for (std::uint16_t v : c.dn) sum += v;
    const double n = static_cast<double>(c.dn.size());
    const double mean = sum / n;
    for (std::uint16_t v : c.dn) sum2 += (v - mean) * (v - mean);
    const double var = sum2 / (n - 1.0);
    // var = gain (mean − black) + gain² σ_read² (+ 1/12 from rounding to integers).
    const double expected_var = 0.5 * (mean - 64.0) + 0.25 * 9.0 + 1.0 / 12.0;
    EXPECT_NEAR(mean, 0.5 * 1000.0 + 64.0, 4.0 * std::sqrt(expected_var / n));
    EXPECT_NEAR(var, expected_var, 4.0 * expected_var * std::sqrt(2.0 / n));
    // Mean and variance of the theory at the true mean, too.
    EXPECT_NEAR(var, 0.5 * 500.0 + 0.25 * 9.0 + 1.0 / 12.0,
                4.0 * expected_var * std::sqrt(2.0 / n));
}

TEST(CaptureCamera, FlatFieldCountsFollowThePoissonLaw) {
    // Gain 1 e/DN, no read noise, no black level: the DN are the photo-electron counts of a
    // repeated mean (the inversion-table path) and of varying means (Boost's PTRD path).
    for (const bool vignetted : {false, true}) {
        Scene scene = plane_scene(0.0, 0.0, 0.0);
        scene.width = 400;
        scene.height = 250;
        SurfaceTruth truth;
        truth.model = BrightnessModel::Lambert;
        CameraModel camera;
        camera.electrons_per_unit_s = 30.0;
        camera.gain_dn_per_e = 1.0;
        camera.read_noise_e = 0.0;
        camera.black_level_dn = 0.0;
        camera.bit_depth = 16;
        camera.vignetting = vignetted ? 1e-9 : 0.0;  // distinct means, the same law (to 1e-9)
        const Capture c = render_capture(scene, {truth}, {}, camera);
        std::vector<double> counts(200, 0.0);
        for (std::uint16_t v : c.dn) counts[std::min<std::size_t>(v, 199)] += 1.0;
        // χ² over the bins 15..45 (expected ≥ 150 each) against N e^{−30} 30^k / k!.
        const auto n = static_cast<double>(c.dn.size());
        double chi2 = 0.0;
        for (int k = 15; k <= 45; ++k) {
            const double expected = n * std::exp(k * std::log(30.0) - 30.0 - std::lgamma(k + 1.0));
            chi2 += (counts[static_cast<std::size_t>(k)] - expected) *
                    (counts[static_cast<std::size_t>(k)] - expected) / expected;
        }
        // 31 bins: χ² has mean 31 and standard deviation ≈ 7.9; 31 + 5·7.9 ≈ 70.
        EXPECT_LT(chi2, 70.0) << (vignetted ? "PTRD path" : "table path");
    }
}

TEST(CaptureCamera, SaturationMaskIsExactlyWhereClipped) {
    Scene scene;
    scene.shape = SceneShape::Sphere;
    scene.width = 61;
    scene.height = 61;
    scene.view = Eigen::Vector3d::UnitZ();
    scene.light = direction_from_angles(deg_to_rad(20.0), kPi);
    SurfaceTruth truth;
    truth.model = BrightnessModel::Lambert;
    // White level reached first (full well beyond it).
    CameraModel camera = noiseless_camera();
    camera.bit_depth = 12;
    camera.gain_dn_per_e = 0.25;
    camera.electrons_per_unit_s = 20000.0;  // centre: 0.25 · 20000 · 0.94 + 100 ≈ 4800 > 4095
    Capture c = render_capture(scene, {truth}, {}, camera);
    std::size_t clipped = 0;
    for (std::size_t i = 0; i < c.dn.size(); ++i) {
        const bool over = c.expected_dn[i] >= 4095.0F;
        ASSERT_EQ(c.saturated[i] == 1, over) << i;
        if (over) {
            ASSERT_EQ(c.dn[i], 4095);
            ++clipped;
        } else {
            ASSERT_LT(c.dn[i], 4095);
        }
    }
    EXPECT_GT(clipped, 100U);
    EXPECT_LT(clipped, c.object_count);
    EXPECT_EQ(c.saturated_count, clipped);
    // Full well reached first: the clipped pixels sit at gain · full well + black.
    camera.full_well_e = 10000.0;  // 0.25 · 10000 + 100 = 2600 DN
    c = render_capture(scene, {truth}, {}, camera);
    for (std::size_t i = 0; i < c.dn.size(); ++i) {
        const bool over = c.expected_dn[i] >= static_cast<float>(0.25 * 10000.0 + 100.0);
        ASSERT_EQ(c.saturated[i] == 1, over) << i;
        if (over) {
            ASSERT_EQ(c.dn[i], 2600);
        }
    }
}

TEST(CaptureCamera, OverexposureSaturatesAtTheFullWellWithShotNoise) {
    Scene scene = plane_scene(10.0, 0.0, 0.0);
    SurfaceTruth truth;
    truth.model = BrightnessModel::Lambert;
    CameraModel camera;
    camera.read_noise_e = 0.0;
    camera.bit_depth = 16;
    camera.full_well_e = 50000.0;
    camera.gain_dn_per_e = 0.5;
    camera.black_level_dn = 10.0;
    for (double exposure_s : {3.0, 1e300}) {  // μe ≈ 6e4 (Poisson draws) and overflowing
        camera.exposure_s = exposure_s;
        const Capture c = render_capture(scene, {truth}, {}, camera);
        std::size_t at_full_well = 0;
        for (std::size_t i = 0; i < c.dn.size(); ++i) {
            ASSERT_EQ(c.saturated[i], 1) << i;
            at_full_well += c.dn[i] == 25010 ? 1 : 0;
        }
        EXPECT_EQ(at_full_well, c.dn.size());  // P(Poisson(5.9e4) < 5e4) < 1e-100
        EXPECT_EQ(c.saturated_count, c.dn.size());
    }
}

TEST(CaptureScene, MeanScatteredPowerModelIsEquationOne) {
    const Scene scene = plane_scene(40.0, 25.0, 30.0);
    SurfaceTruth truth;
    truth.model = BrightnessModel::MeanScatteredPower;
    truth.sigma_um = 0.08;
    truth.T_um = 1.5;
    truth.correlation = Correlation::Exponential;
    const Capture c = render_capture(scene, {truth}, {}, noiseless_camera());
    ModelOptions options;  // the truth's defaults: VH factor, radiance
    const double expected =
        mean_scattered_power(make_geometry(deg_to_rad(40.0), deg_to_rad(25.0), deg_to_rad(30.0)),
                             {0.08, 1.5, Correlation::Exponential}, options)
            .brightness;
    EXPECT_FLOAT_EQ(c.radiance[0], static_cast<float>(expected));
    EXPECT_NEAR(c.phi_s_rad[0], deg_to_rad(30.0), 1e-6);
}

TEST(CaptureCamera, SrgbMatchesIec61966Values) {
    // IEC 61966-2-1 values: the linear segment, the joint, middle grey and half intensity.
    EXPECT_NEAR(srgb_encode(0.001), 0.01292, 1e-12);
    EXPECT_NEAR(srgb_encode(0.0031308), 0.040449936, 1e-6);
    EXPECT_NEAR(srgb_encode(0.18), 0.4613561295, 1e-9);
    EXPECT_NEAR(srgb_encode(0.5), 0.7353569831, 1e-9);
    EXPECT_NEAR(srgb_encode(1.0), 1.0, 1e-12);
    EXPECT_NEAR(srgb_decode(0.5), 0.2140411405, 1e-9);
    for (double u = 0.0; u <= 1.0; u += 1.0 / 64.0)
        EXPECT_NEAR(srgb_decode(srgb_encode(u)), u, 1e-12);
    // And in a render: DN = round(white · encode(signal / white)).
    Scene scene = plane_scene(45.0, 0.0, 0.0);
    SurfaceTruth truth;
    truth.model = BrightnessModel::Lambert;
    CameraModel camera = noiseless_camera();
    camera.bit_depth = 8;
    camera.black_level_dn = 0.0;
    camera.gain_dn_per_e = 0.001;  // signal = 0.001 · 20000 · cos 45° = 14.14 DN
    camera.response = Response::Srgb;
    const Capture c = render_capture(scene, {truth}, {}, camera);
    const double signal = 0.001 * 20000.0 * std::cos(deg_to_rad(45.0));
    EXPECT_EQ(c.dn[0],
              static_cast<std::uint16_t>(std::lround(255.0 * srgb_encode(signal / 255.0))));
    camera.response = Response::Gamma;
    camera.gamma = 2.0;
    const Capture g = render_capture(scene, {truth}, {}, camera);
    EXPECT_EQ(g.dn[0], static_cast<std::uint16_t>(std::lround(255.0 * std::sqrt(signal / 255.0))));
}

TEST(CaptureCamera, SameSeedSameBytesOtherSeedOtherBytes) {
    Scene scene;
    scene.shape = SceneShape::Sphere;
    scene.width = 48;
    scene.height = 32;
    SurfaceTruth truth;
    CameraModel camera;
    camera.seed = 42;
    const Capture a = render_capture(scene, {truth}, {}, camera);
    const Capture b = render_capture(scene, {truth}, {}, camera);
    EXPECT_EQ(a.dn, b.dn);
    camera.seed = 43;
    const Capture d = render_capture(scene, {truth}, {}, camera);
    EXPECT_NE(a.dn, d.dn);
}

TEST(CaptureCamera, ThreadCountDoesNotChangeTheResult) {
    Scene scene;
    scene.shape = SceneShape::Sphere;
    scene.width = 300;
    scene.height = 257;  // ≥ 65536 pixels: threaded
    SurfaceTruth truth;
    CameraModel camera;
    camera.seed = 5;
    CaptureOptions one, three;
    one.threads = 1;
    three.threads = 3;
    const Capture a = render_capture(scene, {truth}, {}, camera, one);
    const Capture b = render_capture(scene, {truth}, {}, camera, three);
    EXPECT_EQ(a.dn, b.dn);
    EXPECT_EQ(a.object_count, b.object_count);
    EXPECT_EQ(a.saturated_count, b.saturated_count);
    EXPECT_EQ(a.theta_i_rad.size(), b.theta_i_rad.size());
}

TEST(CaptureCamera, VignettingScalesByOneMinusStrengthRhoSquared) {
    Scene scene = plane_scene(0.0, 0.0, 0.0);
    scene.width = 20;
    scene.height = 20;
    SurfaceTruth truth;
    truth.model = BrightnessModel::Lambert;
    CameraModel camera = noiseless_camera();
    camera.black_level_dn = 0.0;
    camera.vignetting = 0.5;
    const Capture c = render_capture(scene, {truth}, {}, camera);
    // Corner pixel centre at (−9.5, 9.5) from the centre; half-diagonal² = 200.
    const double rho2 = (9.5 * 9.5 * 2.0) / 200.0;
    EXPECT_NEAR(c.expected_dn[0], 0.5 * 20000.0 * (1.0 - 0.5 * rho2), 1e-2);
}

TEST(CaptureTruth, RegionMapGivesEachRegionItsModel) {
    Scene scene = plane_scene(30.0, 10.0, 0.0);
    scene.width = 10;
    scene.height = 4;
    SurfaceTruth smooth, rough;
    smooth.sigma_um = 0.2;
    smooth.T_um = 1.0;
    rough.sigma_um = 0.6;
    rough.T_um = 1.0;
    rough.correlation = Correlation::Exponential;
    std::vector<std::int32_t> labels(40);
    for (std::size_t i = 0; i < 40; ++i) labels[i] = (i % 10) < 5 ? 0 : 1;
    const Capture c = render_capture(scene, {smooth, rough}, labels, noiseless_camera());
    const Geometry geom = make_geometry(deg_to_rad(30.0), deg_to_rad(10.0), 0.0);
    const auto e0 = static_cast<float>(very_rough_brightness(geom, 0.2, Correlation::Gaussian));
    const auto e1 = static_cast<float>(very_rough_brightness(geom, 0.6, Correlation::Exponential));
    ASSERT_NE(e0, e1);
    for (std::size_t i = 0; i < 40; ++i) {
        EXPECT_EQ(c.label[i], labels[i]);
        EXPECT_FLOAT_EQ(c.radiance[i], labels[i] == 0 ? e0 : e1);
    }
}

TEST(CaptureTruth, TabulatedBrightnessInterpolatesItsTable) {
    // A table of cos θi on a grid: trilinear interpolation reproduces a function linear in θi
    // exactly, and the grid points exactly.
    BrightnessTable table;
    table.theta_i_rad = {0.0, 0.5, 1.0, 1.5};
    table.theta_s_rad = {0.0, 1.5};
    table.phi_s_rad = {0.0, kPi};
    for (double ti : table.theta_i_rad)
        for (std::size_t b = 0; b < 2; ++b)
            for (std::size_t k = 0; k < 2; ++k) table.values.push_back(2.0 * ti + 1.0);
    const auto f = table_brightness(table);
    EXPECT_NEAR(f(make_geometry(0.25, 0.3, 1.0)), 1.5, 1e-12);
    EXPECT_NEAR(f(make_geometry(1.0, 0.0, 0.0)), 3.0, 1e-12);
    SurfaceTruth truth;
    truth.model = BrightnessModel::Tabulated;
    truth.tabulated = f;
    const Capture c =
        render_capture(plane_scene(0.25 * 180.0 / kPi, 0.0, 0.0), {truth}, {}, noiseless_camera());
    EXPECT_NEAR(c.radiance[0], 1.5, 1e-6);
    table.values.pop_back();
    EXPECT_THROW(table_brightness(table), InvalidArgument);
}

TEST(CaptureErrors, InvalidInputNamesTheValue) {
    const Scene scene = plane_scene(30.0, 0.0, 0.0);
    SurfaceTruth truth;
    CameraModel camera;
    camera.bit_depth = 10;
    try {
        render_capture(scene, {truth}, {}, camera);
        FAIL() << "bit depth 10 accepted";
    } catch (const InvalidArgument& e) {
        EXPECT_NE(std::string(e.what()).find("bit_depth = 10"), std::string::npos) << e.what();
    }
    camera.bit_depth = 8;
    camera.black_level_dn = 255.0;
    EXPECT_THROW(render_capture(scene, {truth}, {}, camera), InvalidArgument);
    camera.black_level_dn = 0.0;
    EXPECT_THROW(render_capture(scene, {truth}, {3, 0}, camera), InvalidArgument);
    Scene below = scene;
    below.view = Eigen::Vector3d(1.0, 0.0, 0.0);
    EXPECT_THROW(render_capture(below, {truth}, {}, camera), InvalidArgument);
    Scene not_unit = scene;
    not_unit.light = Eigen::Vector3d(0.0, 0.0, 2.0);
    EXPECT_THROW(render_capture(not_unit, {truth}, {}, camera), InvalidArgument);
    EXPECT_THROW(render_capture(scene, {}, {}, camera), InvalidArgument);
    EXPECT_THROW(parse_scene_shape("cube"), InvalidArgument);
    EXPECT_EQ(parse_response("sRGB"), Response::Srgb);
}

}  // namespace
}  // namespace roughscope::simulation
