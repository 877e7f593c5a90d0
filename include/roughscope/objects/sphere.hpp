// A rough sphere in one photograph as a BRDF table (the sphere counterpart of the paper's §5.2
// cylinders, compared like the CUReT tables of §5.3): the silhouette's circle gives every pixel
// its normal, so with known light L and view V each pixel is one (θi, θs, φs) measurement.
// Formulas in docs/curved-objects.md.
//
// Camera frame as cylinder.hpp (x image right, y image up, z towards the camera). The pixel
// centre (x, y) (image coordinates, y down) inside the circle (cx, cy, R) has the normal
//   n = ((x − cx)/R, (cy − y)/R, √(1 − ρ²)),   ρ² = ((x − cx)² + (y − cy)²)/R².
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "roughscope/brdf/comparison.hpp"
#include "roughscope/brdf/table.hpp"
#include "roughscope/objects/silhouette.hpp"
#include "roughscope/photo/image.hpp"

namespace roughscope::image {

struct SphereOptions {
    Eigen::Vector3d light = Eigen::Vector3d(0.0, 0.0, 1.0);  // L, camera frame, unit
    Eigen::Vector3d view = Eigen::Vector3d(0.0, 0.0, 1.0);   // V, camera frame, unit
    // The circle; none: fit_sphere_circle(find_silhouette(image)).
    std::optional<CircleFit> circle;
    SilhouetteOptions silhouette;
    CircleFitOptions circle_fit;
    // Pixels with ρ > limb_fraction are not used (the limb), in (0, 1].
    double limb_fraction = 0.95;
    // Pixels whose θi or θs exceeds this are not used (grazing light or view), in (0°, 90°].
    double max_angle_deg = 85.0;
    // Cells: square blocks of cell_px × cell_px image pixels (grid from the top-left corner);
    // 0 = the smallest side for which the disc holds at most max_cells cells,
    // ⌈√(π (limb_fraction · R)² / max_cells)⌉. A cell's mean is not the brightness at its
    // centroid where the brightness curves (towards the limb it changes by tens of per cent per
    // pixel): the second-order term is taken out (see SphereResult::table), but what is left
    // still exceeds the noise of a 14-bit sphere of ~10⁴ pixels once cells are 2 px or more. The
    // default keeps every pixel its own cell up to 16384 pixels (a sphere of radius ≈ 75 px at
    // limb_fraction 0.95); larger spheres get blocks, whose angular size shrinks like 1/R.
    std::size_t cell_px = 0;
    std::size_t max_cells = 16384;  // ≥ 1
    // Cells with fewer used pixels than this fraction of cell_px² are dropped, [0, 1].
    double min_cell_fraction = 0.5;
    // Worker threads of the pass over the pixels and, unless comparison.threads is set, of the
    // comparison (0 = all cores); the result does not depend on it (each cell is summed by one
    // thread, in the same order).
    std::size_t threads = 0;
    ComparisonOptions comparison;
};

// Throws InvalidArgument naming the field and its valid range.
void check_sphere_options(const SphereOptions& options);

struct SphereResult {
    CircleFit circle;
    bool circle_detected = false;  // from the silhouette (else given)
    std::size_t cell_px = 0;
    // One measurement per cell, index = 1, 2, ... in raster order of the cells: θi, θs, φs of the
    // cell's mean normal (paper frame, φi = π, φv = φs), value = BRDF f = Ē / cos θi, weight =
    // 1/σ_f² scaled to a mean of 1 (σ_f: the cell's standard error of Ē from pixel noise, / cos
    // θi).
    BrdfTable table;
    Comparison
        comparison;  // compare_brdf(table, options.comparison); empty from measure_sphere_table
    std::size_t pixels_used = 0;
    std::size_t pixels_flagged = 0;  // inside the used disc, lit and seen, never used
    std::vector<std::string> warnings;
};

// Measures the sphere, restricted to region_mask (width · height bytes, nonzero = use; nullptr =
// the whole disc). Throws InvalidArgument for bad options or an inconsistent image/mask,
// DataError when the sphere cannot be found (silhouette.hpp) or fewer than 3 cells are usable.
SphereResult measure_sphere(const LinearImage& image, const std::vector<std::uint8_t>* region_mask,
                            const SphereOptions& options = {});

// measure_sphere without the model comparison: the circle, the cells and the BRDF table (the
// sphere's profile), `comparison` left empty. The same errors, except none from the comparison.
SphereResult measure_sphere_table(const LinearImage& image,
                                  const std::vector<std::uint8_t>* region_mask,
                                  const SphereOptions& options = {});

}  // namespace roughscope::image
