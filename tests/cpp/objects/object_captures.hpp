// Synthetic photographs of cylinders and spheres for the curved-object tests: a rendered capture
// (simulation/capture.hpp) brought to the linear scale the way the image reader does it
// (docs/image.md: (DN − black)/(white − black), saturated and code-0 pixels flagged), and small
// image helpers.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "roughscope/photo/image.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/simulation/capture.hpp"

namespace roughscope::testing {

namespace sim = roughscope::simulation;

// The capture's quantised pixels on the linear scale.
inline image::LinearImage linear_from_capture(const sim::Capture& capture,
                                              const sim::CameraModel& camera) {
    image::LinearImage img;
    img.width = capture.width;
    img.height = capture.height;
    img.channels = 1;
    img.values.resize(capture.dn.size());
    img.flags.assign(capture.dn.size(), 0);
    const double white = camera.white_level_dn(), black = camera.black_level_dn;
    for (std::size_t i = 0; i < capture.dn.size(); ++i) {
        img.values[i] = static_cast<float>((capture.dn[i] - black) / (white - black));
        if (capture.saturated[i]) img.flags[i] |= image::kPixelSaturated;
        if (capture.dn[i] == 0) img.flags[i] |= image::kPixelClippedLow;
    }
    img.info.source = "synthetic";
    return img;
}

// The capture's noise-free model brightness itself (no camera).
inline image::LinearImage linear_from_radiance(const sim::Capture& capture) {
    image::LinearImage img;
    img.width = capture.width;
    img.height = capture.height;
    img.channels = 1;
    img.values.assign(capture.radiance.begin(), capture.radiance.end());
    img.flags.assign(capture.radiance.size(), 0);
    img.info.source = "synthetic";
    return img;
}

inline image::LinearImage transposed(const image::LinearImage& in) {
    image::LinearImage out = in;
    out.width = in.height;
    out.height = in.width;
    for (std::size_t r = 0; r < in.height; ++r)
        for (std::size_t c = 0; c < in.width; ++c) {
            out.values[c * out.width + r] = in.values[r * in.width + c];
            out.flags[c * out.width + r] = in.flags[r * in.width + c];
        }
    return out;
}

// The sub-image [c0, c0 + w) × [r0, r0 + h).
inline image::LinearImage cropped(const image::LinearImage& in, std::size_t c0, std::size_t r0,
                                  std::size_t w, std::size_t h) {
    image::LinearImage out;
    out.width = w;
    out.height = h;
    out.channels = 1;
    out.info = in.info;
    for (std::size_t r = r0; r < r0 + h; ++r)
        for (std::size_t c = c0; c < c0 + w; ++c) {
            out.values.push_back(in.values[r * in.width + c]);
            out.flags.push_back(in.flags[r * in.width + c]);
        }
    return out;
}

inline sim::SurfaceTruth very_rough_truth(double sigma_over_T, Correlation correlation) {
    sim::SurfaceTruth truth;
    truth.model = sim::BrightnessModel::VeryRough;
    truth.sigma_um = sigma_over_T;
    truth.T_um = 1.0;
    truth.correlation = correlation;
    return truth;
}

// A camera whose full well is the white level and whose brightest object pixel (brightness
// e_max) collects `fill` of the full well.
inline sim::CameraModel camera_for(int bits, double e_max, double fill, std::uint64_t seed,
                                   bool noise = true) {
    sim::CameraModel camera;
    camera.bit_depth = bits;
    camera.full_well_e = 60000.0;
    camera.gain_dn_per_e = camera.white_level_dn() / camera.full_well_e;
    camera.black_level_dn = std::round(0.01 * camera.white_level_dn());
    camera.electrons_per_unit_s = fill * camera.full_well_e / e_max;
    camera.exposure_s = 1.0;
    camera.read_noise_e = noise ? 3.0 : 0.0;
    camera.shot_noise = noise;
    camera.seed = seed;
    return camera;
}

// The largest model brightness over the lit object (scan of the capture's radiance).
inline double max_radiance(const sim::Capture& capture) {
    return *std::max_element(capture.radiance.begin(), capture.radiance.end());
}

}  // namespace roughscope::testing
