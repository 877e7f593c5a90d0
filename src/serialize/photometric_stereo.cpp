// Output of photometric stereo (serialize/photometric_stereo.hpp).
#include "roughscope/serialize/photometric_stereo.hpp"

#include <string>
#include <utility>

#include "roughscope/serialize/json.hpp"

namespace roughscope::serialize {

Json to_json(const image::PhotometricStereoResult& result,
             const std::vector<Eigen::Vector3d>& lights) {
    Json j;
    j["model"] = std::string(image::to_string(result.model));
    Json l = Json::array();
    for (const Eigen::Vector3d& v : lights)
        l.push_back(Json::array({number(v.x()), number(v.y()), number(v.z())}));
    j["lights"] = std::move(l);
    Json pixels;
    pixels["object"] = result.object_pixels;
    pixels["valid"] = result.valid_pixels;
    pixels["too_few_lights"] = result.too_few_lights;
    pixels["no_solution"] = result.no_solution;
    j["pixels"] = std::move(pixels);
    j["highlights_removed"] = result.highlights_removed;
    j["median_residual"] = number(result.median_residual);
    if (result.model != image::PhotometricModel::Lambert) {
        j["median_sigma_over_T"] = number(result.median_sigma_over_T);
        Json aic;
        aic["compared_pixels"] = result.compared_pixels;
        aic["rough_better_pixels"] = result.rough_better_pixels;
        aic["median_delta_aic"] = number(result.median_delta_aic);
        j["model_comparison"] = std::move(aic);
    }
    j["warnings"] = result.warnings;
    return j;
}

}  // namespace roughscope::serialize
