// JSON and text forms of the surface topic: the documents of `roughscope surface stats|predict
// --json` and the dicts of roughscope.surface_statistics / predict_brightness (keys in
// docs/cli.md, "surface"). Both front ends call these functions; neither derives a key.
// Optional quantities are null (never NaN), numbers are not rounded (serialize/json.hpp).
#pragma once

#include <cstddef>
#include <string>

#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/serialize/json.hpp"
#include "roughscope/surface/height_map.hpp"
#include "roughscope/surface/predict.hpp"
#include "roughscope/surface/statistics.hpp"

namespace roughscope::serialize {

// What the statistics were computed from: echoed at the top of the document.
struct StatisticsInput {
    std::string file;    // the height file ("" = arrays from Python: null)
    std::string format;  // its format name ("" = null)
    std::size_t nx = 0;
    std::size_t ny = 0;
    double dx_um = 1.0;
    double dy_um = 1.0;
    surface::StatisticsOptions options;
};
// The echo of `map` read from `file` in `format` (either may be "").
StatisticsInput statistics_input(const surface::HeightMap& map,
                                 const surface::StatisticsOptions& options,
                                 const std::string& file = "", const std::string& format = "");

// Keys, in order: file, format, nx, ny, dx_um, dy_um, leveling, polynomial_order (null unless
// polynomial levelling), cutoff_um, acf_estimator, points, sigma_um, sigma_stderr_um, Sa_um, Ssk,
// Sku, Sp_um, Sv_um, Sz_um, T_um, T_y_um, T_stderr_um, T_fit_gaussian_um, T_fit_exponential_um,
// correlation ("gaussian", "exponential" or null), T_extrapolated_um, Sal_um, Str, rms_slope,
// m_from_T, warnings; with `with_curves` also curves: {acf_x, acf_y, acf_radial: {lag_um, acf},
// psd_x, psd_radial: {frequency_per_um, psd}}.
Json to_json(const StatisticsInput& input, const surface::SurfaceStatistics& stats,
             bool with_curves = false);
// The same as aligned "name  value unit" lines for a person ("-" for an unknown value).
std::string to_text(const StatisticsInput& input, const surface::SurfaceStatistics& stats);

// Keys: source (a file name, or "given"), T_source (null for given values), sigma_um, T_um,
// correlation, wavelength_um, factor, radiometry, regime (as asked), sigma_over_T, rms_slope,
// theta_K_deg, xi_K, g_normal, roughness_class (of g_normal), points (each: theta_i_deg,
// theta_s_deg, phi_s_deg, the keys of to_json(ScatteredPower), very_rough_brightness,
// beyond_theta_K), warnings.
Json to_json(const surface::SurfacePrediction& prediction, const ModelOptions& options,
             const std::string& source = "given", const std::string& T_source = "");
std::string to_text(const surface::SurfacePrediction& prediction, const ModelOptions& options,
                    const std::string& source = "given");

// A summary of a height map: nx, ny, dx_um, dy_um, length_x_um, length_y_um, points (valid),
// missing, min_um, max_um, mean_um (null without valid points), title (null when empty).
Json summary_json(const surface::HeightMap& map);
// The heights for a figure, subsampled by a whole stride so neither side exceeds max_side:
// nx, ny, dx_um, dy_um (of the subsampled grid), stride, heights_um (rows of numbers, null =
// missing). InvalidArgument unless max_side >= 1.
Json height_image_json(const surface::HeightMap& map, std::size_t max_side = 512);

}  // namespace roughscope::serialize
