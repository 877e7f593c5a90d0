// A rough sphere as a BRDF table (image/sphere.hpp) against synthetic captures of known σ/T
// (simulation/capture.hpp), compared with every model of brdf/comparison.hpp.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "object_captures.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/objects/sphere.hpp"
#include "roughscope/simulation/capture.hpp"

namespace {

using namespace roughscope;
using namespace roughscope::image;
using roughscope::testing::camera_for;
using roughscope::testing::linear_from_capture;
using roughscope::testing::very_rough_truth;
namespace sim = roughscope::simulation;

constexpr std::size_t kSize = 120;  // R = 48 px

sim::Capture render(const sim::Scene& scene, const sim::SurfaceTruth& truth,
                    const sim::CameraModel& camera) {
    sim::CaptureOptions co;
    co.keep_geometry = false;
    co.threads = 1;
    return sim::render_capture(scene, {truth}, {}, camera, co);
}

sim::Scene sphere_scene(const Eigen::Vector3d& light) {
    sim::Scene scene;
    scene.shape = sim::SceneShape::Sphere;
    scene.width = kSize;
    scene.height = kSize;
    scene.pixel_size_um = 1.0;
    scene.light = light;
    return scene;
}

LinearImage noisy_sphere(const sim::Scene& scene, const sim::SurfaceTruth& truth, int bits,
                         std::uint64_t seed) {
    const double e_max =
        roughscope::testing::max_radiance(render(scene, truth, camera_for(bits, 1, 0.5, 1)));
    const sim::CameraModel camera = camera_for(bits, e_max, 0.6, seed);
    return linear_from_capture(render(scene, truth, camera), camera);
}

CircleFit true_circle() {
    CircleFit c;
    c.centre_x_px = 60.0;
    c.centre_y_px = 60.0;
    c.radius_px = 48.0;
    return c;
}

TEST(SphereTable, VhGaussianFitCoversTheTruthAndWins) {
    int inside = 0, total = 0, wins = 0;
    std::uint64_t seed = 500;
    for (const double light_deg : {0.0, 30.0})
        for (const double s : {0.4, 0.7, 1.1})
            for (const int bits : {12, 14})
                for (int rep = 0; rep < 2; ++rep) {  // 24 trials
                    const Eigen::Vector3d L =
                        sim::direction_from_angles(deg_to_rad(light_deg), kPi);
                    const LinearImage img = noisy_sphere(
                        sphere_scene(L), very_rough_truth(s, Correlation::Gaussian), bits, seed++);
                    SphereOptions o;
                    o.light = L;
                    o.circle = true_circle();
                    const SphereResult r = measure_sphere(img, nullptr, o);
                    EXPECT_EQ(r.cell_px, 1U);  // ~6000 pixels: each its own row
                    EXPECT_GE(r.table.size(), 5000U);
                    EXPECT_FALSE(r.comparison.two_point.available);  // CUReT's pair: not here
                    const ModelResult& vh = r.comparison.result(ComparisonModel::VhGaussianFit);
                    ASSERT_TRUE(vh.available) << vh.reason;
                    const std::optional<double> fit = vh.parameter("sigma_over_T");
                    ASSERT_TRUE(fit.has_value());
                    double se = 0;
                    for (const ModelParameter& p : vh.parameters)
                        if (p.name == "sigma_over_T") se = p.standard_error.value_or(0.0);
                    ASSERT_GT(se, 0.0);
                    ++total;
                    const bool ok = std::abs(*fit - s) <= 2.0 * se;
                    inside += ok;
                    if (!ok)
                        std::printf("  outside: light %.0f sigma/T %.2f %d bit: %.5f +/- %.5f\n",
                                    light_deg, s, bits, *fit, se);
                    ASSERT_TRUE(r.comparison.winner.has_value());
                    const ComparisonModel w = *r.comparison.winner;
                    const bool won =
                        w == ComparisonModel::VhGaussianFit ||
                        vh.errors.gain_sse <= r.comparison.result(w).errors.gain_sse * (1.0 + 1e-3);
                    wins += won;
                    EXPECT_TRUE(won) << "winner " << to_string(w) << " at light " << light_deg
                                     << " sigma/T " << s;
                }
    const double fraction = static_cast<double>(inside) / total;
    std::printf(
        "sphere coverage: %d of %d trials (%.1f %%) within the reported 2 sigma; "
        "vh_gaussian_fit won (or tied) %d of %d\n",
        inside, total, 100.0 * fraction, wins, total);
    EXPECT_GE(fraction, 0.9);
}

TEST(SphereTable, DetectedCircleOnALambertSphere) {
    sim::SurfaceTruth lambert;
    lambert.model = sim::BrightnessModel::Lambert;
    const LinearImage img = noisy_sphere(sphere_scene(Eigen::Vector3d(0, 0, 1)), lambert, 14, 3);
    const SphereResult r = measure_sphere(img, nullptr, SphereOptions{});
    EXPECT_TRUE(r.circle_detected);
    EXPECT_NEAR(r.circle.radius_px, 48.0, 0.2);
    // Lambert: f = Ē / cos θi is constant over the sphere (to the noise).
    double lo = 1e300, hi = 0;
    for (const BrdfMeasurement& m : r.table.measurements) {
        lo = std::min(lo, m.value);
        hi = std::max(hi, m.value);
        EXPECT_NEAR(m.geometry.theta_s_rad, m.geometry.theta_i_rad, 1e-9);  // L = V
    }
    EXPECT_LT(hi / lo - 1.0, 0.1);
    // Small cells on request; and a region mask halves the pixels.
    // Blocks on request (at most max_cells of them), centroid geometry unchanged for L = V.
    SphereOptions blocks;
    blocks.max_cells = 1500;
    const SphereResult rb = measure_sphere(img, nullptr, blocks);
    EXPECT_EQ(rb.cell_px, 3U);
    EXPECT_LE(rb.table.size(), 1500U);
    EXPECT_GT(rb.table.size(), 500U);
    for (const BrdfMeasurement& m : rb.table.measurements)
        EXPECT_NEAR(m.value / r.table.measurements.front().value, 1.0, 0.1);
    std::vector<std::uint8_t> mask(img.pixel_count(), 0);
    for (std::size_t i = 0; i < kSize * kSize / 2; ++i) mask[i] = 1;
    EXPECT_NEAR(static_cast<double>(measure_sphere(img, &mask, SphereOptions{}).pixels_used) /
                    static_cast<double>(r.pixels_used),
                0.5, 0.02);
}

TEST(SphereTable, BadInputIsAnError) {
    sim::SurfaceTruth lambert;
    lambert.model = sim::BrightnessModel::Lambert;
    const LinearImage img = noisy_sphere(sphere_scene(Eigen::Vector3d(0, 0, 1)), lambert, 12, 4);
    auto with = [](auto change) {
        SphereOptions o;
        change(o);
        return o;
    };
    EXPECT_THROW(measure_sphere(img, nullptr, with([](SphereOptions& o) {
                                    o.light = {1, 0, 0};
                                })),
                 InvalidArgument);
    EXPECT_THROW(measure_sphere(img, nullptr, with([](SphereOptions& o) {
                                    o.view = {0, 0, -1};
                                })),
                 InvalidArgument);
    EXPECT_THROW(
        measure_sphere(img, nullptr, with([](SphereOptions& o) { o.limb_fraction = 0.0; })),
        InvalidArgument);
    EXPECT_THROW(measure_sphere(img, nullptr, with([](SphereOptions& o) { o.max_cells = 0; })),
                 InvalidArgument);
    EXPECT_THROW(
        measure_sphere(img, nullptr, with([](SphereOptions& o) { o.max_angle_deg = 95.0; })),
        InvalidArgument);
    EXPECT_THROW(measure_sphere(img, nullptr, with([](SphereOptions& o) {
                                    o.circle = CircleFit{80, 80, -3, 0, 0};
                                })),
                 InvalidArgument);
    EXPECT_THROW(measure_sphere(img, nullptr, with([](SphereOptions& o) {
                                    o.circle = CircleFit{-500, -500, 3, 0, 0};  // off the image
                                })),
                 DataError);
    const std::vector<std::uint8_t> short_mask(3, 1);
    EXPECT_THROW(measure_sphere(img, &short_mask, {}), InvalidArgument);
    LinearImage dark = img;
    std::fill(dark.values.begin(), dark.values.end(), 0.0F);
    EXPECT_THROW(measure_sphere(dark, nullptr, {}), DataError);
    // A sphere cut by the border.
    const LinearImage cut = roughscope::testing::cropped(img, 20, 0, 100, 120);
    EXPECT_THROW(measure_sphere(cut, nullptr, {}), DataError);
}

// A textured Lambert sphere (centre (261.3, 238.6), R = 190 px) in a 520 × 480 image, with a
// saturated pixel every 997th (in a pattern) when `flagged`.
LinearImage textured_sphere(bool flagged) {
    const std::size_t w = 520, h = 480;
    LinearImage img;
    img.width = w;
    img.height = h;
    img.channels = 1;
    img.values.assign(w * h, 0.0F);
    img.flags.assign(w * h, 0);
    for (std::size_t r = 0; r < h; ++r)
        for (std::size_t c = 0; c < w; ++c) {
            const double x = (static_cast<double>(c) + 0.5 - 261.3) / 190.0;
            const double y = (static_cast<double>(r) + 0.5 - 238.6) / 190.0;
            const double rho2 = x * x + y * y;
            const double texture = 0.02 * static_cast<double>((r * 7 + c * 13) % 17) / 17.0;
            img.values[r * w + c] = static_cast<float>(
                0.01 + (rho2 < 1.0 ? 0.8 * std::sqrt(1.0 - rho2) : 0.0) + texture);
            if (flagged && (r * 31 + c * 17) % 997 == 0) img.flags[r * w + c] = kPixelSaturated;
        }
    return img;
}

CircleFit textured_sphere_circle() {
    CircleFit c;
    c.centre_x_px = 261.3;
    c.centre_y_px = 238.6;
    c.radius_px = 190.0;
    return c;
}

TEST(SphereTable, ResultDoesNotDependOnTheNumberOfThreads) {
    // A textured Lambert sphere lit from the camera, a few flagged pixels, a region mask: cells
    // of several pixels, several bands of rows.
    const LinearImage img = textured_sphere(true);
    std::vector<std::uint8_t> region(img.pixel_count(), 1);
    for (std::size_t i = 0; i < region.size(); i += 11) region[i] = 0;
    SphereOptions o;
    o.comparison.fits = false;
    o.threads = 1;
    const SphereResult one = measure_sphere(img, &region, o);
    ASSERT_GT(one.cell_px, 1U);
    ASSERT_GT(one.table.measurements.size(), 1000U);
    EXPECT_GT(one.pixels_flagged, 0U);
    for (const std::size_t threads : {2, 3}) {
        o.threads = threads;
        const SphereResult many = measure_sphere(img, &region, o);
        EXPECT_EQ(many.circle.radius_px, one.circle.radius_px);
        EXPECT_EQ(many.pixels_used, one.pixels_used);
        EXPECT_EQ(many.pixels_flagged, one.pixels_flagged);
        ASSERT_EQ(many.table.measurements.size(), one.table.measurements.size());
        for (std::size_t k = 0; k < one.table.measurements.size(); ++k) {
            const BrdfMeasurement &x = many.table.measurements[k], &y = one.table.measurements[k];
            EXPECT_EQ(x.theta_i_rad, y.theta_i_rad);
            EXPECT_EQ(x.theta_v_rad, y.theta_v_rad);
            EXPECT_EQ(x.phi_v_rad, y.phi_v_rad);
            EXPECT_EQ(x.value, y.value);
            EXPECT_EQ(x.weight, y.weight);
        }
    }
}

TEST(SphereTable, PixelsUsedAreThoseOfTheDocumentedRule) {
    // Each pixel tested as docs/curved-objects.md states it (inside the limb, n·L and n·V above
    // cos θ_max, in the region, no flag) against the pass, which tests only the ends of each
    // row's interval: for lights and views that cut the disc on either side, with and without
    // a region.
    const LinearImage img = textured_sphere(true);
    const CircleFit circle = textured_sphere_circle();
    std::vector<std::uint8_t> region(img.pixel_count(), 1);
    for (std::size_t i = 0; i < region.size(); i += 7) region[i] = 0;
    const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> directions = {
        {{0, 0, 1}, {0, 0, 1}},
        {sim::direction_from_angles(deg_to_rad(40.0), 0.0), {0, 0, 1}},
        {sim::direction_from_angles(deg_to_rad(70.0), 2.0),
         sim::direction_from_angles(deg_to_rad(30.0), 4.0)},
        {sim::direction_from_angles(deg_to_rad(89.0), 1.0),
         sim::direction_from_angles(deg_to_rad(60.0), 3.5)},
    };
    for (const auto& [L, V] : directions)
        for (const bool with_region : {false, true}) {
            SphereOptions o;
            o.light = L;
            o.view = V;
            o.circle = circle;
            o.cell_px = 5;
            o.min_cell_fraction = 0.0;
            std::size_t used = 0, flagged = 0;
            const double cos_max = std::cos(deg_to_rad(o.max_angle_deg));
            const double inv_R = 1.0 / circle.radius_px;
            for (std::size_t r = 0; r < img.height; ++r)
                for (std::size_t c = 0; c < img.width; ++c) {
                    const double nx = (static_cast<double>(c) + 0.5 - circle.centre_x_px) * inv_R;
                    const double ny = (circle.centre_y_px - (static_cast<double>(r) + 0.5)) * inv_R;
                    const double rho2 = nx * nx + ny * ny;
                    if (rho2 > o.limb_fraction * o.limb_fraction) continue;
                    const Eigen::Vector3d n(nx, ny, std::sqrt(1.0 - rho2));
                    if (!(n.dot(L) > cos_max && n.dot(V) > cos_max)) continue;
                    const std::size_t i = r * img.width + c;
                    if (with_region && !region[i]) continue;
                    ++(img.flags[i] ? flagged : used);
                }
            ASSERT_GT(used, 1000U);
            try {
                const SphereResult got =
                    measure_sphere_table(img, with_region ? &region : nullptr, o);
                EXPECT_EQ(got.pixels_used, used) << L.transpose() << " / " << V.transpose();
                EXPECT_EQ(got.pixels_flagged, flagged) << L.transpose() << " / " << V.transpose();
                EXPECT_TRUE(got.comparison.models.empty());
            } catch (const std::exception& e) {
                ADD_FAILURE() << e.what();
            }
        }
}

TEST(SphereTable, CellsSummedWithoutPerPixelTestsAgreeWithThePerPixelPath) {
    // No flag, no region: every row's cells are summed in the pass's fast path. A region of all
    // ones sends the same pixels through the per-pixel path; the cells must agree to rounding.
    const LinearImage img = textured_sphere(false);
    std::vector<std::uint8_t> everywhere(img.pixel_count(), 1);
    SphereOptions o;
    o.circle = textured_sphere_circle();
    o.cell_px = 6;
    const SphereResult fast = measure_sphere_table(img, nullptr, o);
    const SphereResult each = measure_sphere_table(img, &everywhere, o);
    EXPECT_EQ(fast.pixels_used, each.pixels_used);
    ASSERT_EQ(fast.table.measurements.size(), each.table.measurements.size());
    ASSERT_GT(fast.table.measurements.size(), 1000U);
    for (std::size_t k = 0; k < fast.table.measurements.size(); ++k) {
        const BrdfMeasurement &x = fast.table.measurements[k], &y = each.table.measurements[k];
        EXPECT_NEAR(x.theta_i_rad, y.theta_i_rad, 1e-12);
        EXPECT_NEAR(x.theta_v_rad, y.theta_v_rad, 1e-12);
        EXPECT_NEAR(x.value, y.value, 1e-12 * std::abs(y.value));
        EXPECT_NEAR(x.weight, y.weight, 1e-9 * y.weight);
    }
    // measure_sphere is the table and the comparison.
    SphereOptions no_fits = o;
    no_fits.comparison.fits = false;
    const SphereResult whole = measure_sphere(img, nullptr, no_fits);
    ASSERT_EQ(whole.table.measurements.size(), fast.table.measurements.size());
    EXPECT_EQ(whole.table.measurements.back().value, fast.table.measurements.back().value);
    EXPECT_FALSE(whole.comparison.models.empty());
}

}  // namespace
