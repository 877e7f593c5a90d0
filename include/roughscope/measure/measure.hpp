// Roughness from photographs (paper §2, §4, §5.1): a set of captures of one flat sample — their
// files, the light and view directions of each, the exposure — and one region, to σ (specular
// capture, Eq. 13), T given σ (Eq. 15 or the two-geometry solver) and σ/T (Eq. 17 / 19 or the
// solver; a least-squares fit when there are more than two diffuse captures), each with its
// standard error. Every definition is in docs/measure.md.
//
// Brightness of a diffuse capture k: Ẽ_k = mean_k / s_k over the region's pixels on the linear
// scale of image/image.hpp (dark frame subtracted, flat field divided, saturated and clipped
// pixels left out), with s_k the exposure scale: s_k = t_k (exposure time), times ISO_k/ISO_1 and
// (N_1/N_k)² (f-number) when those are known for every capture. Its relative standard error is
// ε_k = max(stderr_pixel, stderr_tiles)/mean (image/statistics.hpp): pixel noise or, when larger,
// the spread between tiles of the region (texture).
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "roughscope/core/response.hpp"
#include "roughscope/estimation/estimation.hpp"
#include "roughscope/fit/fit.hpp"
#include "roughscope/maps/maps.hpp"
#include "roughscope/measure/budget.hpp"
#include "roughscope/measure/exact_series.hpp"
#include "roughscope/measure/finite_distance.hpp"
#include "roughscope/measure/photometric_regions.hpp"
#include "roughscope/objects/cylinder.hpp"
#include "roughscope/objects/photometric_stereo.hpp"
#include "roughscope/objects/sphere.hpp"
#include "roughscope/photo/hdr.hpp"
#include "roughscope/photo/image.hpp"
#include "roughscope/photo/read.hpp"
#include "roughscope/region/region.hpp"
#include "roughscope/region/specular.hpp"
#include "roughscope/region/statistics.hpp"
#include "roughscope/scattering/geometry.hpp"

