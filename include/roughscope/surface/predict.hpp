// The bridge from heights to brightness (paper §3.1, §3.5): a surface's σ, T and correlation —
// measured by a profilometer or an AFM (SurfaceStatistics) or given — put into the scattering
// models, so that a height measurement and a camera measurement of the same sample can be set
// side by side. Value types in, value types out; every number comes from the scattering topic:
//  * the B–K mean scattered power of Eq. 1 with the exact diffuse series for any g (Eq. 2, or the
//    exact exponential series), mean_scattered_power();
//  * the very-rough brightness of Eq. 4 (Gaussian) or Eq. 5 (exponential) from σ/T alone,
//    very_rough_brightness() (constants dropped: a shape, comparable between geometries);
//  * g = σ² v_z² at each geometry and at normal incidence and view (g = (4πσ/λ)²), with the
//    roughness class of §3.1 (slightly, moderately, very rough), Caron's θK and ξK (§3.5) and the
//    RMS slope m = σ√2/T.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/scattering/validity.hpp"
#include "roughscope/surface/statistics.hpp"

namespace roughscope::surface {

// The scattering model's surface taken from height statistics, and what was assumed on the way.
struct SurfaceFromStatistics {
    Surface surface;                    // σ = Sq, T, correlation
    std::string T_source;               // "T_um" (1/e crossing along x) or "T_fit_<correlation>_um"
    bool correlation_assumed = false;   // the statistics named none: Gaussian (or the given one)
    std::vector<std::string> warnings;  // what was assumed, in words
};

// σ = stats.sigma_um; T = the 1/e correlation length along x (stats.T_um), else the fitted T of
// the correlation used; correlation = `correlation` when given, else stats.correlation (the
// better fit by AIC), else Gaussian with a warning. The 1/e T is the paper's T for both
// correlation functions (C(T) = 1/e). InvalidArgument when σ is 0 or not finite, or when no T is
// available (the ACF never falls to 1/e and no fit succeeded).
SurfaceFromStatistics surface_from_statistics(const SurfaceStatistics& stats,
                                              std::optional<Correlation> correlation = {});

// The prediction at one geometry.
struct PredictedBrightness {
    Geometry geometry;
    // Eq. 1 with the options' factor, radiometry, regime (Auto: the exact series wherever the
    // one-term form is not exact to the tolerance), wavelength and patch size.
    ScatteredPower power;
    // Eq. 4 (Gaussian) or Eq. 5 (exponential) as published, from σ/T only, constants dropped,
    // times the radiometric factor: the shape the paper's §4.2 and §5 estimators use.
    double very_rough_brightness = 0.0;
    // θi above Caron's θK (§3.5): shadowing makes the model invalid here.
    bool beyond_theta_K = false;
};

struct SurfacePrediction {
    Surface surface;
    double wavelength_um = 0.0;
    double sigma_over_T = 0.0;
    double rms_slope = 0.0;          // m = σ√2/T (§4)
    double theta_K_rad = 0.0;        // Caron's angle of RMS slope (§3.5; Gaussian statistics)
    double xi_K = 0.0;               // Caron's energy conservation rate at normal incidence (§3.5)
    double g_normal = 0.0;           // g at θi = θs = 0: (4πσ/λ)²
    RoughnessClass roughness_class;  // the class of g_normal (§3.1): the camera's regime
    std::vector<PredictedBrightness> points;
    std::vector<std::string> warnings;
};

// The predictions at `geometries` (each checked as check::geometry, naming its index). Throws
// InvalidArgument for σ, T or the model options out of range (as mean_scattered_power).
SurfacePrediction predict_brightness(const Surface& surface,
                                     const std::vector<Geometry>& geometries,
                                     const ModelOptions& options = {});

// The same from height statistics (surface_from_statistics; its warnings come first).
SurfacePrediction predict_brightness(const SurfaceStatistics& stats,
                                     const std::vector<Geometry>& geometries,
                                     const ModelOptions& options = {},
                                     std::optional<Correlation> correlation = {});

}  // namespace roughscope::surface
