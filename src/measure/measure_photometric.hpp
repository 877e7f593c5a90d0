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
// 3 captures, a specular capture, a capture without a light, maps asked for (the normals are the
// map), a black reference or dark frame are fine.
void check_photometric_stereo_request(
    const MeasureRequest& request,
    const std::function<void(std::string_view, const std::string&)>& refuse);

// Solves for the normals from the decoded captures (one per capture, in order), the lights of
// the captures and their exposure scales as the light intensities, on the roi's mask (empty: the
// whole image), into result.photometric_stereo and result.photometric_lights.
void measure_photometric_stereo(const MeasureRequest& request,
                                const std::vector<std::uint8_t>& mask,
                                const std::vector<LinearImage>& images, MeasureResult& result);

}  // namespace roughscope::image::detail