namespace roughscope::image {

enum class CaptureRole { Diffuse, Specular };
std::string_view to_string(CaptureRole role);  // "diffuse", "specular"
CaptureRole parse_capture_role(std::string_view name);

// Exposure times accepted (s): from a nanosecond gate to about eleven days.
inline constexpr double kMinExposureS = 1e-9;
inline constexpr double kMaxExposureS = 1e6;

// A specular capture's θs may differ from θi, and φs from 0, by at most this (rad).
inline constexpr double kSpecularToleranceRad = 1e-9;

// Default wavelengths of the R, G, B channels (µm): the centres of typical camera colour filters.
// The RGB average (and a grey image) uses MeasureRequest::wavelength_um (the paper's 0.555 µm).
inline constexpr std::array<double, 3> kDefaultChannelWavelengthsUm{0.600, 0.530, 0.460};

// One photograph of an exposure bracket (8-bit files of one still scene, image/hdr.hpp).
struct BracketShot {
    std::string image;
    double exposure_s = 0.0;
};

struct CaptureSpec {
    std::string image;  // path of the image file (a bracket: its first file, for messages)
    // Non-empty: the capture is this bracket merged into one HDR image (merge_hdr, values per
    // second of exposure, so its exposure scale is 1), through the response curve of the
    // request (recovered from response_bracket, or the declared response's).
    std::vector<BracketShot> bracket;
    Geometry geometry;  // (θi, θs, φs) in the paper's frame, radians
    // The light and view directions as given (unit vectors; the capture file's light and view).
    // A curved object (ObjectShape::Cylinder, Sphere, NormalMap) takes them in the camera frame
    // (x image right, y image up, z toward the camera); absent, both are +z (L = V, §5.2).
    std::optional<Eigen::Vector3d> light;
    std::optional<Eigen::Vector3d> view;
    // A point lamp and a camera at a finite distance (finite_distance.hpp): their positions (mm)
    // in the sample frame (z > 0), with MeasureRequest::sample_plane. Each pixel then has its own
    // geometry; geometry, light and view become those at the region's centroid.
    std::optional<Eigen::Vector3d> light_position_mm;
    std::optional<Eigen::Vector3d> view_position_mm;
    // Exposure time (s), in [kMinExposureS, kMaxExposureS]; when absent, the file's metadata
    // (EXIF, RAW). When no capture has one, measure() refuses to compare the captures unless
    // MeasureRequest::exposures_equal says they are the same.
    std::optional<double> exposure_s;
    CaptureRole role = CaptureRole::Diffuse;
    CaptureTolerances uncertainty;  // the capture's own standard uncertainties (budget.hpp)
};

// What was photographed (docs/measure.md "Curved objects and maps"): a flat sample (the §4
// estimators on a region, and maps), a cylinder (the §5.2 profile, cylinder.hpp), a sphere (a BRDF
// table from one photograph, sphere.hpp) or any object whose normals are given as a normal-map
// image (maps only).
// PhotometricStereo: an object of unknown shape photographed by a fixed camera under k ≥ 3 lights
// (each capture's `light`, camera frame): its normals, albedo and, with a rough model, σ/T per
// pixel (objects/photometric_stereo.hpp, docs/photometric-stereo.md).
enum class ObjectShape { Plane, Cylinder, Sphere, NormalMap, PhotometricStereo };
std::string_view to_string(ObjectShape shape);  // "plane", "cylinder", "sphere", "normal_map",
                                                // "photometric_stereo"
ObjectShape parse_object_shape(std::string_view name);

struct ObjectSpec {
    ObjectShape shape = ObjectShape::Plane;
    CylinderOptions cylinder;  // light and view come from the capture
    SphereOptions sphere;      // light and view come from the capture
    // PhotometricStereo: the model and thresholds (the light intensities are the captures'
    // exposure scales, set by measure()).
    PhotometricStereoOptions photometric_stereo;
    // NormalMap: the image of the normals (camera frame). An integer file holds n = 2v − 1 per
    // channel (v on [0, 1], the usual 8/16-bit normal-map encoding); a float TIFF holds n itself.
    // Pixels whose decoded |n| is below 0.5 are off the object.
    std::string normal_map;
};

// A roughness map (maps.hpp) of the diffuse captures, with named regions for its statistics.
struct MapRequest {
    MapOptions options;  // normal_map and region_labels are filled in by measure()
    std::vector<std::pair<std::string, Region>> regions;
};

struct MeasureRequest {
    std::string source;            // the capture file (for messages); may be empty
    double wavelength_um = 0.555;  // λ of the RGB average and of grey images
    std::array<double, 3> channel_wavelengths_um = kDefaultChannelWavelengthsUm;
    ReadOptions read;  // response (linear, srgb, gamma), black level
    // Non-empty: the camera's response is unknown and recovered from this exposure bracket
    // (Debevec–Malik, image/hdr.hpp); every capture (8-bit) is read through that curve.
    std::vector<BracketShot> response_bracket;
    std::optional<std::string> dark_frame;  // image subtracted from every capture
    std::optional<std::string> flat_field;  // image every capture is divided by (mean 1)
    // A region that receives no light (a light trap, black velvet): its mean in each capture,
    // per channel, is that capture's residual black level and is subtracted from it (after the
    // dark frame and the flat field); its standard error enters the budget per capture.
    std::optional<Region> black_reference;
    // The measured region (every capture). Required for a flat sample without maps; for a
    // curved object it restricts the pixels used (absent: the whole object).
    std::optional<Region> roi;
    ObjectSpec object;
    // How pixels map to the sample's plane: needed by light and view positions.
    std::optional<SamplePlane> sample_plane;
    std::optional<MapRequest> maps;
    std::vector<CaptureSpec> captures;
    // The exposures of the captures are the same (the capture file's "exposures_equal"): what
    // lets captures without an exposure time (none given, none in the metadata) be compared.
    bool exposures_equal = false;
    Correlation correlation = Correlation::Gaussian;  // for T given σ
    // The diffuse term's regime for T given σ: SlightlyRough is the paper's Eq. 15 (§4.1.2,
    // Table 1); Series the exact sum at any g; Auto as scattering/beckmann.hpp; VeryRough Eq. 4/5.
    // Unset: the form valid at the sample's g (the larger g = σ² v_z² of the two geometries):
    // SlightlyRough where g < kSlightlyRoughMaxG (0.1, validity.hpp), else Series
    // (MeasureResult::correlation_length_regime says which).
    std::optional<Regime> regime;
    std::optional<double> sigma_um;  // known σ, µm (else from a specular capture)
    double sigma_um_stderr = 0.0;
    double R0 = kDefaultSmoothReflectanceR0;  // Eq. 13's smooth-surface reflectance
    GeometricFactor factor = GeometricFactor::VernoldHarvey;
    Radiometry radiometry = Radiometry::Radiance;
    HighlightOptions highlight;
    RegionStatisticsOptions statistics;
    // Captures read and measured at once, each by its own thread (0: one per core, at most 4);
    // every result is the same whatever the number. Each capture in flight holds its decoded
    // image, so the peak memory grows with the number.
    std::size_t threads = 0;
    // The setup's standard uncertainties and how they are propagated (budget.hpp,
    // docs/uncertainty.md).
    SetupTolerances uncertainty;
    PropagationOptions propagation;
};

// Standard errors: a standard error that the captures cannot give (a region of one pixel, or no
// spread between its pixels: the noise of its mean is unknown, not 0) is NaN in the result, with a
// warning; the JSON writes it as null.

// One capture as measured.
struct CaptureMeasurement {
    CaptureSpec spec;
    ImageInfo info;
    double exposure_scale = 1.0;  // s_k
    std::string exposure_source;  // "capture file", "metadata", "equal (exposures_equal)"
    RegionStatistics region;      // diffuse: the region; specular: the core
    std::optional<HighlightMeasurement> highlight;  // specular captures only
    // The black reference region's statistics (channel average, before its mean was subtracted).
    std::optional<ChannelStatistics> black_reference;
    double brightness = 0.0;  // Ẽ_k = region.average.mean / s_k (diffuse)
    double brightness_relative_stderr = 0.0;
    // A lamp or camera position: the geometry over the region and the correction factors.
    std::optional<FiniteDistance> finite_distance;
};

// σ from one specular capture in one channel (Eq. 13 at that channel's wavelength).
struct ChannelSigma {
    std::string channel;  // "R", "G", "B", "average" or "grey"
    double wavelength_um = 0.0;
    RoughnessEstimate estimate;
};

struct MeasureResult {
    std::vector<CaptureMeasurement> captures;
    std::size_t region_pixels = 0;
    // Specular (§4.1.1): σ per channel and from the RGB average; the channels' agreement as
    // χ² = Σ (σ_c − σ̄)²/sd_c² about their weighted mean, with its degrees of freedom.
    std::vector<ChannelSigma> specular_sigma;
    std::optional<RoughnessEstimate> sigma;  // the RGB average's (or grey) σ
    std::optional<double> channel_sigma_chi2;
    std::size_t channel_sigma_dof = 0;
    // Two diffuse captures (§4.1.2, §4.2): E1/E2 of the first two, σ/T for both correlations,
    // T given σ.
    std::optional<Estimate> E1_over_E2;
    std::optional<RoughnessEstimate> slope_gaussian;
    std::optional<RoughnessEstimate> slope_exponential;
    std::optional<RoughnessEstimate> correlation_length;
    // The regime T given σ was computed in, and whether the request gave it (else chosen by g).
    std::optional<Regime> correlation_length_regime;
    bool correlation_length_regime_given = false;
    // More than two diffuse captures: the least-squares fits (both correlations).
    std::optional<CorrelationComparison> fit;
    // Curved objects and maps (one photograph for a cylinder or a sphere).
    std::optional<CylinderProfile> cylinder;
    std::optional<SphereResult> sphere;
    std::optional<RoughnessMap> map;
    // ObjectShape::PhotometricStereo: the per-pixel solution and the lights it used (one per
    // capture, camera frame).
    std::optional<PhotometricStereoResult> photometric_stereo;
    std::vector<Eigen::Vector3d> photometric_lights;
    // With "maps": {"regions": ...}: each region's σ/T statistics and every pair compared
    // (photometric_regions.hpp, the paper's statue experiment).
    std::vector<PhotometricRegionStatistics> photometric_regions;
    std::vector<PhotometricRegionComparison> photometric_comparisons;
    // A flat sample's budget (budget.hpp): the declared (or assumed) setup uncertainties and the
    // pixel noise propagated to E1/E2, σ/T, σ and T. Absent for curved objects and maps alone.
    std::optional<UncertaintyBudget> uncertainty;
    // The exact series where the capture set allows it (exact_series.hpp): σ known and a pair,
    // or ≥ 3 diffuse captures at distinct geometries; with the closed form's deviation from it.
    std::optional<ExactSeriesEstimate> exact_series;
    std::vector<std::string> warnings;
};

// The budget of a flat sample's measurement (measure() fills MeasureResult::uncertainty with it):
// from the first two diffuse captures (E1/E2, σ/T, T given σ) and the first specular capture (σ)
// or the given σ. Absent when the result has none of those quantities.
std::optional<UncertaintyBudget> uncertainty_budget(const MeasureRequest& request,
                                                    const MeasureResult& result);

// Reads every capture, measures the region and estimates what the captures allow. Throws
// DataError (a file: missing, unreadable, sizes that differ; a dark frame or flat field recorded
// unlike the captures; captures to compare without exposure times and without exposures_equal)
// or InvalidArgument (angles, region outside the image, a mostly saturated region, no diffuse
// pair and no specular capture), NoSolution (a ratio no model produces). With a capture file
// (`source` not empty) every error caused by one of its values is a DataError
// "<file>: <key>: <reason>"; without one, the InvalidArgument names the input.
MeasureResult measure(const MeasureRequest& request);

// The capture file (JSON, docs/measure.md): keys wavelength_um, channel_wavelengths_um,
// response ("linear", "srgb", {"gamma": γ} or {"bracket": [{image, exposure_s}, ...]}),
// black_level_dn, dark_frame, flat_field, roi
// ({"rect": [x, y, w, h]}, {"circle": [cx, cy, r]}, {"polygon": [[x, y], ...]} or
// {"mask": FILE}), correlation, sigma_um, sigma_um_stderr, R0, factor, radiometry, highlight
// {core_radius_px, annulus_inner_px, annulus_outer_px, smoothing_sigma_px, centre_px}, and
// captures: [{image | bracket: [{image, exposure_s}, ...], theta_i_deg, theta_s_deg, phi_s_deg |
// light, view (directions, normal +Z), exposure_s, role}], exposures_equal. Paths are relative
// to the capture file. DataError naming the file and the key for anything malformed, unknown or
// out of range (measure() names the key of a value it cannot use in the same way).
MeasureRequest read_capture_file(const std::string& path);
MeasureRequest parse_capture_file(std::string_view text, const std::string& path);

}  // namespace roughscope::image
