// Synthetic camera captures: images of a flat sample, a cylinder or a sphere of known roughness,
// lit by a distant light and seen by an orthographic camera, with the brightness of any model of
// the library and the noise, clipping, quantisation and response of a real camera. They are the
// ground truth of the image pipeline (photographs → σ, T, σ/T). Every formula is in
// docs/simulation-captures.md; the symbols below follow it.
//
// Frame: the scene frame (X, Y, Z) is the paper's local frame of the flat sample (§2): Z is the
// mean normal N, the light direction L and the view direction V point away from the surface. The
// camera is orthographic and looks along −V; its image axes are right = normalise(−V × up) and
// up' = right × (−V) with up = +Y (+X when V is within 0.1° of ±Y), so a view in the XZ plane
// sees +Y as image up. Pixel (col, row) has its centre at
//   p = (col + ½ − W/2) s · right + (H/2 − row − ½) s · up'        (s = pixel size, µm)
// in the plane through the origin perpendicular to V.
//
// Shapes: the plane Z = 0 (filling the image); the sphere of radius R centred at the origin
// (hit p + √(R² − |p|²) V, normal = hit/R); the cylinder of radius R with its axis the scene Y
// axis through the origin (the camera-facing intersection; normal = the hit's component
// perpendicular to the axis, /R). Pixels that miss the object are background.
//
// Brightness: E = model(θi, θs, φs) from geometry_from_vectors(n, L, V) (zero where L or V is at
// or below the pixel's horizon); background pixels get Scene::background_radiance.
//
// Camera (per pixel, docs/simulation-captures.md "Camera"):
//   μ_e   = k · E · t · v(ρ)                       expected photo-electrons (k = electrons per unit
//                                                   brightness per second, t = exposure_s,
//                                                   v = vignetting)
//   n_e   = min(Poisson(μ_e), full_well_e)          shot noise, full-well clip
//   x_e   = n_e + N(0, σ_read²)                     read noise
//   s     = gain · x_e + black_level_dn             linear signal, DN
//   s_c   = clamp(s, 0, white)                      white = 2^bits − 1
//   DN    = round(s_c)                     (linear)  or round(white · f(s_c / white)) (sRGB/gamma)
// saturated = n_e reached the full well, or s ≥ white.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "roughscope/core/response.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/factors.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/scattering/reflectance_models.hpp"

