// Brightness against incidence angle across a rough cylinder (paper §5.2, Fig. 8): one
// photograph, the cylinder's axis from its silhouette (or given), the pixels binned by their
// position across the axis and averaged along it ("the mean brightness at each point ... by
// averaging the brightness values over the vertical neighbors"), normalised by the profile's
// maximum (§2), compared with Lambert, Eq. 7 (B–K Gaussian), Eq. 9 (V–H Gaussian) and Eq. 10
// (V–H exponential), fitted for σ/T, and the angle where each model leaves the data next to
// Caron's θK (§3.5). Formulas in docs/curved-objects.md.
//
// Camera frame: orthographic camera, x = image right, y = image up, z = towards the camera; the
// light L and view V are unit vectors in it (the paper's case: L = V = +z). Image coordinates are
// x right, y down (silhouette.hpp), so an image direction (dx, dy) is (dx, −dy, 0) in the camera
// frame. The pixel at signed distance d from the axis (across(), silhouette.hpp) has the normal
//   n = (d/R) û + √(1 − (d/R)²) ẑ          (û = across() in the camera frame)
// and the geometry (θi, θs, φs) = geometry_from_vectors(n, L, V) (scattering/geometry.hpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "roughscope/fit/engine.hpp"
#include "roughscope/objects/silhouette.hpp"
#include "roughscope/photo/image.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/factors.hpp"
#include "roughscope/scattering/geometry.hpp"

