// Step 1 of the cylinder profile (objects/cylinder_steps.hpp): the axis, the incidence angle of a
// pixel, and the bins of the normal angle across the axis, against the geometry of a synthetic
// cylinder of known axis and radius (paper §5.2: θi = asin(d/R) for L = V).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "cylinder_images.hpp"
#include "objects/cylinder_steps.hpp"
#include "roughscope/core/errors.hpp"

namespace {

using namespace roughscope;
using namespace roughscope::image;
using namespace roughscope::image::detail;

// The distance of (x, y) from the line through (px, py) along (dx, dy), signed by the side of the
// across direction (positive x component), from the cross product.
double distance_from_line(double x, double y, double px, double py, double dx, double dy) {
    const double norm = std::hypot(dx, dy);
    double d = ((x - px) * dy - (y - py) * dx) / norm;  // (p − P) × a, positive to the right of a
    const double ux = dy / norm;                        // the normal (dy, −dx) / |a|
    if (ux < 0 || (ux == 0 && -dx / norm > 0)) d = -d;
    return d;
}

TEST(CylinderGeometry, IncidenceAngleIsArcsinOfDistanceOverRadius) {
    const double px = 103.0, py = 77.0, dx = 0.3, dy = 1.0, R = 52.0;
    const CylinderAxis axis = cylinder_axis_from_line(px, py, dx, dy, R);
    const Eigen::Vector3d z(0.0, 0.0, 1.0);
    for (int k = 0; k < 40; ++k) {
        const double x = 60.0 + 2.3 * k, y = 20.0 + 3.7 * k;
        const double d = axis.across_distance_px(x, y);
        EXPECT_NEAR(d, distance_from_line(x, y, px, py, dx, dy), 1e-9);
        if (std::abs(d) >= R) continue;
        const ProfileNode node = cylinder_node(d / R, 1.0, axis.across_x(), axis.across_y(), z, z);
        ASSERT_TRUE(node.lit);
        // Lit from the camera: retro-reflection at θi = θs = |asin(d/R)|.
        EXPECT_NEAR(node.geometry.theta_i_rad, std::abs(std::asin(d / R)), 1e-12);
        EXPECT_NEAR(node.geometry.theta_s_rad, node.geometry.theta_i_rad, 1e-12);
        EXPECT_NEAR(node.geometry.phi_s_rad, kPi, 1e-6);
    }
    // Lit from 40° towards +x: θi = acos(n·L) with n = (d/R) û + √(1 − (d/R)²) ẑ, û = (û_x, −û_y).
    const Eigen::Vector3d L(std::sin(deg_to_rad(40.0)), 0.0, std::cos(deg_to_rad(40.0)));
    for (const double s : {-0.6, -0.2, 0.0, 0.3, 0.7}) {
        const Eigen::Vector3d n(s * axis.across_x(), -s * axis.across_y(), std::sqrt(1 - s * s));
        const ProfileNode node = cylinder_node(s, 0.5, axis.across_x(), axis.across_y(), L, z);
        ASSERT_TRUE(node.lit);
        EXPECT_NEAR(node.geometry.theta_i_rad, std::acos(n.dot(L)), 1e-12);
        EXPECT_NEAR(node.geometry.theta_s_rad, std::acos(n.z()), 1e-12);
        EXPECT_EQ(node.weight, 0.5);
    }
    // Lit from beyond the limb on one side: that side's normals face away from L.
    const Eigen::Vector3d grazing(std::sin(deg_to_rad(80.0)), 0.0, std::cos(deg_to_rad(80.0)));
    EXPECT_FALSE(cylinder_node(-0.5, 1.0, 1.0, 0.0, grazing, z).lit);
}

TEST(CylinderGeometry, BinEdgesLieAtTheSinesOfMultiplesOfTheBinWidth) {
    const double R = 60.0;
    const CylinderAxis axis = cylinder_axis_from_line(80.0, 70.0, 0.0, 1.0, R);
    for (const CylinderHalf half : {CylinderHalf::Right, CylinderHalf::Left, CylinderHalf::Both}) {
        SCOPED_TRACE(std::string(to_string(half)));
        CylinderOptions o;
        o.half = half;
        o.bin_width_deg = 3.0;
        o.limb_fraction = 0.97;
        const CylinderBinning g = bin_cylinder(axis, o, 160, 140);
        const double w = deg_to_rad(3.0);
        EXPECT_EQ(g.bins, half == CylinderHalf::Both ? 60U : 30U);
        ASSERT_EQ(g.sub_bin.size(), 2 * g.sub_bins);
        // Independently: the bin of d is ⌊x / w⌋ with x = α, −α or α + 90° by the half, α =
        // asin(d/R), none beyond the limb or on the other half.
        const auto expected = [&](double d) -> std::int32_t {
            if (std::abs(d) > 0.97 * R) return -1;
            const double alpha = std::asin(d / R);
            const double x = half == CylinderHalf::Right  ? alpha
                             : half == CylinderHalf::Left ? -alpha
                                                          : alpha + kPi / 2;
            return x < 0 ? -1 : static_cast<std::int32_t>(std::floor(x / w));
        };
        std::size_t edges = 0;
        for (std::size_t k = 0; k < g.sub_bins; ++k) {
            const double lo = g.sub_bin_low_px(k);
            EXPECT_DOUBLE_EQ(lo, static_cast<double>(k) / 8.0 - R);
            if (std::isfinite(g.split[k])) {
                ++edges;
                // The edge of the bin above it: d = R sin(x − offset) at a multiple x of w (or the
                // limb).
                const double x = g.split[k] / R;
                const double at = half == CylinderHalf::Right  ? std::asin(x)
                                  : half == CylinderHalf::Left ? -std::asin(x)
                                                               : std::asin(x) + kPi / 2;
                const double to_multiple = std::abs(at / w - std::round(at / w));
                const bool limb = std::abs(std::abs(g.split[k]) - 0.97 * R) < 1e-9;
                EXPECT_TRUE(to_multiple < 1e-9 || limb) << "edge at d = " << g.split[k];
            }
            // Every point of the sub-bin is in the bin of its half-sub-bin.
            for (int j = 1; j < 16; ++j) {
                const double d = lo + static_cast<double>(j) / 128.0;
                const std::int32_t b = g.sub_bin[2 * k + (d >= g.split[k] ? 1 : 0)];
                EXPECT_EQ(b, expected(d)) << "d = " << d;
                EXPECT_EQ(g.bin_of(d), b);
            }
        }
        // The edges inside the object: one per bin boundary crossed, and the limb's.
        EXPECT_GE(edges, half == CylinderHalf::Both ? 50U : 25U);
    }
}

TEST(CylinderGeometry, SlicesSpanTheImageAlongTheAxis) {
    CylinderOptions o;
    // A vertical axis through (50, 30): t = y − 30 runs over [−30, h − 30].
    const CylinderBinning v =
        bin_cylinder(cylinder_axis_from_line(50.0, 30.0, 0.0, 1.0, 20.0), o, 100, 90);
    EXPECT_DOUBLE_EQ(v.t_min_px, -30.0);
    EXPECT_EQ(v.slices, 91U);
    // At 45°: t over the corners spans (w + h)/√2.
    const CylinderBinning d =
        bin_cylinder(cylinder_axis_from_line(50.0, 45.0, 1.0, 1.0, 20.0), o, 100, 90);
    EXPECT_NEAR(d.t_min_px, -(50.0 + 45.0) / std::sqrt(2.0), 1e-12);
    EXPECT_EQ(d.slices, static_cast<std::size_t>(std::ceil(190.0 / std::sqrt(2.0))) + 1);
    EXPECT_EQ(scan_bands(100), 1U);
    EXPECT_EQ(scan_bands(600), 2U);
    EXPECT_EQ(scan_bands(100000), 8U);
}

TEST(CylinderGeometry, BinsThatWouldPassTheMemoryLimitAreRefused) {
    CylinderOptions o;
    o.bin_width_deg = 1e-4;  // 9·10⁵ bins over 5,000 slices in 8 bands
    const CylinderAxis axis = cylinder_axis_from_line(2000.0, 2000.0, 0.0, 1.0, 100.0);
    EXPECT_THROW(bin_cylinder(axis, o, 4000, 4000), InvalidArgument);
}

TEST(CylinderGeometry, LocatesAGivenAxisAndOneFromTheSilhouette) {
    const CylinderAxis truth = cylinder_axis_from_line(90.0, 60.0, 0.0, 1.0, 40.0);
    const LinearImage img = roughscope::testing::cylinder_law_image(
        180, 120, truth, roughscope::testing::lambert_law(40.0, 0.8, 0.01));
    CylinderOptions o;
    const CylinderLocation found = locate_cylinder(img, o);
    EXPECT_TRUE(found.axis.detected);
    EXPECT_NEAR(found.axis.point_x_px, 90.0, 0.3);
    EXPECT_NEAR(found.axis.radius_px, 40.0, 0.5);
    EXPECT_NEAR(std::abs(found.axis.direction_y), 1.0, 1e-6);
    ASSERT_EQ(found.object_rows.size(), 120U);
    EXPECT_LE(found.object_rows[60].begin, 51U);
    EXPECT_GE(found.object_rows[60].end, 129U);
    EXPECT_GT(found.silhouette_level, 0.01);
    EXPECT_LT(found.silhouette_level, 0.8);

    o.axis = truth;
    const CylinderLocation given = locate_cylinder(img, o);
    EXPECT_FALSE(given.axis.detected);
    EXPECT_EQ(given.axis.point_x_px, 90.0);
    EXPECT_EQ(given.axis.radius_px, 40.0);
    EXPECT_TRUE(given.object_rows.empty());
    EXPECT_EQ(given.silhouette_level, 0.0);

    // No object: nothing above the background.
    LinearImage dark = img;
    std::fill(dark.values.begin(), dark.values.end(), 0.0F);
    o.axis.reset();
    EXPECT_THROW(locate_cylinder(dark, o), DataError);
}

}  // namespace
