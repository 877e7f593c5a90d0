// The photometric-stereo path of measure() (measure_photometric.hpp).
#include "measure_photometric.hpp"

#include <cstddef>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"

namespace roughscope::image::detail {

void check_photometric_stereo_request(
    const MeasureRequest& request,
    const std::function<void(std::string_view, const std::string&)>& refuse) {
    if (request.captures.size() < 3)
        refuse("captures", concat("photometric stereo needs at least 3 captures (one per light); "
                                  "got ",
                                  std::to_string(request.captures.size())));
    const bool rough = request.object.photometric_stereo.model != PhotometricModel::Lambert;
    if (rough && request.captures.size() < 4)
        refuse("captures",
               concat("the rough model ", to_string(request.object.photometric_stereo.model),
                      " fits a normal, an albedo and σ/T per pixel: it needs at least 4 "
                      "captures; got ",
                      std::to_string(request.captures.size())));
    for (std::size_t k = 0; k < request.captures.size(); ++k) {
        const CaptureSpec& c = request.captures[k];
        const std::string key = concat("captures[", std::to_string(k), "]");
        if (c.role != CaptureRole::Diffuse)
            refuse(key, "photometric stereo takes diffuse captures only (role \"diffuse\")");
        if (!c.light)
            refuse(key,
                   "photometric stereo needs each capture's light direction (\"light\", "
                   "camera frame)");
    }
    if (request.maps && request.maps->regions.empty())
        refuse("maps",
               "photometric stereo gives per-pixel maps itself (normals, albedo, σ/T; --maps "
               "DIR): \"maps\" is for its \"regions\"; give them or leave \"maps\" out");
    check_photometric_stereo_options(request.object.photometric_stereo, request.captures.size());
}

void measure_photometric_stereo(const MeasureRequest& request,
                                const std::vector<std::uint8_t>& mask,
                                const std::vector<LinearImage>& images,
                                const std::vector<std::int32_t>& region_labels,
                                MeasureResult& result) {
    PhotometricStereoOptions options = request.object.photometric_stereo;
    options.light_intensities.clear();
    std::vector<const LinearImage*> pointers;
    for (std::size_t k = 0; k < images.size(); ++k) {
        const CaptureMeasurement& c = result.captures[k];
        result.photometric_lights.push_back(*c.spec.light);
        // Values are ρ B e_j with e_j the exposure scale s_k (measure.hpp).
        options.light_intensities.push_back(c.exposure_scale);
        pointers.push_back(&images[k]);
    }
    const std::string src = request.source.empty() ? std::string("measure") : request.source;
    try {
        result.photometric_stereo =
            photometric_stereo(pointers, result.photometric_lights, mask, options);
    } catch (const InvalidArgument& e) {
        if (request.source.empty()) throw;
        throw DataError(concat(src, ": object: ", e.what()));
    }
    for (const std::string& w : result.photometric_stereo->warnings)
        result.warnings.push_back(concat("photometric stereo: ", w));
    if (region_labels.empty() || !request.maps) return;
    std::vector<std::string> names;
    for (const auto& r : request.maps->regions) names.push_back(r.first);
    const MapOptions& o = request.maps->options;
    result.photometric_regions = photometric_region_statistics(
        *result.photometric_stereo, region_labels, names, o.slightly_rough_max_sigma_over_T,
        o.very_rough_min_sigma_over_T);
    result.photometric_comparisons = compare_photometric_regions(result.photometric_regions);
}

}  // namespace roughscope::image::detail
