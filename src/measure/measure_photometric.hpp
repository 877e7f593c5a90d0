// The photometric-stereo path of measure() (ObjectShape::PhotometricStereo, measure.hpp).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "roughscope/measure/measure.hpp"

namespace roughscope::image::detail {

// Refuses (through `refuse(key, reason)`) a request photometric stereo cannot solve: fewer than
// 3 (4 for a rough model) captures, a specular capture, a capture without a light, "maps" without
// regions (the normals are the map; its regions and class thresholds are what it uses).
void check_photometric_stereo_request(
    const MeasureRequest& request,
    const std::function<void(std::string_view, const std::string&)>& refuse);

// Solves for the normals from the decoded captures (one per capture, in order), the lights of
// the captures and their exposure scales as the light intensities, on the roi's mask (empty: the
// whole image), into result.photometric_stereo and result.photometric_lights; with region labels
// (the maps' regions, −1 outside) their statistics and comparisons.
void measure_photometric_stereo(const MeasureRequest& request,
                                const std::vector<std::uint8_t>& mask,
                                const std::vector<LinearImage>& images,
                                const std::vector<std::int32_t>& region_labels,
                                MeasureResult& result);

}  // namespace roughscope::image::detail
