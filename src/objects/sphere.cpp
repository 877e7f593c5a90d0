#include "roughscope/objects/sphere.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "object_profile.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"
#include "sphere_steps.hpp"

namespace roughscope::image {
namespace {

using check::format_number;

std::string image_name(const LinearImage& image) {
    return image.info.source.empty() ? std::string("image") : image.info.source;
}

}  // namespace

void check_sphere_options(const SphereOptions& options) {
    detail::check_unit_direction("sphere light", options.light);
    detail::check_unit_direction("sphere view", options.view);
    if (!(options.limb_fraction > 0.0 && options.limb_fraction <= 1.0))
        throw InvalidArgument(
            concat("sphere limb_fraction = ", format_number(options.limb_fraction),
                   " is outside the valid range (0, 1]"));
    if (!(options.max_angle_deg > 0.0 && options.max_angle_deg <= 90.0))
        throw InvalidArgument(
            concat("sphere max_angle_deg = ", format_number(options.max_angle_deg),
                   " is outside the valid range (0, 90] deg"));
    if (options.max_cells < 1) throw InvalidArgument("sphere max_cells must be at least 1");
    if (!(options.min_cell_fraction >= 0.0 && options.min_cell_fraction <= 1.0))
        throw InvalidArgument(
            concat("sphere min_cell_fraction = ", format_number(options.min_cell_fraction),
                   " is outside the valid range [0, 1]"));
    if (options.circle) {
        check::finite("sphere circle centre x", options.circle->centre_x_px);
        check::finite("sphere circle centre y", options.circle->centre_y_px);
        check::positive("sphere circle radius", options.circle->radius_px, " px");
    }
    validate(options.comparison);
}

SphereResult measure_sphere_table(const LinearImage& image,
                                  const std::vector<std::uint8_t>* region_mask,
                                  const SphereOptions& options) {
    check_sphere_options(options);
    // The values: read and checked by the silhouette's pass, or here when there is none.
    check_linear_image_layout(image);
    if (region_mask && region_mask->size() != image.pixel_count())
        throw InvalidArgument(concat("sphere region mask has ", std::to_string(region_mask->size()),
                                     " entries, the image ", image_name(image), " has ",
                                     std::to_string(image.pixel_count()), " pixels"));
    SphereResult out;
    if (options.circle) {
        check_linear_image(image);
        out.circle = *options.circle;
    } else {
        out.circle = fit_sphere_circle(
            detail::find_outline(image, options.silhouette, options.threads).silhouette,
            options.circle_fit);
        out.circle_detected = true;
    }
    out.cell_px = detail::sphere_cell_px(options, out.circle.radius_px);
    const detail::SphereCells cells = detail::sum_sphere_cells(
        image, region_mask ? region_mask->data() : nullptr, out.circle, options, out.cell_px);
    out.pixels_used = cells.pixels_used;
    out.pixels_flagged = cells.pixels_flagged;
    if (out.pixels_flagged)
        out.warnings.push_back(concat(std::to_string(out.pixels_flagged),
                                      " flagged pixel(s) (saturated, clipped) left out"));

    // Cells → BRDF measurements.
    std::size_t dropped = 0;
    const std::vector<detail::CellMeasurement> rows =
        detail::cell_measurements(cells, out.circle, options, dropped);
    if (dropped)
        out.warnings.push_back(
            concat(std::to_string(dropped), " cell(s) with too few usable pixels left out"));
    if (rows.size() < 3)
        throw DataError(concat(image_name(image), ": the sphere has ", std::to_string(rows.size()),
                               " usable cell(s); at least 3 are needed"));
    // Weights 1/σ_f², scaled to a mean of 1 (all 1 when no cell has a noise estimate).
    double mean_inv = 0;
    std::size_t with_noise = 0;
    for (const detail::CellMeasurement& rw : rows)
        if (rw.brdf_stderr > 0) {
            mean_inv += 1.0 / (rw.brdf_stderr * rw.brdf_stderr);
            ++with_noise;
        }
    const bool weighted = with_noise == rows.size();
    if (weighted) mean_inv /= static_cast<double>(rows.size());
    out.table.name = image.info.source.empty() ? std::string("sphere") : image.info.source;
    out.table.channel = image.channels == 3 ? "mean" : "grey";
    out.table.measurements.reserve(rows.size());
    int index = 0;
    for (const detail::CellMeasurement& rw : rows) {
        const double weight = weighted ? 1.0 / (rw.brdf_stderr * rw.brdf_stderr) / mean_inv : 1.0;
        const Geometry& g = rw.geometry;
        out.table.measurements.push_back(make_brdf_measurement(
            ++index, g.theta_i_rad, kPi, g.theta_s_rad, g.phi_s_rad, rw.brdf, weight));
    }
    if (!weighted)
        out.warnings.push_back("no pixel-noise estimate in some cells: all cells weighted 1");
    return out;
}

SphereResult measure_sphere(const LinearImage& image, const std::vector<std::uint8_t>* region_mask,
                            const SphereOptions& options) {
    SphereResult out = measure_sphere_table(image, region_mask, options);
    ComparisonOptions comparison = options.comparison;
    if (comparison.threads == 0) comparison.threads = options.threads;
    out.comparison = compare_brdf(out.table, comparison);
    return out;
}

}  // namespace roughscope::image
