// `roughscope simulate capture`: a synthetic camera capture of a plane, cylinder or sphere of
// known roughness (simulation/capture.hpp), written as DIR/capture.<ext> + DIR/capture.json
// through serialize::write_capture_files (atomic, nothing half-written). Several --sigma-over-T
// values make a region map of equal vertical stripes, one truth each. Formulas and keys:
// docs/simulation-captures.md.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "common.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/serialize/capture.hpp"
#include "roughscope/simulation/capture.hpp"
#include "simulate.hpp"

namespace roughscope::cli {
namespace {

namespace fs = std::filesystem;

struct CaptureCommand {
    simulation::Scene scene;
    simulation::SurfaceTruth truth;
    simulation::CameraModel camera;
    std::vector<double> sigma_over_T{0.2};
    double theta_i_deg = 30.0, phi_i_deg = 180.0, theta_v_deg = 0.0, phi_v_deg = 0.0;
    double oren_nayar_sigma_deg = 20.0;
    int bits = 14;
    long long width = 256, height = 256;
    bool no_shot_noise = false;
    simulation::CaptureFormat format = simulation::CaptureFormat::Png;
    std::string out_dir;
};

void run_capture(CaptureCommand& c) {
    c.scene.width = static_cast<std::size_t>(c.width);
    c.scene.height = static_cast<std::size_t>(c.height);
    c.scene.light =
        simulation::direction_from_angles(deg_to_rad(c.theta_i_deg), deg_to_rad(c.phi_i_deg));
    c.scene.view =
        simulation::direction_from_angles(deg_to_rad(c.theta_v_deg), deg_to_rad(c.phi_v_deg));
    c.camera.bit_depth = c.bits;
    c.camera.shot_noise = !c.no_shot_noise;
    c.truth.oren_nayar.sigma_rad = deg_to_rad(c.oren_nayar_sigma_deg);
    if (c.format == simulation::CaptureFormat::Dng &&
        c.camera.response != simulation::Response::Linear)
        throw UsageError(concat("--format dng holds linear raw values: --response ",
                                simulation::to_string(c.camera.response),
                                " is not allowed (use --response linear)"));
    if (!(c.camera.black_level_dn < c.camera.white_level_dn()))
        throw UsageError(concat("--black-level ", format_message(c.camera.black_level_dn),
                                " is outside the valid range [0, ",
                                format_message(c.camera.white_level_dn()), ") for --bits ",
                                std::to_string(c.bits)));
    serialize::CaptureRecord record;
    record.scene = c.scene;
    record.camera = c.camera;
    for (double ratio : c.sigma_over_T) {
        simulation::SurfaceTruth t = c.truth;
        t.sigma_um = ratio * c.truth.T_um;
        record.truths.push_back(t);
    }
    if (record.truths.size() > 1) {
        // Equal vertical stripes, left to right.
        const std::size_t n = record.truths.size();
        record.labels.resize(c.scene.width * c.scene.height);
        for (std::size_t i = 0; i < record.labels.size(); ++i)
            record.labels[i] = static_cast<std::int32_t>((i % c.scene.width) * n / c.scene.width);
    }
    if (c.out_dir.empty())
        throw UsageError(
            "--out: an empty path; give the directory to write capture.<ext> and "
            "capture.json into (created if missing)");
    const fs::path dir(c.out_dir);
    if (fs::exists(dir) && !fs::is_directory(dir))
        throw DataError(concat("--out ", quote_input(c.out_dir), " exists and is not a directory"));
    const simulation::Capture capture = simulation::render_capture(
        record.scene, record.truths, record.labels, record.camera,
        simulation::capture_options_for_file(c.format, !record.labels.empty()));
    // The image is encoded (and DNG's response checked) before anything is created on disk.
    fs::create_directories(dir);
    const serialize::CaptureFiles files =
        serialize::write_capture_files(capture, record, c.format, dir);
    // The paths come from the command line: control characters are escaped (core/text.hpp).
    std::cout << "wrote " << printable_text(files.image.string()) << " and "
              << printable_text(files.sidecar.string()) << " (" << capture.object_count
              << " object pixels, " << capture.saturated_count << " saturated)\n";
}

}  // namespace

void add_simulate_capture(CLI::App& simulate) {
    auto args = std::make_shared<CaptureCommand>();
    CaptureCommand& c = *args;
    CLI::App* cmd = simulate.add_subcommand(
        "capture",
        "Synthetic camera capture of a plane, cylinder or sphere of known roughness: image "
        "(PNG, TIFF, float TIFF or DNG) + JSON sidecar with the truth "
        "(docs/simulation-captures.md)");
    const std::string gs = "Scene";
    add_enum_option(*cmd, "--scene", c.scene.shape, simulation::parse_scene_shape,
                    "plane (default), cylinder (axis = scene Y) or sphere")
        ->group(gs);
    cmd->add_option("--width", c.width, "Image width, pixels 1..65535 (default 256)")
        ->transform(integer_validator(1, 65535))
        ->group(gs);
    cmd->add_option("--height", c.height, "Image height, pixels 1..65535 (default 256)")
        ->transform(integer_validator(1, 65535))
        ->group(gs);
    add_positive_option(*cmd, "--pixel-size-um", c.scene.pixel_size_um,
                        "Object-space pixel size, um (default 10)", "um")
        ->group(gs);
    add_non_negative_option(*cmd, "--radius-um", c.scene.radius_um,
                            "Sphere/cylinder radius, um (default 0: 0.4 x the smaller image side)",
                            "um")
        ->group(gs);
    add_non_negative_option(*cmd, "--background", c.scene.background_radiance,
                            "Brightness of pixels off the object (default 0)")
        ->group(gs);
    const std::string gg = "Light and view (degrees, scene frame: Z = the plane's normal)";
    add_angle_option(*cmd, "--theta-i", c.theta_i_deg, "Light polar angle [0,90) (default 30)")
        ->group(gg);
    add_azimuth_option(*cmd, "--phi-i", c.phi_i_deg,
                       "Light azimuth (default 180: the paper's light azimuth)")
        ->group(gg);
    add_angle_option(*cmd, "--theta-v", c.theta_v_deg, "View polar angle [0,90) (default 0)")
        ->group(gg);
    add_azimuth_option(*cmd, "--phi-v", c.phi_v_deg,
                       "View azimuth (default 0: the specular half-plane)")
        ->group(gg);
    const std::string gt = "Surface truth";
    cmd->add_option("--sigma-over-T", c.sigma_over_T,
                    "sigma/T (default 0.2); several (comma-separated) make equal vertical stripes, "
                    "one region each")
        ->delimiter(',')
        ->transform(range_validator(1e-6, 1e6))
        ->group(gt);
    add_range_option(*cmd, "--T-um", c.truth.T_um, kMinLengthUm, 1e12,
                     "Correlation length T, um (default 5; sigma = ratio x T)")
        ->group(gt);
    add_enum_option(*cmd, "--correlation", c.truth.correlation, parse_correlation,
                    "gaussian (default) or exponential")
        ->group(gt);
    add_enum_option(*cmd, "--model", c.truth.model, simulation::parse_brightness_model,
                    "very_rough (default, Eq. 4/5), mean_scattered_power (Eq. 1), lambert, "
                    "oren_nayar, lafortune")
        ->group(gt);
    add_enum_option(*cmd, "--factor", c.truth.factor, parse_geometric_factor,
                    "Geometric factor: vh (default), beckmann, ogilvy, kirchhoff")
        ->group(gt);
    add_range_option(*cmd, "--wavelength-um", c.truth.model_options.wavelength_um, kMinLengthUm,
                     kMaxLengthUm, "Wavelength for mean_scattered_power, um (default 0.555)")
        ->group(gt);
    add_range_option(*cmd, "--oren-nayar-sigma-deg", c.oren_nayar_sigma_deg, 0.0, 90.0,
                     "Oren-Nayar facet slope sigma, degrees (default 20)")
        ->group(gt);
    add_positive_option(*cmd, "--lafortune-n", c.truth.lafortune_n,
                        "Lafortune diffuse-lobe exponent (default 1)")
        ->group(gt);
    const std::string gc = "Camera";
    add_positive_option(*cmd, "--electrons-per-unit-s", c.camera.electrons_per_unit_s,
                        "Electrons per unit brightness per second (default 20000)")
        ->group(gc);
    add_positive_option(*cmd, "--exposure-s", c.camera.exposure_s, "Exposure time, s (default 1)",
                        "s")
        ->group(gc);
    add_positive_option(*cmd, "--gain", c.camera.gain_dn_per_e,
                        "Gain, DN per electron (default 0.25)")
        ->group(gc);
    add_range_option(*cmd, "--full-well-e", c.camera.full_well_e, 1.0, 1e12,
                     "Full-well capacity, electrons (default 60000)")
        ->group(gc);
    add_range_option(*cmd, "--black-level", c.camera.black_level_dn, 0.0, 65534.0,
                     "Black level, DN (default 64; below the white level 2^bits - 1)")
        ->group(gc);
    add_non_negative_option(*cmd, "--read-noise-e", c.camera.read_noise_e,
                            "Read noise, electrons RMS (default 3)")
        ->group(gc);
    cmd->add_flag("--no-shot-noise", c.no_shot_noise, "Expected electrons, no Poisson draw")
        ->group(gc);
    cmd->add_option("--bits", c.bits, "Bit depth: 8, 12, 14 (default) or 16")
        ->transform(CLI::IsMember({8, 12, 14, 16}))
        ->group(gc);
    add_enum_option(*cmd, "--response", c.camera.response, simulation::parse_response,
                    "linear (default), srgb or gamma")
        ->group(gc);
    add_range_option(*cmd, "--gamma", c.camera.gamma, 0.1, 10.0,
                     "Gamma of --response gamma (default 2.2)")
        ->group(gc);
    add_range_option(*cmd, "--vignetting", c.camera.vignetting, 0.0, 1.0,
                     "Vignetting strength: 1 - v rho^2 (default 0)")
        ->group(gc);
    cmd->add_option("--seed", c.camera.seed, "Seed of the noise (default 1)")
        ->transform(integer_validator(0, 9'223'372'036'854'775'807LL))
        ->group(gc);
    const std::string go = "Output";
    add_enum_option(*cmd, "--format", c.format, simulation::parse_capture_format,
                    "png (default), tiff, tiff_float or dng")
        ->group(go);
    cmd->add_option("--out", c.out_dir,
                    "Directory for capture.<ext> and capture.json (created if missing)")
        ->required()
        ->group(go);
    cmd->callback([args]() { run_capture(*args); });
}

}  // namespace roughscope::cli
