// The sphere's BRDF table (sphere.hpp, measure_sphere_table) as steps: the cells of the disc, one
// pass summing each cell's used pixels, and each cell's measurement — the mean brightness at the
// normal of the cell's centroid, less its curvature term, over cos θi. Formulas in
// docs/curved-objects.md.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "roughscope/objects/sphere.hpp"
#include "roughscope/scattering/geometry.hpp"

namespace roughscope::image::detail {

// The sums of one cell's used pixels (channel average v; pixel centres (px, py) about the circle's
// centre, py up).
struct CellSums {
    double sum = 0, sum2 = 0, diff2 = 0;      // Σv, Σv², Σ(v − v_left)² of used neighbours
    double sx = 0, sy = 0, sxx = 0, syy = 0;  // Σpx, Σpy, Σpx², Σpy², px
    std::uint32_t count = 0, diffs = 0;
};

// The cells: square blocks of cell_px × cell_px pixels from the image's top-left corner.
struct SphereCells {
    std::size_t cell_px = 1;
    std::size_t columns = 0, rows = 0;  // of cells
    std::vector<CellSums> cells;        // row · columns + column
    std::size_t pixels_used = 0;
    std::size_t pixels_flagged = 0;  // inside the used disc, lit and seen, never used
};

// options.cell_px, or when 0 the smallest side for which the disc ρ ≤ limb_fraction of radius
// `radius_px` holds at most max_cells cells: ⌈√(π (limb_fraction · R)² / max_cells)⌉.
std::size_t sphere_cell_px(const SphereOptions& options, double radius_px);

// One pass over the pixels in `region` (width · height bytes, nonzero = use; nullptr: all) whose
// centre lies on the disc ρ ≤ limb_fraction with θi and θs at most max_angle_deg, on
// options.threads threads over bands of whole rows of cells (the sums do not depend on the number
// of threads). Flagged pixels are counted, not used.
SphereCells sum_sphere_cells(const LinearImage& image, const std::uint8_t* region,
                             const CircleFit& circle, const SphereOptions& options,
                             std::size_t cell_px);

// One cell as a BRDF measurement: the geometry of the normal at its centroid, f = Ē / cos θi
// (Ē the cell's mean less ½ (E_xx var_x + E_yy var_y), the curvature from the neighbouring
// cells' means) and its standard error from the pixel noise, / cos θi.
struct CellMeasurement {
    Geometry geometry;
    double brdf = 0.0;
    double brdf_stderr = 0.0;
};

// The cells with at least min_cell_fraction · cell_px² used pixels whose centroid's normal has L
// and V above its horizon, in raster order; `dropped` counts the others that hold pixels.
std::vector<CellMeasurement> cell_measurements(const SphereCells& cells, const CircleFit& circle,
                                               const SphereOptions& options, std::size_t& dropped);

}  // namespace roughscope::image::detail
