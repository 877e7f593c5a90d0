// Synthetic captures for the roughness-map tests: simulation::render_capture brought to the
// linear scale of image/image.hpp by the camera's own formula (value = (DN − black)/(white −
// black), flags from the clipped pixels), without a file in between.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "roughscope/photo/image.hpp"
#include "roughscope/simulation/capture.hpp"

namespace roughscope::testing {

namespace sim = roughscope::simulation;

inline image::LinearImage to_linear(const sim::Capture& c, const sim::CameraModel& camera) {
    image::LinearImage im;
    im.width = c.width;
    im.height = c.height;
    im.channels = 1;
    im.values.resize(c.width * c.height);
    im.flags.assign(c.width * c.height, 0);
    const double black = camera.black_level_dn, white = camera.white_level_dn();
    for (std::size_t i = 0; i < im.values.size(); ++i) {
        im.values[i] = static_cast<float>((c.dn[i] - black) / (white - black));
        if (c.saturated[i] != 0 || c.dn[i] >= white) im.flags[i] |= image::kPixelSaturated;
        if (c.dn[i] <= black) im.flags[i] |= image::kPixelClippedLow;
    }
    im.info.source = "synthetic";
    return im;
}

inline sim::SurfaceTruth very_rough_truth(double sigma_over_T,
                                          Correlation correlation = Correlation::Gaussian) {
    sim::SurfaceTruth t;
    t.model = sim::BrightnessModel::VeryRough;
    t.sigma_um = sigma_over_T;
    t.T_um = 1.0;
    t.correlation = correlation;
    return t;
}

// A camera whose brightest expected pixel (over the truths at the two normal-view geometries)
// holds 70 % of a deep full well (16 bits, 2·10⁶ electrons: 0.07 % shot noise at full scale).
inline sim::CameraModel deep_camera(const std::vector<sim::SurfaceTruth>& truths,
                                    const std::vector<Geometry>& geoms, std::uint64_t seed,
                                    bool noise = true, double full_well_e = 2e6) {
    double peak = 0.0;
    for (const auto& t : truths)
        for (const auto& g : geoms) peak = std::max(peak, sim::surface_brightness(t, g));
    sim::CameraModel camera;
    camera.bit_depth = 16;
    camera.full_well_e = full_well_e;
    camera.black_level_dn = 0.0;
    camera.gain_dn_per_e = 1.02 * 65535.0 / full_well_e;
    camera.electrons_per_unit_s = 0.7 * full_well_e / peak;
    camera.read_noise_e = noise ? 3.0 : 0.0;
    camera.shot_noise = noise;
    camera.seed = seed;
    return camera;
}

struct LitPair {
    sim::Capture c1, c2;
    image::LinearImage a, b;
};

// A scene lit at θ1 and θ2 (azimuth π, paper frame), the camera along `view`.
inline LitPair render_lit_pair(sim::Scene scene, const std::vector<sim::SurfaceTruth>& truths,
                               const std::vector<std::int32_t>& labels1,
                               const std::vector<std::int32_t>& labels2, double theta1_rad,
                               double theta2_rad, std::uint64_t seed, bool noise = true,
                               bool keep_geometry = false) {
    const std::vector<Geometry> geoms{normal_view_geometry(theta1_rad),
                                      normal_view_geometry(theta2_rad)};
    const sim::CameraModel cam1 = deep_camera(truths, geoms, seed, noise);
    sim::CameraModel cam2 = cam1;
    cam2.seed = seed + 1000;
    sim::CaptureOptions options;
    options.keep_geometry = keep_geometry;
    options.threads = 1;
    LitPair p;
    scene.light = sim::direction_from_angles(theta1_rad, kPi);
    p.c1 = sim::render_capture(scene, truths, labels1, cam1, options);
    scene.light = sim::direction_from_angles(theta2_rad, kPi);
    p.c2 = sim::render_capture(scene, truths, labels2, cam2, options);
    p.a = to_linear(p.c1, cam1);
    p.b = to_linear(p.c2, cam2);
    return p;
}

}  // namespace roughscope::testing
