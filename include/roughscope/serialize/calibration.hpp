// Output of the calibration steps (objects/mirror_sphere.hpp: the light's direction from a mirror
// sphere): one JSON schema (keys in docs/calibration.md), shared by `roughscope calibrate light
// --json` and roughscope.calibrate_light, and the text report of the command.
#pragma once

#include <string>

#include "roughscope/objects/mirror_sphere.hpp"
#include "roughscope/serialize/json.hpp"

namespace roughscope::serialize {

// The light as a JSON object: method, light [x, y, z], theta_deg, phi_deg,
// angle_uncertainty_deg, highlight {x_px, y_px, rho, uncertainty_px, normal}, circle
// {centre_x_px, centre_y_px, radius_px, uncertainty_px}, pixels {disc, highlight, saturated},
// blobs, background, peak, threshold, warnings.
Json to_json(const image::MirrorSphereLight& light, double circle_uncertainty_px);

// The text report: the light vector, θ and φ, "± u deg", the highlight and the warnings.
std::string light_calibration_text(const image::MirrorSphereLight& light);

}  // namespace roughscope::serialize
