// Synthetic captures for the roughness-map and measurement tests: simulation::render_capture
// brought to the linear scale of image/image.hpp by the camera's own formula (value = (DN −
// black)/(white − black), flags from the clipped pixels), without a file in between; and pairs
// written as 16-bit TIFFs for the measurement's capture files.
#pragma once

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "roughscope/core/text.hpp"
#include "roughscope/io/output_file.hpp"
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

// ---------------------------------------------------------------------------------------------
// Pairs written as files (a capture file names them)

inline constexpr double kFileCameraFullWell = 60000.0;

// A 16-bit linear camera (black 0) whose brightest pixel, of brightness `peak`, fills 60 % of
// the full well.
inline sim::CameraModel linear_camera(double peak, std::uint64_t seed, bool noise = true) {
    sim::CameraModel c;
    c.bit_depth = 16;
    c.full_well_e = kFileCameraFullWell;
    c.gain_dn_per_e = 1.05 * 65535.0 / kFileCameraFullWell;
    c.black_level_dn = 0.0;
    c.electrons_per_unit_s = 0.6 * kFileCameraFullWell / peak;
    c.exposure_s = 1.0;
    c.shot_noise = noise;
    c.read_noise_e = noise ? 3.0 : 0.0;
    c.seed = seed;
    return c;
}

inline double peak_brightness(const sim::Scene& scene, const sim::SurfaceTruth& truth) {
    sim::CameraModel c;
    c.shot_noise = false;
    const sim::Capture probe = sim::render_capture(scene, {truth}, {}, c);
    double peak = 0.0;
    for (const float v : probe.radiance) peak = std::max(peak, static_cast<double>(v));
    return peak;
}

struct Rendered {
    std::filesystem::path file;
    sim::Capture capture;
};

// Two 16-bit TIFFs of the scene lit from l1 (truth t1) and from l2 (truth t2), by one camera
// whose brightest pixel of the two fills 60 % of the full well (exposure 1 s each).
inline std::pair<Rendered, Rendered> render_pair(const std::filesystem::path& dir, sim::Scene scene,
                                                 const Eigen::Vector3d& l1,
                                                 const Eigen::Vector3d& l2,
                                                 const sim::SurfaceTruth& t1,
                                                 const sim::SurfaceTruth& t2, std::uint64_t seed,
                                                 bool noise = true) {
    scene.light = l1;
    double peak = peak_brightness(scene, t1);
    scene.light = l2;
    peak = std::max(peak, peak_brightness(scene, t2));
    sim::CaptureOptions options;
    options.threads = 1;
    std::pair<Rendered, Rendered> out;
    int k = 0;
    for (auto [r, light, truth] :
         {std::tuple{&out.first, l1, &t1}, std::tuple{&out.second, l2, &t2}}) {
        scene.light = light;
        r->capture =
            sim::render_capture(scene, {*truth}, {}, linear_camera(peak, seed + k, noise), options);
        r->file = dir / concat("c", std::to_string(k), ".tiff");
        io::write_file_atomic(r->file, sim::encode_capture_tiff(r->capture));
        ++k;
    }
    return out;
}

// The light at polar angle θ (degrees) on the paper's light azimuth π.
inline Eigen::Vector3d light_at(double theta_deg) {
    return sim::direction_from_angles(deg_to_rad(theta_deg), kPi);
}

}  // namespace roughscope::testing
