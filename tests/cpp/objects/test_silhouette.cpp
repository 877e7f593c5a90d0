// Silhouettes, circles and cylinder axes (image/silhouette.hpp) on synthetic captures of known
// geometry (simulation/capture.hpp: the sphere and the cylinder are centred in the image, radius
// 0.4 · min(width, height) pixels by default).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "object_captures.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/objects/cylinder.hpp"
#include "roughscope/objects/silhouette.hpp"
#include "roughscope/objects/sphere.hpp"
#include "roughscope/simulation/capture.hpp"

namespace {

using namespace roughscope;
using namespace roughscope::image;
using roughscope::testing::camera_for;
using roughscope::testing::linear_from_capture;
namespace sim = roughscope::simulation;

// A Lambert object lit from the camera (its limb stays visible: cos θi ≈ 0.12 half a pixel
// inside the edge of a 64-px sphere), 14-bit with shot and read noise.
LinearImage lambert_capture(sim::SceneShape shape, std::size_t w, std::size_t h, std::uint64_t seed,
                            double radius_px = 0.0, int bits = 14) {
    sim::Scene scene;
    scene.shape = shape;
    scene.width = w;
    scene.height = h;
    scene.pixel_size_um = 1.0;
    scene.radius_um = radius_px;
    scene.light = Eigen::Vector3d(0, 0, 1);
    sim::SurfaceTruth lambert;
    lambert.model = sim::BrightnessModel::Lambert;
    const sim::CameraModel camera = camera_for(bits, 1.0, 0.6, seed);
    sim::CaptureOptions co;
    co.keep_geometry = false;
    co.threads = 1;
    return linear_from_capture(sim::render_capture(scene, {lambert}, {}, camera, co), camera);
}

TEST(SilhouetteCircle, SphereCentreAndRadiusWithinAFifthOfAPixel) {
    struct Case {
        std::size_t w, h;
        double radius_px;  // 0: the default 0.4 · min(w, h)
        int bits;
    };
    const std::vector<Case> cases = {{120, 120, 0, 14},
                                     {200, 200, 0, 12},
                                     {240, 180, 0, 8},
                                     {160, 160, 30.5, 12},
                                     {301, 257, 0, 14}};
    std::uint64_t seed = 1;
    for (const Case& c : cases) {
        for (int trial = 0; trial < 2; ++trial) {
            const LinearImage img =
                lambert_capture(sim::SceneShape::Sphere, c.w, c.h, seed++, c.radius_px, c.bits);
            const Silhouette s = find_silhouette(img);
            EXPECT_FALSE(s.touches_border());
            const CircleFit fit = fit_sphere_circle(s);
            const double r_true =
                c.radius_px > 0 ? c.radius_px : 0.4 * static_cast<double>(std::min(c.w, c.h));
            EXPECT_NEAR(fit.centre_x_px, 0.5 * static_cast<double>(c.w), 0.2) << c.w << "x" << c.h;
            EXPECT_NEAR(fit.centre_y_px, 0.5 * static_cast<double>(c.h), 0.2) << c.w << "x" << c.h;
            EXPECT_NEAR(fit.radius_px, r_true, 0.2) << c.w << "x" << c.h;
            EXPECT_LT(fit.rms_residual_px, 0.5);
        }
    }
}

TEST(SilhouetteCircle, OffCentreSphereFromACrop) {
    const LinearImage full = lambert_capture(sim::SceneShape::Sphere, 200, 200, 7);
    const LinearImage img = roughscope::testing::cropped(full, 10, 6, 185, 190);
    const CircleFit fit = fit_sphere_circle(find_silhouette(img));
    EXPECT_NEAR(fit.centre_x_px, 100.0 - 10.0, 0.2);
    EXPECT_NEAR(fit.centre_y_px, 100.0 - 6.0, 0.2);
    EXPECT_NEAR(fit.radius_px, 80.0, 0.2);
}

TEST(SilhouetteCircle, ExactPointsAndBadInput) {
    std::vector<EdgePoint> pts;
    for (int k = 0; k < 40; ++k) {
        const double a = 0.1 + 0.05 * k;  // an arc of 2 rad
        pts.push_back({12.5 + 7.25 * std::cos(a), -3.0 + 7.25 * std::sin(a)});
    }
    const CircleFit fit = fit_circle(pts);
    EXPECT_NEAR(fit.centre_x_px, 12.5, 1e-9);
    EXPECT_NEAR(fit.centre_y_px, -3.0, 1e-9);
    EXPECT_NEAR(fit.radius_px, 7.25, 1e-9);
    EXPECT_THROW(fit_circle({{0, 0}, {1, 1}}), InvalidArgument);
    EXPECT_THROW(fit_circle({{0, 0}, {1, 1}, {2, 2}, {3, 3}}), DataError);
    EXPECT_THROW(fit_circle({{0, 0}, {1, NAN}, {2, 2}}), InvalidArgument);
}

TEST(SilhouetteErrors, NoObjectTouchingTheBorderNotCircular) {
    LinearImage empty;
    empty.width = empty.height = 64;
    empty.channels = 1;
    empty.values.assign(64 * 64, 0.25F);
    empty.flags.assign(64 * 64, 0);
    EXPECT_THROW(find_silhouette(empty), DataError);
    // A speck of 4 pixels is below the minimum object fraction.
    for (std::size_t i : {2080U, 2081U, 2144U, 2145U}) empty.values[i] = 0.9F;
    EXPECT_THROW(find_silhouette(empty), DataError);

    // A sphere cut by the frame: part of its outline is missing.
    const LinearImage big = roughscope::testing::cropped(
        lambert_capture(sim::SceneShape::Sphere, 200, 200, 3), 0, 0, 160, 200);
    try {
        fit_sphere_circle(find_silhouette(big));
        ADD_FAILURE() << "no error for a sphere cut by the border";
    } catch (const DataError& e) {
        EXPECT_NE(std::string(e.what()).find("border"), std::string::npos) << e.what();
    }

    // A bright square: not a circle, and the message says by how much.
    LinearImage square = empty;
    std::fill(square.values.begin(), square.values.end(), 0.0F);
    for (std::size_t r = 12; r < 52; ++r)
        for (std::size_t c = 12; c < 52; ++c) square.values[r * 64 + c] = 0.8F;
    try {
        fit_sphere_circle(find_silhouette(square));
        ADD_FAILURE() << "no error for a square";
    } catch (const DataError& e) {
        EXPECT_NE(std::string(e.what()).find("not circular"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("times"), std::string::npos) << e.what();
    }
    // The square is not a cylinder either (two pairs of edges: no dominant direction).
    EXPECT_THROW(fit_cylinder_axis(find_silhouette(square)), DataError);

    SilhouetteOptions bad;
    bad.edge_fraction = 0.0;
    EXPECT_THROW(find_silhouette(square, bad), InvalidArgument);
    bad = {};
    bad.min_object_fraction = 1.5;
    EXPECT_THROW(find_silhouette(square, bad), InvalidArgument);
}

TEST(SilhouetteCylinder, VerticalAndTransposedAxis) {
    for (std::uint64_t seed = 1; seed <= 3; ++seed) {
        const LinearImage img = lambert_capture(sim::SceneShape::Cylinder, 160, 160, seed);
        const Silhouette s = find_silhouette(img);
        EXPECT_TRUE(s.touches_top && s.touches_bottom);
        EXPECT_FALSE(s.touches_left || s.touches_right);
        const CylinderAxis axis = fit_cylinder_axis(s);
        EXPECT_TRUE(axis.detected);
        EXPECT_NEAR(axis.radius_px, 64.0, 0.2);
        EXPECT_NEAR(std::abs(axis.direction_y), 1.0, 1e-5);
        EXPECT_NEAR(axis.across_distance_px(80.0, 10.0), 0.0, 0.2);
        EXPECT_NEAR(axis.across_x(), 1.0, 1e-5);  // towards the image's right

        const CylinderAxis t =
            fit_cylinder_axis(find_silhouette(roughscope::testing::transposed(img)));
        EXPECT_NEAR(t.radius_px, 64.0, 0.2);
        EXPECT_NEAR(std::abs(t.direction_x), 1.0, 1e-5);
        EXPECT_NEAR(t.across_distance_px(10.0, 80.0), 0.0, 0.2);
        EXPECT_NEAR(t.across_y(), -1.0, 1e-5);  // horizontal axis: "right" half is up
    }
}

// A Lambert cylinder (L = V) with its axis at 30° from the image vertical, point-sampled at pixel
// centres: E = √(1 − (d/R)²) inside, 0 outside.
LinearImage rotated_cylinder(double angle_rad, double cx, double cy, double R, std::size_t w,
                             std::size_t h) {
    LinearImage img;
    img.width = w;
    img.height = h;
    img.channels = 1;
    img.flags.assign(w * h, 0);
    const double ux = std::cos(angle_rad), uy = std::sin(angle_rad);  // across the axis
    for (std::size_t r = 0; r < h; ++r)
        for (std::size_t c = 0; c < w; ++c) {
            const double d = (c + 0.5 - cx) * ux + (r + 0.5 - cy) * uy;
            const double s = d / R;
            img.values.push_back(std::abs(s) < 1 ? static_cast<float>(std::sqrt(1 - s * s)) : 0.F);
        }
    return img;
}

TEST(SilhouetteCylinder, RotatedAxisDetectedAndGiven) {
    const double angle = roughscope::deg_to_rad(30.0);
    const LinearImage img = rotated_cylinder(angle, 101.3, 95.7, 41.0, 200, 200);
    const CylinderAxis axis = fit_cylinder_axis(find_silhouette(img));
    // The axis direction is perpendicular to (cos 30°, sin 30°).
    EXPECT_NEAR(std::abs(axis.direction_x * std::cos(angle) + axis.direction_y * std::sin(angle)),
                0.0, 2e-3);
    EXPECT_NEAR(axis.radius_px, 41.0, 0.2);
    EXPECT_NEAR(axis.across_distance_px(101.3, 95.7), 0.0, 0.2);
    // Given as a line (direction of either sign, any length) or as two edges.
    const CylinderAxis given =
        cylinder_axis_from_line(101.3, 95.7, 2 * std::sin(angle), -2 * std::cos(angle), 41.0);
    EXPECT_NEAR(given.across_x(), std::cos(angle), 1e-12);
    EXPECT_NEAR(given.across_y(), std::sin(angle), 1e-12);
    const double ax = -std::sin(angle), ay = std::cos(angle);
    const double ux = std::cos(angle), uy = std::sin(angle);
    const CylinderAxis edges = cylinder_axis_from_edges(
        {101.3 - 41 * ux, 95.7 - 41 * uy}, {101.3 - 41 * ux + 50 * ax, 95.7 - 41 * uy + 50 * ay},
        {101.3 + 41 * ux - 20 * ax, 95.7 + 41 * uy - 20 * ay},
        {101.3 + 41 * ux + 10 * ax, 95.7 + 41 * uy + 10 * ay});
    EXPECT_NEAR(edges.radius_px, 41.0, 1e-9);
    EXPECT_NEAR(edges.across_distance_px(101.3, 95.7), 0.0, 1e-9);
    EXPECT_THROW(cylinder_axis_from_line(0, 0, 0, 0, 5), InvalidArgument);
    EXPECT_THROW(cylinder_axis_from_line(0, 0, 1, 0, 0), InvalidArgument);
    EXPECT_THROW(cylinder_axis_from_edges({0, 0}, {0, 10}, {5, 0}, {6, 10}), InvalidArgument);
    EXPECT_THROW(cylinder_axis_from_edges({0, 0}, {0, 0}, {5, 0}, {5, 10}), InvalidArgument);
}

TEST(SilhouetteCylinder, AnEdgeCutByTheBorderIsAnError) {
    const LinearImage img = lambert_capture(sim::SceneShape::Cylinder, 160, 160, 5);
    const LinearImage cut = roughscope::testing::cropped(img, 0, 0, 120, 160);  // right edge gone
    try {
        fit_cylinder_axis(find_silhouette(cut));
        ADD_FAILURE() << "no error for a cylinder cut by the border";
    } catch (const DataError& e) {
        EXPECT_NE(std::string(e.what()).find("missing"), std::string::npos) << e.what();
    }
    // A sphere is not a cylinder: its outline is not two straight lines.
    EXPECT_THROW(
        fit_cylinder_axis(find_silhouette(lambert_capture(sim::SceneShape::Sphere, 160, 160, 6))),
        DataError);
}

}  // namespace

namespace {

// Above 2^21 pixels the components are found on a block-reduced mask (f = 2 here): the circle is
// still the full-resolution one.
TEST(SilhouetteCircle, LargeImageUsesTheBlockReducedComponents) {
    using namespace roughscope::image;
    const std::size_t w = 1500, h = 1450;
    const double cx = 731.3, cy = 702.9, R = 600.4;
    LinearImage img;
    img.width = w;
    img.height = h;
    img.channels = 1;
    img.flags.assign(w * h, 0);
    img.values.resize(w * h);
    for (std::size_t r = 0; r < h; ++r)
        for (std::size_t c = 0; c < w; ++c) {
            const double x = (c + 0.5 - cx) / R, y = (r + 0.5 - cy) / R;
            const double rho2 = x * x + y * y;
            // Lambert lit from the camera, a dark speck of texture, a noise speck outside.
            img.values[r * w + c] = rho2 < 1 ? static_cast<float>(std::sqrt(1 - rho2)) : 0.0F;
        }
    for (std::size_t r = 600; r < 603; ++r)
        for (std::size_t c = 700; c < 703; ++c) img.values[r * w + c] = 0.0F;  // a hole
    img.values[20 * w + 20] = 0.9F;
    const Silhouette s = find_silhouette(img);
    EXPECT_EQ(s.mask[601 * w + 701], 1);  // the hole is filled
    EXPECT_EQ(s.mask[20 * w + 20], 0);    // the speck is not the object
    const CircleFit fit = fit_sphere_circle(s);
    EXPECT_NEAR(fit.centre_x_px, cx, 0.2);
    EXPECT_NEAR(fit.centre_y_px, cy, 0.2);
    EXPECT_NEAR(fit.radius_px, R, 0.2);
}

TEST(SilhouetteValues, ANonFiniteValueIsRefusedWhereverItIs) {
    // No separate pass checks the values: the silhouette's pass does, for find_silhouette, the
    // cylinder and the sphere (and they check every value themselves when the axis or circle is
    // given). A NaN or an infinity in the background, on the object, in any plane: the
    // InvalidArgument of check_linear_image, naming the file and the sample.
    const LinearImage grey = lambert_capture(sim::SceneShape::Sphere, 96, 80, 3);
    const std::size_t n = grey.pixel_count();
    LinearImage rgb = grey;
    rgb.channels = 3;
    rgb.values.resize(3 * n);
    for (std::size_t k = 0; k < n; ++k) rgb.values[n + k] = rgb.values[2 * n + k] = grey.values[k];
    CylinderOptions given_axis;
    given_axis.axis = CylinderAxis{48.0, 40.0, 0.0, 1.0, 30.0};
    SphereOptions given_circle;
    given_circle.circle = CircleFit{48.0, 40.0, 32.0};
    given_circle.comparison.fits = false;
    SphereOptions no_fits;
    no_fits.comparison.fits = false;
    for (const std::size_t sample :
         {std::size_t{5}, std::size_t{40 * 96 + 48}, 2 * n + 40 * 96 + 50}) {
        for (const float bad :
             {std::numeric_limits<float>::quiet_NaN(), -std::numeric_limits<float>::infinity()}) {
            LinearImage image = sample < n ? grey : rgb;
            image.info.source = "bad.tif";
            image.values[sample] = bad;
            const std::string at = "at sample " + std::to_string(sample);
            const auto expect_refused = [&](auto&& call, const char* what) {
                try {
                    call();
                    ADD_FAILURE() << what << ": no error for sample " << sample;
                } catch (const InvalidArgument& e) {
                    const std::string m = e.what();
                    EXPECT_NE(m.find("bad.tif"), std::string::npos) << m;
                    EXPECT_NE(m.find(at + " is not finite"), std::string::npos) << what << m;
                } catch (const std::exception& e) {
                    ADD_FAILURE() << what << ": " << e.what();
                }
            };
            expect_refused([&] { (void)find_silhouette(image); }, "silhouette");
            expect_refused([&] { (void)measure_cylinder_profile(image, nullptr, {}); }, "cylinder");
            expect_refused([&] { (void)measure_cylinder_profile(image, nullptr, given_axis); },
                           "cylinder, axis given");
            expect_refused([&] { (void)measure_sphere(image, nullptr, no_fits); }, "sphere");
            expect_refused([&] { (void)measure_sphere(image, nullptr, given_circle); },
                           "sphere, circle given");
        }
    }
    // Huge finite values whose average overflows (the object's pixels) are not refused as
    // non-finite (the silhouette may fail otherwise on such an image).
    LinearImage huge = rgb;
    for (std::size_t k = 0; k < 3 * n; ++k)
        huge.values[k] =
            grey.values[k % n] > 0.1F ? 0.9F * std::numeric_limits<float>::max() : 0.0F;
    try {
        (void)find_silhouette(huge);
    } catch (const InvalidArgument& e) {
        EXPECT_EQ(std::string(e.what()).find("not finite"), std::string::npos) << e.what();
    } catch (const DataError&) {
    }
}

}  // namespace
