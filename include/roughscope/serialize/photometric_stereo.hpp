// Output of photometric stereo (objects/photometric_stereo.hpp): the summary of a solution as one
// JSON object (keys in docs/photometric-stereo.md), shared by the CLI and roughscope.
// photometric_stereo (which adds the per-pixel arrays).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "roughscope/objects/photometric_stereo.hpp"
#include "roughscope/serialize/json.hpp"

namespace roughscope::serialize {

// model ("lambert", "vh_gaussian", "vh_exponential"), lights [[x, y, z], ...], pixels {object,
// valid, too_few_lights, no_solution}, highlights_removed, median_residual (null when no pixel has
// one); the rough models also median_sigma_over_T and model_comparison {compared_pixels,
// rough_better_pixels, median_delta_aic}; warnings.
Json to_json(const image::PhotometricStereoResult& result,
             const std::vector<Eigen::Vector3d>& lights);

}  // namespace roughscope::serialize
