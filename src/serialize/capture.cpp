// The sidecar of a synthetic capture and its files (serialize/capture.hpp).
#include "roughscope/serialize/capture.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/io/output_file.hpp"
#include "roughscope/scattering/factors.hpp"
#include "roughscope/version.hpp"

namespace roughscope::serialize {

namespace {

using simulation::BrightnessModel;
using simulation::Response;

Json vector3(const Eigen::Vector3d& v) {
    return Json::array({number(v.x()), number(v.y()), number(v.z())});
}

// A direction with its polar angle from Z and azimuth from X (degrees).
Json direction(const Eigen::Vector3d& v) {
    Json out;
    out["x"] = number(v.x());
    out["y"] = number(v.y());
    out["z"] = number(v.z());
    out["theta_deg"] = degrees(std::atan2(std::hypot(v.x(), v.y()), v.z()));
    const double phi = std::hypot(v.x(), v.y()) > 0.0 ? std::atan2(v.y(), v.x()) : 0.0;
    out["phi_deg"] = degrees(phi < 0.0 ? phi + 2.0 * kPi : phi);
    return out;
}

Json region(const simulation::SurfaceTruth& t, std::size_t label, const simulation::Capture& c,
            bool whole_object) {
    Json out;
    out["label"] = label;
    out["model"] = std::string(simulation::to_string(t.model));
    out["sigma_um"] = number(t.sigma_um);
    out["T_um"] = number(t.T_um);
    out["sigma_over_T"] = number(t.sigma_over_T());
    out["correlation"] = std::string(to_string(t.correlation));
    out["factor"] = std::string(to_string(t.factor));
    out["radiometry"] = std::string(to_string(t.radiometry));
    out["wavelength_um"] = t.model == BrightnessModel::MeanScatteredPower
                               ? number(t.model_options.wavelength_um)
                               : Json(nullptr);
    const bool on = t.model == BrightnessModel::OrenNayar;
    out["oren_nayar_sigma_deg"] = on ? degrees(t.oren_nayar.sigma_rad) : Json(nullptr);
    out["oren_nayar_albedo"] = on ? number(t.oren_nayar.albedo) : Json(nullptr);
    out["lafortune_n"] =
        t.model == BrightnessModel::Lafortune ? number(t.lafortune_n) : Json(nullptr);
    // Pixels of this region and their bounding box (from the per-pixel labels when kept).
    std::size_t pixels = 0;
    std::size_t c0 = c.width, r0 = c.height, c1 = 0, r1 = 0;
    if (!c.label.empty()) {
        for (std::size_t i = 0; i < c.label.size(); ++i) {
            if (c.label[i] != static_cast<std::int32_t>(label)) continue;
            ++pixels;
            const std::size_t col = i % c.width, row = i / c.width;
            c0 = std::min(c0, col);
            c1 = std::max(c1, col);
            r0 = std::min(r0, row);
            r1 = std::max(r1, row);
        }
        out["pixels"] = pixels;
    } else {
        out["pixels"] = whole_object ? Json(c.object_count) : Json(nullptr);
    }
    out["bbox"] = pixels > 0 ? Json::array({c0, r0, c1, r1}) : Json(nullptr);
    return out;
}

}  // namespace

Json capture_sidecar(const simulation::Capture& capture, const CaptureRecord& record,
                     simulation::CaptureFormat format, const std::string& image_file,
                     const std::string& sidecar_file) {
    const simulation::Scene& s = record.scene;
    const simulation::CameraModel& cam = record.camera;
    Json doc;
    doc[kVersionKey] = ROUGHSCOPE_VERSION_STRING;
    doc["format"] = "roughscope-capture";
    doc["version"] = 1;
    Json files;
    files["image"] = image_file;
    files["format"] = std::string(simulation::to_string(format));
    files["sidecar"] = sidecar_file;
    doc["files"] = image_file.empty() ? Json(nullptr) : files;

    Json scene;
    scene["shape"] = std::string(simulation::to_string(s.shape));
    scene["width"] = s.width;
    scene["height"] = s.height;
    scene["pixel_size_um"] = number(s.pixel_size_um);
    scene["radius_um"] = s.shape == simulation::SceneShape::Plane
                             ? Json(nullptr)
                             : number(simulation::scene_radius_um(s));
    scene["light"] = direction(s.light);
    scene["view"] = direction(s.view);
    const simulation::CameraAxes axes = simulation::camera_axes(s.view);
    scene["image_right"] = vector3(axes.right);
    scene["image_up"] = vector3(axes.up);
    scene["background_radiance"] = number(s.background_radiance);
    doc["scene"] = scene;

    Json regions = Json::array();
    for (std::size_t k = 0; k < record.truths.size(); ++k)
        regions.push_back(region(record.truths[k], k, capture, record.labels.empty()));
    Json truth;
    truth["regions"] = regions;
    doc["truth"] = truth;

    Json camera;
    camera["electrons_per_unit_s"] = number(cam.electrons_per_unit_s);
    camera["exposure_s"] = number(cam.exposure_s);
    camera["gain_dn_per_e"] = number(cam.gain_dn_per_e);
    camera["full_well_e"] = number(cam.full_well_e);
    camera["black_level_dn"] = number(cam.black_level_dn);
    camera["white_level_dn"] = number(cam.white_level_dn());
    camera["read_noise_e"] = number(cam.read_noise_e);
    camera["bit_depth"] = cam.bit_depth;
    camera["response"] = std::string(simulation::to_string(cam.response));
    camera["gamma"] = cam.response == Response::Gamma ? number(cam.gamma) : Json(nullptr);
    camera["vignetting"] = number(cam.vignetting);
    camera["shot_noise"] = cam.shot_noise;
    camera["seed"] = cam.seed;
    doc["camera"] = camera;

    Json stats;
    stats["object_pixels"] = capture.object_count;
    stats["saturated_pixels"] = capture.saturated_count;
    stats["background_pixels"] = capture.width * capture.height - capture.object_count;
    doc["statistics"] = stats;
    doc["documentation"] = "docs/simulation-captures.md";
    return doc;
}

CaptureFiles write_capture_files(const simulation::Capture& capture, const CaptureRecord& record,
                                 simulation::CaptureFormat format, const std::filesystem::path& dir,
                                 const std::string& stem) {
    const std::string image_name = concat(stem, ".", simulation::file_extension(format));
    const std::string sidecar_name = concat(stem, ".json");
    // Everything that can fail on the input first, then the two writes.
    const std::string image = simulation::encode_capture(capture, record.camera, format);
    const std::string sidecar =
        dump(capture_sidecar(capture, record, format, image_name, sidecar_name));
    CaptureFiles out{dir / image_name, dir / sidecar_name};
    io::write_file_atomic(out.image, image);
    io::write_file_atomic(out.sidecar, sidecar);
    return out;
}

}  // namespace roughscope::serialize
