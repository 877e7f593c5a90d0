// JSON schema of a measurement from photographs (image/measure.hpp): the document of
// `roughscope measure --json` and the dict of roughscope.measure. Keys in docs/measure.md.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "roughscope/measure/measure.hpp"
#include "roughscope/serialize/json.hpp"

namespace roughscope::serialize {

// format ("roughscope-measurement"), version, capture_file, then the headline values —
// E1_over_E2, sigma_over_T_gaussian, sigma_over_T_exponential, sigma_um, T_um (each with
// `_stderr`; null where the captures do not give them), rms_slope, theta_K_deg, xi_K,
// roughness_class, roughness_class_assumed —, then specular (per channel σ and the χ² of their
// agreement), slope_gaussian, slope_exponential, correlation_length, fit (the estimates in full),
// region, captures (per capture: file, geometry, exposure, response, region statistics, highlight,
// and the photograph's ImageInfo as `info`) and warnings.
Json to_json(const image::MeasureResult& result, const image::MeasureRequest& request);

// The text report of `roughscope measure` (without --json): "key  value" lines of the headline
// values (each "value ± error", core/uncertainty.hpp), the object's, sphere's and map's
// summaries, then "warning: ..." lines; names from the capture file with their control
// characters escaped. measure_text takes the document to_json returns.
std::string to_text(const image::MeasureResult& result, const image::MeasureRequest& request);
std::string measure_text(const Json& document);

// A photograph's ImageInfo (photo/image.hpp; keys as its fields, docs/image.md "Metadata"):
// source, format, raw_format, bits_per_sample, is_float, white_level_dn, black_level_dn,
// response, gamma (null unless the response is gamma), file_response, file_response_evidence,
// exposure_s, f_number, iso (null where the file does not record them) and warnings. The one
// conversion: `info` of each capture in the measurement and of Python's read_image.
Json to_json(const image::ImageInfo& info);

// A cylinder's profile (§5.2, image/cylinder.hpp): axis, profile rows (theta_deg, brightness,
// stderr, ...), the fitted sigma_over_T_gaussian / _exponential with _stderr, the models with
// their predictions and departure_angle_deg, theta_K_deg.
Json to_json(const image::CylinderProfile& profile);
// A sphere (image/sphere.hpp): the circle, the table's size and the comparison of every model.
Json to_json(const image::SphereResult& sphere);
// A roughness map's summary (image/maps.hpp): size, registration, classes, regions (the layers
// are written as files by the CLI and returned as arrays by the Python module).
Json to_json(const image::RoughnessMap& map);

// The float layers the map made, by name ("sigma_over_T_gaussian", "sigma_over_T_gaussian_stderr",
// "sigma_over_T_exponential", "sigma_over_T_exponential_stderr" — of MapOptions::correlation,
// of both with both_correlations —, "E1_over_E2" with ratio_layer, and with σ known "T_um",
// "T_um_stderr"), NaN where missing; the class layers ("roughness_class", and with σ
// "roughness_class_g") as kClass* codes. The CLI writes these as files, the Python module returns
// them as arrays, under the same names.
struct MapLayer {
    std::string name;
    const image::MapLayerValues* values;
};
std::vector<MapLayer> map_float_layers(const image::RoughnessMap& map);
struct MapClassLayer {
    std::string name;
    const image::MapClassCodes* values;
};
std::vector<MapClassLayer> map_class_layers(const image::RoughnessMap& map);

// The region statistics of one capture (also used for the highlight's core and annulus).
Json to_json(const image::RegionStatistics& statistics);

}  // namespace roughscope::serialize
