// Step 1 of the cylinder profile (cylinder_steps.hpp): the axis and the bins of the normal angle
// across it (docs/curved-objects.md, "Cylinder axis" and "Cylinder profile").
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>

#include "cylinder_steps.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/memory.hpp"
#include "roughscope/core/text.hpp"

namespace roughscope::image::detail {
namespace {

// Bands of rows of the pass over the pixels: at most kMaxBands, of at least kRowsPerBand rows.
constexpr std::size_t kRowsPerBand = 256;
constexpr std::size_t kMaxBands = 8;

// The bisection's steps for a bin edge inside a sub-bin (far below rounding of a 1/8 px width).
constexpr int kEdgeBisections = 60;

}  // namespace

void check_unit_direction(std::string_view name, const Eigen::Vector3d& v) {
    if (!v.allFinite() || std::abs(v.norm() - 1.0) > 1e-6)
        throw InvalidArgument(concat(name, " direction (", check::format_number(v.x()), ", ",
                                     check::format_number(v.y()), ", ", check::format_number(v.z()),
                                     ") must be a finite unit vector (camera frame)"));
    if (!(v.z() > 0.0))
        throw InvalidArgument(concat(name, " direction (", check::format_number(v.x()), ", ",
                                     check::format_number(v.y()), ", ", check::format_number(v.z()),
                                     ") must point towards the camera's side (z > 0): it is "
                                     "below the horizon of every visible surface point"));
}

ProfileNode cylinder_node(double s, double weight, double ux, double uy,
                          const Eigen::Vector3d& light, const Eigen::Vector3d& view) {
    s = std::clamp(s, -1.0, 1.0);
    const Eigen::Vector3d n(s * ux, -s * uy, std::sqrt(std::max(0.0, 1.0 - s * s)));
    ProfileNode node;
    node.weight = weight;
    if (const auto g = geometry_from_vectors(n.normalized(), light, view)) {
        node.geometry = *g;
        node.lit = true;
    }
    return node;
}

CylinderLocation locate_cylinder(const LinearImage& image, const CylinderOptions& options) {
    CylinderLocation where;
    if (options.axis) {
        check_linear_image(image);
        where.axis = cylinder_axis_from_line(options.axis->point_x_px, options.axis->point_y_px,
                                             options.axis->direction_x, options.axis->direction_y,
                                             options.axis->radius_px);
    } else {
        Outline outline = find_outline(image, options.silhouette, options.threads);
        where.axis = fit_cylinder_axis(outline.silhouette, options.axis_fit);
        where.silhouette_level = outline.silhouette.threshold;
        where.object_rows = std::move(outline.rows);
    }
    return where;
}

std::size_t scan_bands(std::size_t height) {
    return std::clamp<std::size_t>(height / kRowsPerBand, 1, kMaxBands);
}

std::int32_t CylinderBinning::bin_of(double across_px) const {
    const double R = axis.radius_px;
    const double d = across_px;
    if (std::abs(d) > limb_fraction * R) return -1;
    const double alpha = std::asin(std::clamp(d / R, -1.0, 1.0));
    double x = 0;
    switch (half) {
        case CylinderHalf::Right:
            x = alpha;
            break;
        case CylinderHalf::Left:
            x = -alpha;
            break;
        case CylinderHalf::Both:
            x = alpha + kPi / 2.0;
            break;
    }
    if (x < 0) return -1;
    return static_cast<std::int32_t>(
        std::min(bins - 1, static_cast<std::size_t>(x / bin_width_rad)));
}

double CylinderBinning::sub_bin_low_px(std::size_t k) const {
    return static_cast<double>(k) / kSubBinsPerPx - axis.radius_px;
}

CylinderBinning bin_cylinder(const CylinderAxis& axis, const CylinderOptions& options,
                             std::size_t width, std::size_t height) {
    CylinderBinning g;
    g.axis = axis;
    g.half = options.half;
    g.bin_width_rad = deg_to_rad(options.bin_width_deg);
    g.limb_fraction = options.limb_fraction;
    const double R = axis.radius_px;
    const double bw = g.bin_width_rad;
    const bool both = options.half == CylinderHalf::Both;
    g.bins = static_cast<std::size_t>(std::ceil((both ? kPi : kPi / 2.0) / bw - 1e-9));
    g.sub_bins = static_cast<std::size_t>(std::ceil(2.0 * R * kSubBinsPerPx)) + 1;
    // Each sub-bin holds at most one bin edge (bins are ≥ 1/8 px wide only when R sin(bw) ≥ 1/8,
    // which every R ≥ 4 px and bw ≥ 2° meet; narrower bins share a sub-bin and the finer edge is
    // missed): the pixel's side of that edge, split[k], picks the half-sub-bin 2k or 2k + 1.
    g.split.assign(g.sub_bins, std::numeric_limits<double>::infinity());
    g.sub_bin.assign(2 * g.sub_bins, -1);
    for (std::size_t k = 0; k < g.sub_bins; ++k) {
        const double d_lo = static_cast<double>(k) / kSubBinsPerPx - R;
        const double d_hi = d_lo + 1.0 / kSubBinsPerPx;
        const std::int32_t b_lo = g.bin_of(d_lo), b_hi = g.bin_of(d_hi);
        g.sub_bin[2 * k] = b_lo;
        g.sub_bin[2 * k + 1] = b_lo;
        if (b_lo != b_hi) {  // bisect for the edge
            double a = d_lo, b = d_hi;
            for (int it = 0; it < kEdgeBisections; ++it) {
                const double m = 0.5 * (a + b);
                (g.bin_of(m) == b_lo ? a : b) = m;
            }
            g.split[k] = b;
            g.sub_bin[2 * k + 1] = b_hi;
        }
    }

    // Slices (1 px) along the axis: t = (p − P)·a over the image's corners.
    double t_min = std::numeric_limits<double>::infinity(), t_max = -t_min;
    for (const double cx : {0.0, static_cast<double>(width)})
        for (const double cy : {0.0, static_cast<double>(height)}) {
            const double t = (cx - axis.point_x_px) * axis.direction_x +
                             (cy - axis.point_y_px) * axis.direction_y;
            t_min = std::min(t_min, t);
            t_max = std::max(t_max, t);
        }
    g.t_min_px = t_min;
    g.slices = static_cast<std::size_t>(std::ceil(t_max - t_min)) + 1;
    g.bands = scan_bands(height);
    // The scan's accumulators, at most: every band's bins and its slices of each bin.
    check_memory(static_cast<double>(g.bands) * static_cast<double>(g.bins) *
                     (sizeof(BinSums) + 12.0 * static_cast<double>(g.slices)),
                 concat("cylinder bin_width_deg = ", check::format_number(options.bin_width_deg),
                        " (", std::to_string(g.bins), " bins of the normal angle over ",
                        std::to_string(g.slices), " slices along the axis)"),
                 "give a wider bin_width_deg (default 2)");
    return g;
}

}  // namespace roughscope::image::detail
