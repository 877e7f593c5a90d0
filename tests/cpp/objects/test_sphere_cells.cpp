// The steps of a sphere's BRDF table (objects/sphere_steps.hpp): the cells of the disc, the pass
// over its pixels and each cell's measurement, against images of known brightness on a sphere of
// known centre and radius (the normal n = ((x − cx)/R, (cy − y)/R, √(1 − ρ²))).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include <gtest/gtest.h>

#include "objects/sphere_steps.hpp"

namespace {

using namespace roughscope;
using namespace roughscope::image;
using namespace roughscope::image::detail;

const CircleFit kCircle{60.3, 50.7, 40.0, 0.0, 0};

// The normal at pixel centre (c + ½, r + ½), or none off the disc.
std::optional<Eigen::Vector3d> normal_at(std::size_t c, std::size_t r) {
    const double x = (static_cast<double>(c) + 0.5 - kCircle.centre_x_px) / kCircle.radius_px;
    const double y = (kCircle.centre_y_px - (static_cast<double>(r) + 0.5)) / kCircle.radius_px;
    if (x * x + y * y >= 1.0) return std::nullopt;
    return Eigen::Vector3d(x, y, std::sqrt(1.0 - x * x - y * y));
}

// A grey 120 × 100 image: E = albedo · n·L on the disc, 0 elsewhere; every 13th pixel flagged.
LinearImage lambert_sphere(const Eigen::Vector3d& light, double albedo) {
    LinearImage img;
    img.width = 120;
    img.height = 100;
    img.channels = 1;
    img.values.assign(img.width * img.height, 0.0F);
    img.flags.assign(img.width * img.height, 0);
    for (std::size_t r = 0; r < img.height; ++r)
        for (std::size_t c = 0; c < img.width; ++c) {
            const std::size_t i = r * img.width + c;
            if (const auto n = normal_at(c, r))
                img.values[i] = static_cast<float>(albedo * std::max(0.0, n->dot(light)));
            if (i % 13 == 0) img.flags[i] = kPixelSaturated;
        }
    return img;
}

TEST(SphereCells, CellSideHoldsTheDiscInAtMostMaxCells) {
    SphereOptions o;
    o.limb_fraction = 0.9;
    o.max_cells = 100;
    // π (0.9 · 40)² = 4071.5 px over 100 cells: 40.7 px a cell, side ⌈6.38⌉ = 7.
    EXPECT_EQ(sphere_cell_px(o, 40.0), 7U);
    o.max_cells = 16384;
    EXPECT_EQ(sphere_cell_px(o, 40.0), 1U);
    o.cell_px = 3;
    EXPECT_EQ(sphere_cell_px(o, 40.0), 3U);
}

TEST(SphereCells, ThePassUsesTheLitAndSeenPixelsOfTheDisc) {
    const Eigen::Vector3d z(0.0, 0.0, 1.0);
    const LinearImage img = lambert_sphere(z, 1.0);
    std::vector<std::uint8_t> region(img.pixel_count(), 1);
    for (std::size_t i = 0; i < region.size(); i += 5) region[i] = 0;
    for (const bool with_region : {false, true})
        for (const std::size_t k : {std::size_t{1}, std::size_t{4}}) {
            SphereOptions o;
            o.limb_fraction = 0.95;
            o.max_angle_deg = 70.0;
            const SphereCells cells =
                sum_sphere_cells(img, with_region ? region.data() : nullptr, kCircle, o, k);
            // By definition: ρ ≤ 0.95 and θ = acos(n_z) ≤ 70° (L = V = z), in the region.
            std::size_t used = 0, flagged = 0;
            double sum = 0;
            for (std::size_t r = 0; r < img.height; ++r)
                for (std::size_t c = 0; c < img.width; ++c) {
                    const std::size_t i = r * img.width + c;
                    const auto n = normal_at(c, r);
                    if (!n || n->head<2>().squaredNorm() > 0.95 * 0.95 ||
                        !(n->z() > std::cos(deg_to_rad(70.0))) || (with_region && !region[i]))
                        continue;
                    if (img.flags[i] != 0) {
                        ++flagged;
                        continue;
                    }
                    ++used;
                    sum += img.values[i];
                }
            EXPECT_EQ(cells.pixels_used, used);
            EXPECT_EQ(cells.pixels_flagged, flagged);
            EXPECT_EQ(cells.columns, (120 + k - 1) / k);
            EXPECT_EQ(cells.rows, (100 + k - 1) / k);
            double cell_sum = 0;
            std::size_t cell_count = 0;
            for (const CellSums& cs : cells.cells) {
                cell_sum += cs.sum;
                cell_count += cs.count;
            }
            EXPECT_EQ(cell_count, used);
            EXPECT_NEAR(cell_sum, sum, 1e-9 * sum);
        }
}

}  // namespace