namespace roughscope::image {

enum class CylinderHalf { Right, Left, Both };
std::string_view to_string(CylinderHalf half);  // "right", "left", "both"
CylinderHalf parse_cylinder_half(std::string_view name);

// The models drawn on a profile (Fig. 8).
enum class ProfileModel {
    Lambert,        // cos θi
    BkGaussian,     // Eq. 7 (F_Beck, Gaussian, very rough), general form Eq. 4
    VhGaussian,     // Eq. 9 (F_VH, Gaussian, very rough), general form Eq. 4
    VhExponential,  // Eq. 10 (F_VH, exponential, very rough), general form Eq. 5
};
inline constexpr ProfileModel kProfileModels[] = {ProfileModel::Lambert, ProfileModel::BkGaussian,
                                                  ProfileModel::VhGaussian,
                                                  ProfileModel::VhExponential};
std::string_view to_string(ProfileModel model);     // "lambert", "bk_gaussian", "vh_gaussian",
                                                    // "vh_exponential"
std::string_view display_name(ProfileModel model);  // "Lambert", "Eq. 7 B–K(G)", ...
ProfileModel parse_profile_model(std::string_view name);

struct CylinderOptions {
    Eigen::Vector3d light = Eigen::Vector3d(0.0, 0.0, 1.0);  // L, camera frame, unit
    Eigen::Vector3d view = Eigen::Vector3d(0.0, 0.0, 1.0);   // V, camera frame, unit
    // The axis; none: fit_cylinder_axis(find_silhouette(image)).
    std::optional<CylinderAxis> axis;
    SilhouetteOptions silhouette;
    CylinderAxisOptions axis_fit;
    // Bins of the angle α = asin(d/R) of the normal about the axis (α = θi on the lit half when
    // L = V), width in (0°, 45°].
    double bin_width_deg = 2.0;
    CylinderHalf half = CylinderHalf::Right;  // the paper uses the right-hand half
    std::size_t min_pixels_per_bin = 20;      // bins with fewer used pixels are dropped (≥ 1)
    // Pixels with |d| > limb_fraction · R are not used (the limb, where the edge blurs and the
    // normal changes fastest), in (0, 1].
    double limb_fraction = 0.99;
    // σ/T at which the models are drawn; none: Eq. 7 and 9 at the fitted V–H Gaussian σ/T, Eq. 10
    // at the fitted V–H exponential σ/T.
    std::optional<double> sigma_over_T;
    // Bins with θi ≤ this enter the fit, in (0°, 90°).
    double fit_max_theta_i_deg = 60.0;
    double fit_max_flagged_fraction = 0.02;                   // [0, 1]
    GeometricFactor factor = GeometricFactor::VernoldHarvey;  // of the fitted model
    Radiometry radiometry = Radiometry::Radiance;             // of every B–K model and the fit
    // Departure rule: a model leaves the data at the first bin (increasing θi) from which
    // departure_bins consecutive bins (or all remaining, when fewer) differ from the data by more
    // than departure_k standard errors.
    double departure_k = 3.0;
    std::size_t departure_bins = 2;
    // Worker threads of the pass over the pixels (0 = all cores); the result does not depend on
    // it (the pixels are summed in fixed bands of rows, added in order).
    std::size_t threads = 0;
};

// Throws InvalidArgument naming the field and its valid range.
void check_cylinder_options(const CylinderOptions& options);

struct ProfileBin {
    double alpha_rad = 0.0;    // mean angle of the normal about the axis, asin(d/R)
    double across_px = 0.0;    // mean signed distance d from the axis
    Geometry geometry;         // at the bin's mean normal (θi is the profile's abscissa)
    double theta_i_rad = 0.0;  // = geometry.theta_i_rad
    double brightness = 0.0;   // mean channel average / profile maximum
    // Of brightness (same scale): the larger of the two below, and at least 1e−4 (a 14-bit
    // quantisation step; noise-free synthetic data have no noise of their own).
    double standard_error = 0.0;
    double stderr_slices = 0.0;  // from the spread between slices along the axis
    double stderr_pixel = 0.0;   // from pixel noise (differences of neighbours along the axis)
    double raw_mean = 0.0;       // mean channel average, linear scale (not normalised)
    std::size_t count = 0;       // pixels used
    std::size_t flagged = 0;     // pixels of the bin left out (image.hpp kPixel* flags)
    std::size_t slices = 0;      // 1-px slices along the axis that hold pixels of the bin
    // θi ≤ fit_max_theta_i_deg, brightness and standard error > 0, and flagged pixels at most
    // fit_max_flagged_fraction of the bin's pixels (a bin whose darkest or brightest pixels were
    // clipped has a biased mean)
    bool in_fit = false;
};

struct ProfileModelCurve {
    ProfileModel model = ProfileModel::Lambert;
    std::string name;                    // to_string(model)
    std::optional<double> sigma_over_T;  // none for Lambert
    // Model brightness averaged over each bin's pixels (their distribution across the axis),
    // normalised by its maximum over the bins.
    std::vector<double> prediction;
    double rms_difference = 0.0;  // √(mean (prediction − brightness)²) over the bins
    std::optional<double> departure_theta_i_rad;  // none when it never leaves the data
    std::optional<std::size_t> departure_bin;
};

// σ/T and the gain K fitted to the bins with in_fit: minimise Σ w_b (K M_b(σ/T) − E_b)² with
// w_b = 1/standard_error_b² and M_b the model averaged over the bin's pixels (the same average
// as ProfileModelCurve::prediction), by the library's engine (fit/engine.hpp: σ/T on a log scale
// in [1e−3, 1e3], grid start, K profiled out, covariance scaled by SSE/(N − 2)).
struct ProfileFit {
    Correlation correlation = Correlation::Gaussian;
    SolverStatus status = SolverStatus::Failed;
    std::string message;
    std::optional<double> sigma_over_T;  // none when not identified
    double sigma_over_T_stderr = 0.0;    // 0 when no covariance
    double gain = 0.0;
    double aic = 0.0;
    int bins = 0;
};

struct CylinderProfile {
    CylinderAxis axis;  // axis.detected: from the silhouette, else given
    Eigen::Vector3d light = Eigen::Vector3d(0.0, 0.0, 1.0);
    Eigen::Vector3d view = Eigen::Vector3d(0.0, 0.0, 1.0);
    CylinderHalf half = CylinderHalf::Right;
    double bin_width_rad = 0.0;
    double maximum = 0.0;                   // the raw mean of the brightest bin (the normaliser)
    std::vector<ProfileBin> bins;           // increasing θi (both halves too)
    std::vector<ProfileModelCurve> models;  // kProfileModels order
    ProfileFit gaussian_fit;
    ProfileFit exponential_fit;
    Correlation preferred = Correlation::Gaussian;  // lower AIC
    // Caron's θK (validity.hpp) at the σ/T of the V–H Gaussian curve (given or fitted).
    std::optional<double> theta_K_rad;
    std::size_t pixels_used = 0;
    std::size_t pixels_flagged = 0;  // on the object and the region, never used
    std::vector<std::string> warnings;

    const ProfileModelCurve& curve(ProfileModel model) const;
};

// Measures the profile on `image`, restricted to region_mask (width · height bytes, nonzero =
// use; nullptr = the whole object). Flagged pixels (image.hpp kPixel*) are never used. Throws
// InvalidArgument for bad options or an inconsistent image/mask, DataError when the object or its
// axis cannot be found (silhouette.hpp) or fewer than 3 bins keep min_pixels_per_bin pixels.
CylinderProfile measure_cylinder_profile(const LinearImage& image,
                                         const std::vector<std::uint8_t>* region_mask,
                                         const CylinderOptions& options = {});

// The model brightness (gain 1) of one profile model at one geometry: cos θi for Lambert, else
// very_rough_brightness with the model's factor and correlation (Eq. 4 / Eq. 5).
double profile_model_brightness(ProfileModel model, const Geometry& geom, double sigma_over_T,
                                Radiometry radiometry = Radiometry::Radiance);

}  // namespace roughscope::image