namespace roughscope::simulation {

// ---------------------------------------------------------------------------------------------
// Scene

enum class SceneShape { Plane, Cylinder, Sphere };
std::string_view to_string(SceneShape shape);  // "plane", "cylinder", "sphere"
SceneShape parse_scene_shape(std::string_view name);

// The unit vector of polar angle θ (from Z) and azimuth φ (from X): (sin θ cos φ, sin θ sin φ,
// cos θ). The paper's light is at φ = π: direction_from_angles(θi, π) = light_direction(θi...).
Eigen::Vector3d direction_from_angles(double theta_rad, double phi_rad);

// The largest image rendered (width × height): 2^28 pixels (≈ 268 MP).
inline constexpr std::size_t kMaxCapturePixels = std::size_t{1} << 28;

struct Scene {
    SceneShape shape = SceneShape::Plane;
    std::size_t width = 256;      // pixels, 1..65535
    std::size_t height = 256;     // pixels, 1..65535
    double pixel_size_um = 10.0;  // object-space side of one pixel, µm, [1e-9, 1e12]
    // Sphere and cylinder radius, µm, [0, 1e15]; 0 = 0.4 · min(width, height) · pixel_size_um.
    double radius_um = 0.0;
    Eigen::Vector3d light = direction_from_angles(deg_to_rad(30.0), kPi);  // L, unit
    Eigen::Vector3d view = Eigen::Vector3d(0.0, 0.0, 1.0);                 // V, unit
    double background_radiance = 0.0;  // brightness of pixels that miss the object, [0, 1e30]
};

// The orthographic camera's image axes for view direction V (see "Frame" above).
struct CameraAxes {
    Eigen::Vector3d right, up;
};
CameraAxes camera_axes(const Eigen::Vector3d& view);

// The radius actually used (radius_um or its default).
double scene_radius_um(const Scene& scene);

// ---------------------------------------------------------------------------------------------
// Surface truth

enum class BrightnessModel {
    VeryRough,           // very_rough_brightness (Eq. 4/5), σ/T only
    MeanScatteredPower,  // mean_scattered_power (Eq. 1, any regime): σ, T, λ; its brightness field
    Lambert,             // cos θi
    OrenNayar,           // oren_nayar_radiance (with inter-reflection)
    Lafortune,           // lafortune_diffuse_brightness (the paper's diffuse lobe)
    Tabulated,           // SurfaceTruth::tabulated(geometry): a callback or a table
};
std::string_view to_string(BrightnessModel model);  // "very_rough", "mean_scattered_power",
                                                    // "lambert", "oren_nayar", "lafortune",
                                                    // "tabulated"
BrightnessModel parse_brightness_model(std::string_view name);

// One surface's truth and the model that turns it into brightness.
struct SurfaceTruth {
    BrightnessModel model = BrightnessModel::VeryRough;
    double sigma_um = 1.0;  // RMS height σ
    double T_um = 5.0;      // correlation length T (σ/T = sigma_um / T_um)
    Correlation correlation = Correlation::Gaussian;
    GeometricFactor factor = GeometricFactor::VernoldHarvey;
    Radiometry radiometry = Radiometry::Radiance;
    ModelOptions model_options{};  // MeanScatteredPower: λ, patch, regime (factor/radiometry
                                   // above take precedence)
    OrenNayarParams oren_nayar{0.3, 1.0};
    double lafortune_n = 1.0;  // exponent of the diffuse Lafortune lobe
    // Tabulated: brightness at a geometry (e.g. an interpolated table of simulated values). Must
    // return a finite value ≥ 0.
    std::function<double(const Geometry&)> tabulated;
    double sigma_over_T() const { return sigma_um / T_um; }
};

// The model brightness of `truth` at `geom` (validated by the model itself).
double surface_brightness(const SurfaceTruth& truth, const Geometry& geom);

// A tabulated brightness on a regular (θi, θs, φs) grid: values[(a·n_s + b)·n_phi + c] at
// θi = theta_i_rad[a], θs = theta_s_rad[b], φs = phi_s_rad[c] (each axis strictly increasing,
// ≥ 2 points; φs in [0, π]); trilinear interpolation, clamped at the grid's edges.
struct BrightnessTable {
    std::vector<double> theta_i_rad, theta_s_rad, phi_s_rad;
    std::vector<double> values;
};
// Validates the table (InvalidArgument naming the axis or value) and returns its interpolant.
std::function<double(const Geometry&)> table_brightness(BrightnessTable table);

// ---------------------------------------------------------------------------------------------
// Camera

// The tone response (core/response.hpp) applied to the linear signal.
using roughscope::parse_response;
using roughscope::Response;
using roughscope::to_string;

struct CameraModel {
    double electrons_per_unit_s = 20000.0;  // k: electrons per unit brightness per second (> 0)
    double exposure_s = 1.0;                // t (> 0)
    double gain_dn_per_e = 0.25;            // DN per electron (> 0)
    double full_well_e = 60000.0;           // electrons (> 0)
    double black_level_dn = 64.0;           // DN added to every pixel (≥ 0, < white)
    double read_noise_e = 3.0;              // σ_read, electrons RMS (≥ 0)
    int bit_depth = 14;                     // 8, 12, 14 or 16
    Response response = Response::Linear;
    double gamma = 2.2;       // Response::Gamma: DN = white · u^(1/γ); γ in [0.1, 10]
    double vignetting = 0.0;  // v(ρ) = 1 − vignetting · ρ², ρ = r / half-diagonal; [0, 1]
    bool shot_noise = true;   // false: n_e = μ_e (no Poisson draw)
    std::uint64_t seed = 1;
    double white_level_dn() const;  // 2^bit_depth − 1
};

// Throws InvalidArgument naming the field and its valid range.
void check_camera(const CameraModel& camera);
void check_scene(const Scene& scene);

using roughscope::srgb_decode;
using roughscope::srgb_encode;

// ---------------------------------------------------------------------------------------------
// Rendering

struct CaptureOptions {
    // Keep the per-pixel label, (θi, θs, φs) and normal (4 + 12 + 12 bytes a pixel); off for
    // very large images when only the pixels are needed.
    bool keep_geometry = true;
    // Keep radiance and expected_dn (4 bytes a pixel each; empty otherwise). Writing a file needs
    // neither, except expected_dn for the float TIFF (encode_capture_tiff_float).
    bool keep_radiance = true;
    bool keep_expected_dn = true;
    // Worker threads over blocks of rows (0 = all cores; images below 65536 pixels use one). The
    // result does not depend on it.
    std::size_t threads = 0;
};

struct Capture {
    std::size_t width = 0, height = 0;
    int bit_depth = 14;
    std::vector<float> radiance;          // model brightness E per pixel (background included)
    std::vector<float> expected_dn;       // gain · μ_e + black: the noise-free linear signal, DN
    std::vector<std::uint16_t> dn;        // the quantised pixel values
    std::vector<std::uint8_t> saturated;  // 1 where clipped (full well or white level)
    // keep_geometry only (else empty):
    std::vector<std::int32_t> label;                         // truth index, −1 for the background
    std::vector<float> theta_i_rad, theta_s_rad, phi_s_rad;  // NaN for background / below horizon
    std::vector<float> normal;  // n, 3 per pixel (x, y, z); NaN for background
    std::size_t saturated_count = 0;
    std::size_t object_count = 0;  // pixels on the object
};

// Renders one capture. `truths` holds one SurfaceTruth per region; `labels` is empty (the whole
// object is truths[0]) or width·height entries in [0, truths.size()) (row-major, row 0 at the top).
// Seeded and reproducible: pixel rows draw from independent streams derived from camera.seed, so
// the result does not depend on how rows are scheduled. Throws InvalidArgument for bad input.
Capture render_capture(const Scene& scene, const std::vector<SurfaceTruth>& truths,
                       const std::vector<std::int32_t>& labels, const CameraModel& camera,
                       const CaptureOptions& options = {});

// ---------------------------------------------------------------------------------------------
// Files (bytes; write them with io::write_file_atomic)

enum class CaptureFormat { Png, Tiff, TiffFloat, Dng };
std::string_view to_string(CaptureFormat format);  // "png", "tiff", "tiff_float", "dng"
CaptureFormat parse_capture_format(std::string_view name);
std::string_view file_extension(CaptureFormat format);  // "png", "tiff", "tiff", "dng"

// The options of a render whose only use is writing `format` and its sidecar (roughscope
// simulate capture, Python write_capture): no radiance, expected_dn only for the float TIFF, the
// geometry only with several regions (its label layer gives the sidecar's per-region counts).
CaptureOptions capture_options_for_file(CaptureFormat format, bool several_regions);

// PNG: 8-bit grey when bit_depth = 8, else 16-bit grey holding the DN unscaled (sBIT = bit depth).
std::string encode_capture_png(const Capture& capture);
// TIFF: 16-bit unsigned grey, the DN unscaled.
std::string encode_capture_tiff(const Capture& capture);
// TIFF: 32-bit float grey, expected_dn (the noise-free linear signal in DN, not clipped);
// InvalidArgument when the capture was rendered without it.
std::string encode_capture_tiff_float(const Capture& capture);
// DNG 1.4: one IFD, LinearRaw (34892), 3 samples of 16 bits (the DN repeated), BlackLevel,
// WhiteLevel, identity ColorMatrix1, AsShotNeutral 1 1 1. Linear response only (InvalidArgument
// otherwise: a DNG holds linear raw values).
std::string encode_capture_dng(const Capture& capture, const CameraModel& camera);
std::string encode_capture(const Capture& capture, const CameraModel& camera, CaptureFormat format);

}  // namespace roughscope::simulation
