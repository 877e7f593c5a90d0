// JSON schema of a measurement from photographs (image/measure.hpp): the document of
// `roughscope measure --json` and the dict of roughscope.measure. Keys in docs/measure.md.
#pragma once

#include "roughscope/image/measure.hpp"
#include "roughscope/serialize/json.hpp"

namespace roughscope::serialize {

// format ("roughscope-measurement"), version, capture_file, then the headline values —
// E1_over_E2, sigma_over_T_gaussian, sigma_over_T_exponential, sigma_um, T_um (each with
// `_stderr`; null where the captures do not give them), rms_slope, theta_K_deg, xi_K,
// roughness_class, roughness_class_assumed —, then specular (per channel σ and the χ² of their
// agreement), slope_gaussian, slope_exponential, correlation_length, fit (the estimates in full),
// region, captures (per capture: file, geometry, exposure, response, region statistics, highlight)
// and warnings.
Json to_json(const image::MeasureResult& result, const image::MeasureRequest& request);

// The region statistics of one capture (also used for the highlight's core and annulus).
Json to_json(const image::RegionStatistics& statistics);

}  // namespace roughscope::serialize
