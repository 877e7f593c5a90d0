// Output of the calibration steps (serialize/calibration.hpp).
#include "roughscope/serialize/calibration.hpp"

#include <string>
#include <utility>
#include <vector>

#include "roughscope/core/numbers.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/serialize/text.hpp"

namespace roughscope::serialize {
namespace {

Json vector_json(const Eigen::Vector3d& v) {
    return Json::array({number(v.x()), number(v.y()), number(v.z())});
}

}  // namespace

Json to_json(const image::MirrorSphereLight& light, double circle_uncertainty_px) {
    Json j;
    j["method"] = "mirror_sphere";
    j["light"] = vector_json(light.light);
    j["theta_deg"] = number(light.theta_deg);
    j["phi_deg"] = number(light.phi_deg);
    j["angle_uncertainty_deg"] = number(light.angle_uncertainty_deg);
    Json h;
    h["x_px"] = number(light.highlight_x_px);
    h["y_px"] = number(light.highlight_y_px);
    h["rho"] = number(light.highlight_rho);
    h["uncertainty_px"] = number(light.highlight_uncertainty_px);
    h["normal"] = vector_json(light.normal);
    j["highlight"] = std::move(h);
    Json c;
    c["centre_x_px"] = number(light.circle.centre_x_px);
    c["centre_y_px"] = number(light.circle.centre_y_px);
    c["radius_px"] = number(light.circle.radius_px);
    c["uncertainty_px"] = number(circle_uncertainty_px);
    j["circle"] = std::move(c);
    Json p;
    p["disc"] = light.disc_pixels;
    p["highlight"] = light.highlight_pixels;
    p["saturated"] = light.saturated_pixels;
    j["pixels"] = std::move(p);
    j["blobs"] = light.blobs;
    j["background"] = number(light.background);
    j["peak"] = number(light.peak);
    j["threshold"] = number(light.threshold);
    j["warnings"] = light.warnings;
    return j;
}

std::string light_calibration_text(const image::MirrorSphereLight& light) {
    const Eigen::Vector3d& l = light.light;
    const auto fixed = [](double v, int decimals) { return format_fixed(v, decimals, "light"); };
    std::vector<std::pair<std::string, std::string>> items{
        {"light (x, y, z)", concat(fixed(l.x(), 5), ", ", fixed(l.y(), 5), ", ", fixed(l.z(), 5),
                                   "  (camera frame: x right, y up, z towards the camera)")},
        {"theta", concat(fixed(light.theta_deg, 2), " deg  (from the camera axis)")},
        {"phi", concat(fixed(light.phi_deg, 2), " deg  (from +x towards +y)")},
        {"direction",
         concat("± ", format_significant(light.angle_uncertainty_deg, 2, "uncertainty"),
                " deg  (standard uncertainty, k = 1)")},
        {"highlight",
         concat("x ", fixed(light.highlight_x_px, 2), " px, y ", fixed(light.highlight_y_px, 2),
                " px, ", std::to_string(light.highlight_pixels), " px (",
                std::to_string(light.saturated_pixels), " saturated), at ",
                fixed(light.highlight_rho, 3), " of the radius")},
        {"sphere", concat("centre ", fixed(light.circle.centre_x_px, 2), ", ",
                          fixed(light.circle.centre_y_px, 2), " px, radius ",
                          fixed(light.circle.radius_px, 2), " px")}};
    std::string out = key_value_lines(items);
    for (const std::string& w : light.warnings) out += concat("warning: ", w, "\n");
    return out;
}

}  // namespace roughscope::serialize
