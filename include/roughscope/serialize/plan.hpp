// Output of capture planning (measure/plan.hpp): one JSON schema (keys in docs/uncertainty.md
// "Planning a capture"), shared by `roughscope plan --json` and roughscope.plan_capture, and the
// text report of the command.
#pragma once

#include <string>

#include "roughscope/measure/plan.hpp"
#include "roughscope/serialize/json.hpp"

namespace roughscope::serialize {

// The plan as a JSON object: correlation, factor, sigma_over_T, sigma_over_T_max,
// sigma_over_T_points, exposure, fill, noise_rel, tolerances {angle_deg, exposure_rel,
// black_level_rel}, assumed, grid {theta_min_deg, theta_max_deg, theta_step_deg,
// min_difference_deg, pairs, pairs_with_value}, recommended, paper_30_45 (pairs), top (pairs,
// first order), warnings. A pair: theta1_deg, theta2_deg, has_value, reason, sigma_over_T,
// E1_over_E2, sigma_over_T_uncertainty, sigma_over_T_relative_uncertainty,
// sigma_over_T_interval95 [low, high], method, budget [{source, u_input, sensitivity,
// contribution, fraction}].
Json to_json(const image::CapturePlan& plan);

// The text report: the recommended θ1/θ2 and "σ/T 0.800 ± 0.012 (k=1, 95 % [0.776, 0.824])",
// the same for 30°/45°, the largest source, the top pairs and the warnings.
std::string plan_text(const image::CapturePlan& plan);

}  // namespace roughscope::serialize
