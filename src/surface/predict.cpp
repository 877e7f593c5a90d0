// The bridge from height statistics to the scattering models (surface/predict.hpp).
#include "roughscope/surface/predict.hpp"

#include <cmath>
#include <string>
#include <utility>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/scattering/factors.hpp"

namespace roughscope::surface {

SurfaceFromStatistics surface_from_statistics(const SurfaceStatistics& stats,
                                              std::optional<Correlation> correlation) {
    if (!(std::isfinite(stats.sigma_um) && stats.sigma_um > 0.0))
        throw InvalidArgument(
            std::isfinite(stats.sigma_um)
                ? "the height statistics have sigma = " +
                      format_significant(stats.sigma_um, 6, "sigma_um") +
                      " um: a flat surface (sigma > 0 required) scatters no diffuse light"
                : std::string("the height statistics have a sigma that is not finite"));
    SurfaceFromStatistics out;
    out.surface.sigma_um = stats.sigma_um;
    if (correlation) {
        out.surface.correlation = *correlation;
    } else if (stats.correlation) {
        out.surface.correlation = *stats.correlation;
    } else {
        out.surface.correlation = Correlation::Gaussian;
        out.correlation_assumed = true;
        out.warnings.emplace_back(
            "the height statistics name no correlation function (neither fit succeeded): "
            "Gaussian assumed");
    }
    const std::optional<double> fitted = stats.fitted_T_um(out.surface.correlation);
    if (stats.T_um && std::isfinite(*stats.T_um) && *stats.T_um > 0.0) {
        out.surface.T_um = *stats.T_um;
        out.T_source = "T_um";
    } else if (fitted && std::isfinite(*fitted) && *fitted > 0.0) {
        out.surface.T_um = *fitted;
        out.T_source = "T_fit_";
        out.T_source.append(to_string(out.surface.correlation)).append("_um");
        out.warnings.emplace_back("the ACF does not fall to 1/e within the map: T from the " +
                                  std::string(to_string(out.surface.correlation)) + " fit");
    } else {
        throw InvalidArgument(
            "the height statistics have no correlation length T (the ACF does not fall to 1/e "
            "within the map and no fit succeeded): give a longer map or sigma and T directly");
    }
    for (const auto& [period, axis] :
         {std::pair{stats.period_um, "x"}, std::pair{stats.period_y_um, "y"}})
        if (period)
            out.warnings.push_back(
                "the height statistics show a periodic component along " + std::string(axis) +
                " (period " + format_significant(*period, 3) +
                " um): the model assumes a random rough surface; a periodic one also diffracts "
                "light into orders the prediction leaves out");
    return out;
}

SurfacePrediction predict_brightness(const Surface& surface,
                                     const std::vector<Geometry>& geometries,
                                     const ModelOptions& options) {
    check_length_um("sigma", surface.sigma_um);
    check_length_um("T", surface.T_um);
    check_length_um("wavelength", options.wavelength_um);
    SurfacePrediction out;
    out.surface = surface;
    out.wavelength_um = options.wavelength_um;
    out.sigma_over_T = surface.sigma_um / surface.T_um;
    out.rms_slope = rms_slope(out.sigma_over_T);
    out.theta_K_rad = caron_theta_K_rad(out.sigma_over_T);
    out.xi_K = caron_xi_K(out.sigma_over_T);
    // §3.1: g = σ² v_z², v_z = −k (cos θi + cos θs) = −2k at normal incidence and view.
    out.g_normal = roughness_g(Geometry{}, surface.sigma_um, options.wavelength_um);
    out.roughness_class = roughness_class(out.g_normal);
    out.points.reserve(geometries.size());
    bool beyond = false;
    for (std::size_t i = 0; i < geometries.size(); ++i) {
        const Geometry& geom = geometries[i];
        check::geometry(geom, "geometry " + std::to_string(i + 1));
        PredictedBrightness p;
        p.geometry = geom;
        p.power = mean_scattered_power(geom, surface, options);
        p.very_rough_brightness = very_rough_brightness(geom, out.sigma_over_T, surface.correlation,
                                                        options.factor, options.radiometry);
        p.beyond_theta_K = geom.theta_i_rad > out.theta_K_rad;
        beyond = beyond || p.beyond_theta_K;
        out.points.push_back(p);
    }
    if (beyond)
        out.warnings.push_back("theta_i above Caron's theta_K = " +
                               format_significant(rad_to_deg(out.theta_K_rad), 4, "theta_K") +
                               " deg at some geometries: shadowing makes the model invalid there "
                               "(section 3.5)");
    return out;
}

SurfacePrediction predict_brightness(const SurfaceStatistics& stats,
                                     const std::vector<Geometry>& geometries,
                                     const ModelOptions& options,
                                     std::optional<Correlation> correlation) {
    SurfaceFromStatistics from = surface_from_statistics(stats, correlation);
    SurfacePrediction out = predict_brightness(from.surface, geometries, options);
    from.warnings.insert(from.warnings.end(), out.warnings.begin(), out.warnings.end());
    out.warnings = std::move(from.warnings);
    return out;
}

}  // namespace roughscope::surface
