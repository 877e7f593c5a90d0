// Photometric stereo: the normals and the albedo of an object of unknown shape from k ≥ 3
// photographs taken by a fixed camera under lights from known directions (Woodham 1980), the
// step that gives the paper's §5 statue experiment its normals. Formulas, thresholds and the
// quality map in docs/photometric-stereo.md.
//
// Camera frame as sphere.hpp and mirror_sphere.hpp: x image right, y image UP, z towards the
// camera (orthographic view V = +z). The light j has the unit direction L_j (towards the lamp,
// L_j,z > 0: in front of the object) and the relative intensity e_j (1 when the lamps are alike;
// divide out different exposures here).
//
// Lambert's model: I_j = ρ max(0, n·L_j) e_j. A pixel's light j is usable unless its value is
// flagged (saturated, clipped, missing) or at most shadow_fraction of the pixel's brightest
// value over the lights (a cast or attached shadow). With S the usable set, the least-squares
// solution of I_j/e_j = g·L_j (j in S) is g = (L_Sᵀ L_S)⁻¹ L_Sᵀ (I/e)_S, n = g/|g|, ρ = |g|.
// A specular highlight only adds light: where |S| ≥ 4 and a value exceeds the fit by more than
// highlight_fraction · ρ, the largest such light is left out and the pixel solved again (while
// |S| ≥ 4). A pixel with fewer than 3 usable lights, lights of S nearly coplanar, ρ ≤ 0 or a
// normal facing away from the camera (n_z ≤ 0) has no normal (NaN).
//
// Quality: the residual RMS_j∈S (I_j/e_j − g·L_j) / ρ, relative to the albedo (0 for exact
// Lambertian data; NaN with exactly 3 lights, where the fit is exact whatever the surface).
//
// Rough-surface photometric stereo (PhotometricModel::VeryRough*): I_j/e_j = ρ B(n, L_j, V; σ/T),
// B the very-rough brightness of the paper's Eq. 4 (Gaussian) or Eq. 5 (exponential) with the
// Vernold–Harvey factor (scattering/beckmann.hpp very_rough_brightness) at the local geometry
// θi = acos(n·L_j), θs = acos(n·V), φs of geometry_from_vectors. Per pixel with |S| ≥ 4 usable
// lights (shadows as above, before any highlight is left out): ρ by linear least squares for the
// current (n, σ/T); n (two tangent-plane offsets from the Lambertian normal) and ln σ/T by
// Levenberg–Marquardt from the Lambertian normal and the best of a log scan of σ/T. A light whose
// value exceeds the fit by more than highlight_fraction × the pixel's brightest prediction is
// left out (while |S| ≥ 5) and the pixel fitted again. The standard error of σ/T is from
// (JᵀJ)⁻¹ SSE/(|S| − 4) (NaN when |S| = 4; an interval takes Student's t with |S| − 4 degrees of
// freedom). Model comparison per pixel (|S| ≥ 5):
// ΔAIC = AIC(Lambert, 3 parameters) − AIC(rough, 4), AIC = |S| ln(SSE/|S|) + 2p, both on the
// rough fit's set; ΔAIC > 0: the rough model explains the pixel better.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "roughscope/photo/image.hpp"

namespace roughscope::image {

// Lights whose directions span less than this (the smallest singular value of the k × 3 matrix
// of the directions, relative to the largest) are coplanar: they cannot give a normal.
inline constexpr double kPhotometricStereoMinLightSpread = 0.05;

enum class PhotometricModel { Lambert, VeryRoughGaussian, VeryRoughExponential };
std::string_view to_string(PhotometricModel model);  // "lambert", "vh_gaussian", "vh_exponential"
PhotometricModel parse_photometric_model(std::string_view name);  // InvalidArgument listing them

struct PhotometricStereoOptions {
    PhotometricModel model = PhotometricModel::Lambert;
    // The rough models' range of σ/T (the fit's bounds), 0 < min < max.
    double min_sigma_over_T = 0.02;
    double max_sigma_over_T = 20.0;
    // e_j, one per light, > 0; empty: all 1.
    std::vector<double> light_intensities;
    // A light is a shadow at a pixel where its value is at most this fraction of the pixel's
    // brightest value over the lights, in [0, 1).
    double shadow_fraction = 0.05;
    // A value above the Lambertian fit by more than this fraction of ρ is a highlight (left out
    // while ≥ 4 lights remain), > 0.
    double highlight_fraction = 0.1;
    // Worker threads (0: every core); the result does not depend on it.
    std::size_t threads = 0;
};

// Throws InvalidArgument naming the field and its valid range.
void check_photometric_stereo_options(const PhotometricStereoOptions& options,
                                      std::size_t num_lights);

struct PhotometricStereoResult {
    std::size_t width = 0;
    std::size_t height = 0;
    // Per pixel, row-major (row 0 at the top); NaN where the pixel has no normal.
    std::vector<float> normals;   // 3 · width · height: (n_x, n_y, n_z) of each pixel in turn
    std::vector<float> albedo;    // ρ, on the images' linear scale divided by e_j
    std::vector<float> residual;  // the quality map (see above)
    std::vector<std::uint8_t> lights_used;  // |S| at the pixel's solution (0 off the object)
    std::size_t object_pixels = 0;          // pixels inside the mask (every pixel without one)
    std::size_t valid_pixels = 0;           // pixels with a normal
    std::size_t too_few_lights = 0;         // object pixels with fewer than 3 usable lights
    // Object pixels with ≥ 3 usable lights but no normal: a nearly coplanar set, ρ ≤ 0, n_z ≤ 0.
    std::size_t no_solution = 0;
    std::size_t highlights_removed = 0;  // lights left out as highlights, over all pixels
    double median_residual = 0.0;        // over the valid pixels with a residual (NaN if none)
    // The rough models only (else empty / 0 / NaN): per pixel σ/T, its standard error and
    // ΔAIC (NaN where not defined); the pixels where ΔAIC > 0 and the medians over the valid
    // pixels.
    PhotometricModel model = PhotometricModel::Lambert;
    std::vector<float> sigma_over_T;
    std::vector<float> sigma_over_T_stderr;
    std::vector<float> delta_aic;
    std::size_t rough_better_pixels = 0;
    std::size_t compared_pixels = 0;  // pixels with a ΔAIC
    double median_sigma_over_T = 0.0;
    double median_delta_aic = 0.0;
    std::vector<std::string> warnings;

    bool valid(std::size_t row, std::size_t col) const {
        return lights_used[row * width + col] >= 3;
    }
    Eigen::Vector3d normal(std::size_t row, std::size_t col) const {
        const float* n = normals.data() + 3 * (row * width + col);
        return {n[0], n[1], n[2]};
    }
};

// Normals and albedo from the photographs (linear values, image.hpp; a colour image's channel
// average is used), one per light, all of one size; `mask` (width · height, non-zero on the
// object) may be empty (every pixel). Throws InvalidArgument for fewer than 3 lights, a light
// count that differs from the image count, a light that is not a unit vector or points away
// from the camera (L_z ≤ 0), lights that are coplanar, images of different sizes, a mask of the
// wrong size, and bad options.
PhotometricStereoResult photometric_stereo(const std::vector<const LinearImage*>& images,
                                           const std::vector<Eigen::Vector3d>& lights,
                                           const std::vector<std::uint8_t>& mask,
                                           const PhotometricStereoOptions& options = {});

}  // namespace roughscope::image
