#include "roughscope/objects/cylinder.hpp"

#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cylinder_steps.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/scattering/validity.hpp"

namespace roughscope::image {
namespace {

using check::format_number;

std::string image_name(const LinearImage& image) {
    return image.info.source.empty() ? std::string("image") : image.info.source;
}

}  // namespace

std::string_view to_string(CylinderHalf half) {
    switch (half) {
        case CylinderHalf::Right:
            return "right";
        case CylinderHalf::Left:
            return "left";
        case CylinderHalf::Both:
            return "both";
    }
    return "right";
}

CylinderHalf parse_cylinder_half(std::string_view name) {
    if (name == "right") return CylinderHalf::Right;
    if (name == "left") return CylinderHalf::Left;
    if (name == "both") return CylinderHalf::Both;
    throw InvalidArgument(
        concat("unknown cylinder half ", quote_input(name), " (valid: right, left, both)"));
}

std::string_view to_string(ProfileModel model) {
    switch (model) {
        case ProfileModel::Lambert:
            return "lambert";
        case ProfileModel::BkGaussian:
            return "bk_gaussian";
        case ProfileModel::VhGaussian:
            return "vh_gaussian";
        case ProfileModel::VhExponential:
            return "vh_exponential";
    }
    return "lambert";
}

std::string_view display_name(ProfileModel model) {
    switch (model) {
        case ProfileModel::Lambert:
            return "Lambert";
        case ProfileModel::BkGaussian:
            return "Eq. 7 B–K(G)";
        case ProfileModel::VhGaussian:
            return "Eq. 9 V–H–B–K(G)";
        case ProfileModel::VhExponential:
            return "Eq. 10 V–H–B–K(E)";
    }
    return "Lambert";
}

ProfileModel parse_profile_model(std::string_view name) {
    for (const ProfileModel m : kProfileModels)
        if (name == to_string(m)) return m;
    throw InvalidArgument(concat("unknown profile model ", quote_input(name),
                                 " (valid: lambert, bk_gaussian, vh_gaussian, vh_exponential)"));
}

double profile_model_brightness(ProfileModel model, const Geometry& geom, double sigma_over_T,
                                Radiometry radiometry) {
    switch (model) {
        case ProfileModel::Lambert:  // Lambert's law: E ∝ cos θi
            check::geometry(geom);
            return std::cos(geom.theta_i_rad);
        case ProfileModel::BkGaussian:  // Eq. 7 (general form Eq. 4, F_Beck)
            return very_rough_brightness(geom, sigma_over_T, Correlation::Gaussian,
                                         GeometricFactor::Beckmann, radiometry);
        case ProfileModel::VhGaussian:  // Eq. 9 (general form Eq. 4, F_VH)
            return very_rough_brightness(geom, sigma_over_T, Correlation::Gaussian,
                                         GeometricFactor::VernoldHarvey, radiometry);
        case ProfileModel::VhExponential:  // Eq. 10 (general form Eq. 5, F_VH)
            return very_rough_brightness(geom, sigma_over_T, Correlation::Exponential,
                                         GeometricFactor::VernoldHarvey, radiometry);
    }
    return 0.0;
}

const ProfileModelCurve& CylinderProfile::curve(ProfileModel model) const {
    for (const ProfileModelCurve& c : models)
        if (c.model == model) return c;
    throw InvalidArgument(concat("the profile has no curve ", to_string(model)));
}

void check_cylinder_options(const CylinderOptions& options) {
    detail::check_unit_direction("cylinder light", options.light);
    detail::check_unit_direction("cylinder view", options.view);
    if (!(options.bin_width_deg > 0.0 && options.bin_width_deg <= 45.0))
        throw InvalidArgument(
            concat("cylinder bin_width_deg = ", format_number(options.bin_width_deg),
                   " is outside the valid range (0, 45] deg"));
    if (options.min_pixels_per_bin < 1)
        throw InvalidArgument("cylinder min_pixels_per_bin must be at least 1");
    if (!(options.limb_fraction > 0.0 && options.limb_fraction <= 1.0))
        throw InvalidArgument(
            concat("cylinder limb_fraction = ", format_number(options.limb_fraction),
                   " is outside the valid range (0, 1]"));
    if (options.sigma_over_T) check::positive("cylinder sigma_over_T", *options.sigma_over_T);
    if (!(options.fit_max_theta_i_deg > 0.0 && options.fit_max_theta_i_deg < 90.0))
        throw InvalidArgument(
            concat("cylinder fit_max_theta_i_deg = ", format_number(options.fit_max_theta_i_deg),
                   " is outside the valid range (0, 90) deg"));
    if (!(options.fit_max_flagged_fraction >= 0.0 && options.fit_max_flagged_fraction <= 1.0))
        throw InvalidArgument(concat(
            "cylinder fit_max_flagged_fraction = ", format_number(options.fit_max_flagged_fraction),
            " is outside the valid range [0, 1]"));
    check::positive("cylinder departure_k", options.departure_k);
    if (options.departure_bins < 1)
        throw InvalidArgument("cylinder departure_bins must be at least 1");
    if (options.axis) {
        const CylinderAxis& a = *options.axis;
        (void)cylinder_axis_from_line(a.point_x_px, a.point_y_px, a.direction_x, a.direction_y,
                                      a.radius_px);
    }
}

// The steps of cylinder_steps.hpp in order: where the cylinder is, its bins, the scan over the
// pixels, the bins' brightness against incidence angle, the σ/T fits, each model's curve and
// departure, Caron's θK and the dark-limb check.
CylinderProfile measure_cylinder_profile(const LinearImage& image,
                                         const std::vector<std::uint8_t>* region_mask,
                                         const CylinderOptions& options) {
    check_cylinder_options(options);
    // The values: read and checked by the silhouette's pass, or here when there is none.
    check_linear_image_layout(image);
    if (region_mask && region_mask->size() != image.pixel_count())
        throw InvalidArgument(concat("cylinder region mask has ",
                                     std::to_string(region_mask->size()), " entries, the image ",
                                     image_name(image), " has ",
                                     std::to_string(image.pixel_count()), " pixels"));
    CylinderProfile out;
    out.light = options.light;
    out.view = options.view;
    out.half = options.half;
    out.bin_width_rad = deg_to_rad(options.bin_width_deg);

    const detail::CylinderLocation where = detail::locate_cylinder(image, options);
    out.axis = where.axis;
    const detail::CylinderBinning binning =
        detail::bin_cylinder(out.axis, options, image.width, image.height);
    const detail::CylinderSums sums =
        detail::scan_cylinder(image, region_mask ? region_mask->data() : nullptr, binning,
                              where.object_rows, options.threads);
    out.pixels_flagged = sums.pixels_flagged;
    detail::CylinderBins bins = detail::profile_bins(sums, binning, options, image_name(image));
    out.maximum = bins.maximum;
    out.pixels_used = bins.pixels_used;
    out.warnings = std::move(bins.warnings);
    out.bins = bins.bins;

    const detail::CylinderFits fits = detail::fit_cylinder_profile(bins, options);
    out.gaussian_fit = fits.gaussian;
    out.exponential_fit = fits.exponential;
    out.preferred = fits.preferred;

    // The curves: every B–K curve at the given σ/T, else Eq. 7 and 9 at the fitted V–H Gaussian
    // σ/T and Eq. 10 at the fitted V–H exponential σ/T.
    for (const ProfileModel m : kProfileModels) {
        std::optional<double> sigma_over_T;
        if (m != ProfileModel::Lambert) {
            sigma_over_T = options.sigma_over_T               ? options.sigma_over_T
                           : m == ProfileModel::VhExponential ? out.exponential_fit.sigma_over_T
                                                              : out.gaussian_fit.sigma_over_T;
            if (!sigma_over_T) {
                out.warnings.push_back(
                    concat("no ", to_string(m), " curve: the fit of its σ/T did not succeed"));
                ProfileModelCurve none;
                none.model = m;
                none.name = std::string(to_string(m));
                out.models.push_back(std::move(none));
                continue;
            }
        }
        out.models.push_back(detail::profile_curve(m, sigma_over_T, bins, options));
    }
    if (const auto& s = out.curve(ProfileModel::VhGaussian).sigma_over_T)
        out.theta_K_rad = caron_theta_K_rad(*s);
    if (out.axis.detected)
        if (auto warning = detail::dark_limb_warning(out.bins, out.maximum, where.silhouette_level))
            out.warnings.push_back(std::move(*warning));
    return out;
}

}  // namespace roughscope::image
