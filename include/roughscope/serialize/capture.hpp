// The sidecar of a synthetic capture (simulation/capture.hpp) and the one function that writes a
// capture's files: DIR/<stem>.<ext> (the image) and DIR/<stem>.json (the truth, the geometry and
// the camera). The CLI (`roughscope simulate capture`) and the Python module (write_capture) both
// call write_capture_files; the keys are documented in docs/simulation-captures.md.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "roughscope/serialize/json.hpp"
#include "roughscope/simulation/capture.hpp"

namespace roughscope::serialize {

// Everything a capture was made from.
struct CaptureRecord {
    simulation::Scene scene;
    std::vector<simulation::SurfaceTruth> truths;
    std::vector<std::int32_t> labels;  // empty: one truth for the whole object
    simulation::CameraModel camera;
};

// The sidecar document. Keys, in order: format ("roughscope-capture"), version (1), files
// {image, format, sidecar} (null when image_file is empty: a capture not written), scene {shape,
// width, height, pixel_size_um, radius_um (null for the plane), light {x, y, z, theta_deg,
// phi_deg}, view {…}, image_right [x, y, z], image_up [x, y, z], background_radiance}, truth
// {regions: [{label, model, sigma_um, T_um, sigma_over_T, correlation, factor, radiometry,
// wavelength_um, oren_nayar_sigma_deg, oren_nayar_albedo, lafortune_n, pixels, bbox [col0, row0,
// col1, row1] or null}]}, camera {electrons_per_unit_s, exposure_s, gain_dn_per_e, full_well_e,
// black_level_dn, white_level_dn, read_noise_e, bit_depth, response, gamma (null unless gamma),
// vignetting, shot_noise, seed}, statistics {object_pixels, saturated_pixels, background_pixels},
// documentation.
Json capture_sidecar(const simulation::Capture& capture, const CaptureRecord& record,
                     simulation::CaptureFormat format, const std::string& image_file,
                     const std::string& sidecar_file);

struct CaptureFiles {
    std::filesystem::path image, sidecar;
};

// Encodes the image (simulation::encode_capture), then writes it and the sidecar, each with
// io::write_file_atomic (nothing half-written; an error before the first write leaves DIR as it
// was). `dir` must exist. Throws InvalidArgument (e.g. DNG with a non-linear response) or
// DataError (cannot write).
CaptureFiles write_capture_files(const simulation::Capture& capture, const CaptureRecord& record,
                                 simulation::CaptureFormat format, const std::filesystem::path& dir,
                                 const std::string& stem = "capture");

}  // namespace roughscope::serialize
