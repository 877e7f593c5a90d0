// Roughness estimation from brightness measurements (paper §4).
//
// Contract shared with other modules (keep these signatures): the two-point slope estimators of
// §4.2 with the viewer on the normal (θs = φs = 0), angles in radians, ratio = E1/E2 > 0.
// Throw InvalidArgument for bad inputs and NoSolution (with the valid range of ratios) when the
// ratio has no solution.
//
// Everything else in this header builds on those two:
//  * closed forms of §4 — σ from the specular reflectance (Eq. 12–13), T from two diffuse
//    measurements of a slightly rough surface (Eq. 14–15), σ/T for very rough surfaces (Eq. 16–19);
//  * the valid range of brightness ratios for each closed form (what NoSolution reports);
//  * a general two-geometry solver (any θi, θs, φs for each of the two measurements, any
//    geometric factor, radiometry and regime), solved by bracketed root finding (TOMS 748);
//  * first-order (analytic) propagation of relative brightness noise to σ, T and σ/T;
//  * the derived quantities of §3.5 (θK, ξK, RMS slope, roughness class, g, warnings).
// Least-squares fits to N ≥ 3 measurements are in fit.hpp.
//
// Units: angles in radians, lengths in µm, brightness in any consistent unit (only ratios enter).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/factors.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/scattering/validity.hpp"

namespace roughscope {

// =============================================================================================
// Contract: §4.2 very-rough slope estimators, viewer on the normal (θs = φs = 0).

// Eq. 17 (Gaussian correlation) / Eq. 19 (exponential, Eq. 5 as published): σ/T from E1/E2 at
// incidence θ1, θ2, very rough (correlation.hpp: sigma_over_T_from_normal_view_ratio).
double sigma_over_T_from_ratio(Correlation correlation, double E1_over_E2, double theta1_rad,
                               double theta2_rad,
                               GeometricFactor factor = GeometricFactor::VernoldHarvey);

// =============================================================================================
// Valid ranges of the brightness ratio E1/E2 (RatioRange: correlation.hpp).

// Eq. 16: E1/E2 = C exp{(T²/4σ²)(a2 − a1)} with a = v_xy²/v_z², C = F1² v_z2²/(F2² v_z1²):
// θ1 < θ2: (C, ∞); θ1 > θ2: (0, C).
// Eq. 18: E1/E2 = C {(1 + a2 T²/σ²)/(1 + a1 T²/σ²)}^{3/2}: between C and C (a2/a1)^{3/2}.
RatioRange ratio_range(Correlation correlation, double theta1_rad, double theta2_rad,
                       GeometricFactor factor = GeometricFactor::VernoldHarvey);

// Eq. 14: with σ known the ratio is (g1F1²/g2F2²) exp{g2 − g1 + (T²/4)(v_xy2² − v_xy1²)}; T ∈ (0,
// ∞) maps to the ratios between its T → 0 value and 0 or ∞.
RatioRange ratio_range_correlation_length(double sigma_um, double theta1_rad, double theta2_rad,
                                          double wavelength_um,
                                          GeometricFactor factor = GeometricFactor::VernoldHarvey);

// =============================================================================================
// §4.1 closed forms for slightly rough surfaces.

// The default R0 = 1: the paper's Table 1 uses R_spec = 1 − Ẽ_dif/Ẽ_tot, a brightness ratio
// normalised to the total brightness at the highlight, so the smooth-surface reference is 1 (and
// λ = 0.555 µm, R0 = 1 reproduce Table 1). Give the Fresnel reflectance of the material relative
// to the same normalisation if it is known.
inline constexpr double kDefaultSmoothReflectanceR0 = 1.0;

// §4.1.1: R_spec = 1 − Ẽ_dif/Ẽ_tot from the peak total and the surrounding diffuse brightness.
// Both > 0 and Ẽ_dif < Ẽ_tot, else InvalidArgument.
double specular_reflectance_from_brightness(double E_tot, double E_dif);

// Eq. 13: σ = (λ/(4π cos θ)) [ln(R0/R_spec)]^{1/2}, θ = θi = θs (specular direction).
// 0 < R_spec < R0, θ in [0, 90°), λ > 0, R0 > 0, else InvalidArgument.
double sigma_from_specular(double R_spec, double theta_rad, double wavelength_um,
                           double R0 = kDefaultSmoothReflectanceR0);

// Eq. 15: T = 2 [(g1 − g2 + ln ζ)/(v_xy2² − v_xy1²)]^{1/2}, ζ = g2F2²E1/(g1F1²E2), viewer on the
// normal, σ known (Eq. 3, Gaussian correlation, slightly rough). F_VH by default (§4.2).
// NoSolution (with ratio_range_correlation_length) when the radicand is not positive.
double correlation_length_from_ratio(double E1_over_E2, double sigma_um, double theta1_rad,
                                     double theta2_rad, double wavelength_um,
                                     GeometricFactor factor = GeometricFactor::VernoldHarvey);

// =============================================================================================
// General two-geometry solver (extends §4.2 beyond normal view): E1/E2 measured at two arbitrary
// geometries.
//
// The model ratio M(x) = B(geom1; x)/B(geom2; x) of the brightness B (diffuse term × radiometric
// factor, gain K cancels) is inverted for the unknown x (σ/T, or T with σ known) by TOMS 748
// bracketed root finding on ln M(x) − ln(E1/E2) in ln x. The bracket is found by expanding
// geometrically from the middle of [lower, upper] until the residual changes sign (no grid);
// when it never does, the ratio is outside what the model produces and NoSolution gives the range
// M spans over [lower, upper]. Agrees with Eq. 15, 17, 19 where those apply (normal view, same
// regime).
struct TwoGeometryOptions {
    GeometricFactor factor = GeometricFactor::VernoldHarvey;  // §4.2's recommendation
    Radiometry radiometry = Radiometry::Radiance;             // Harvey (§3.3)
    // For correlation_length_two_geometries only: the regime of the diffuse term (Eq. 3 /
    // first exponential term for SlightlyRough; the exact series for Series; Auto as in
    // ModelOptions). The very-rough solver always uses Eq. 4 / Eq. 5 (σ/T only).
    Regime regime = Regime::SlightlyRough;
    double wavelength_um = 0.555;  // only for the correlation-length solver
    double lower = 1e-4;           // bracket for the unknown (σ/T, or T in µm)
    double upper = 1e4;
    double relative_tolerance = 1e-13;  // on the unknown
    int max_iterations = 200;
    // For correlation_length_two_geometries in the Series and Auto regimes only (the exact
    // series' ratio need not be monotonic in T): when E1/E2 has several solutions, one T is kept
    // only if, at T, the diffuse brightness of each geometry is at least this fraction of the
    // diffuse brightness in the specular direction of the same incidence (fainter than that, no
    // camera sees the sample beside its own highlight). Several kept solutions are an error
    // (NoSolution) listing them; a single solution is returned whatever its brightness.
    double min_observable_fraction = 1e-12;
};

// σ/T for a very-rough surface (Eq. 4 Gaussian / Eq. 5 exponential, as published) from
// E1/E2 measured at geom1, geom2. The two geometries must differ in their ratio
// v_xy²/v_z² (else InvalidArgument: the ratio carries no information about σ/T).
double sigma_over_T_two_geometries(double E1_over_E2, const Geometry& geom1, const Geometry& geom2,
                                   Correlation correlation, const TwoGeometryOptions& options = {});

// T (µm) with σ known (µm) from E1/E2 at geom1, geom2, from the diffuse term of the chosen
// regime (mean_scattered_power). Works for both correlations (the exponential one has no
// closed form, paper §3.4).
double correlation_length_two_geometries(double E1_over_E2, const Geometry& geom1,
                                         const Geometry& geom2, double sigma_um,
                                         Correlation correlation,
                                         const TwoGeometryOptions& options = {});

// Model brightness ratio B(geom1)/B(geom2) used by the solvers (exposed for tests and plots).
double model_ratio_very_rough(const Geometry& geom1, const Geometry& geom2, double sigma_over_T,
                              Correlation correlation, const TwoGeometryOptions& options = {});
double model_ratio_diffuse(const Geometry& geom1, const Geometry& geom2, double sigma_um,
                           double T_um, Correlation correlation,
                           const TwoGeometryOptions& options = {});

// =============================================================================================
// Uncertainty propagation of the §4 estimators and derived quantities (slope, Caron's θK and ξK,
// §3.5).

// A value with its standard error (first-order propagation; 0 when no noise was given).
struct Estimate {
    double value = 0.0;
    double std_error = 0.0;
};

// §3.5 and §4 quantities that accompany every estimate.
struct RoughnessEstimate {
    std::optional<Estimate> sigma_um;      // RMS height σ
    std::optional<Estimate> T_um;          // correlation length T
    std::optional<Estimate> sigma_over_T;  // slope ratio σ/T
    Correlation correlation = Correlation::Gaussian;
    std::optional<Estimate> rms_slope;    // m = σ√2/T
    std::optional<Estimate> theta_K_rad;  // Caron's θK = π/2 − atan(m)
    std::optional<Estimate> xi_K;         // Caron's ξK = 1 − exp(−T²/4σ²)
    std::vector<double> g;                // g = σ²v_z² at each measurement geometry (σ known)
    // Roughness class from the largest g when σ is known; otherwise the class the model assumes
    // (roughness_class_assumed = true).
    RoughnessClass roughness_class = RoughnessClass::VeryRough;
    bool roughness_class_assumed = true;
    std::vector<std::string> warnings;
};

// Relative (1-sigma) noise of each brightness value; 0 = no uncertainty requested.
struct BrightnessNoise {
    double relative_E1 = 0.0;
    double relative_E2 = 0.0;
};

// Eq. 13 with uncertainty: R_spec = 1 − Ẽ_dif/Ẽ_tot with relative noise ε_tot, ε_dif on the two
// brightness values gives sd(R_spec) = (1 − R_spec) √(ε_tot² + ε_dif²) (the same formula is used
// when R_spec is given directly). Fills sigma_um, g at the specular geometry and the class.
struct SpecularInput {
    double R_spec = 0.0;  // or set E_tot and E_dif (then R_spec is computed)
    std::optional<double> E_tot;
    std::optional<double> E_dif;
    double theta_rad = 0.0;
    double wavelength_um = 0.555;
    double R0 = kDefaultSmoothReflectanceR0;
    double relative_noise_tot = 0.0;
    double relative_noise_dif = 0.0;
};
RoughnessEstimate estimate_sigma_specular(const SpecularInput& input);

// Eq. 15 (or the general solver) with uncertainty: sd(T) from the ratio noise and from
// sd(σ) (independent). Fills T_um, sigma_um (as given), sigma_over_T, m, θK, ξK, g at both
// geometries, class and warnings (g not ≪ 1; angles above θK).
struct CorrelationLengthInput {
    double E1_over_E2 = 0.0;
    double sigma_um = 0.0;
    double sigma_um_std_error = 0.0;
    Geometry geom1;  // normal view (θs = φs = 0) selects the closed form Eq. 15 when correlation
    Geometry geom2;  // is Gaussian and the regime SlightlyRough; otherwise the numeric solver
    Correlation correlation = Correlation::Gaussian;
    TwoGeometryOptions options;
    BrightnessNoise noise;
};
RoughnessEstimate estimate_correlation_length(const CorrelationLengthInput& input);

// Eq. 17 / 19 (or the general solver) with uncertainty. If σ is known (sigma_um), T, g and the
// roughness class at the geometries are filled too.
struct SlopeInput {
    double E1_over_E2 = 0.0;
    Geometry geom1;  // normal view selects the closed forms Eq. 17 / 19
    Geometry geom2;
    Correlation correlation = Correlation::Gaussian;
    TwoGeometryOptions options;
    BrightnessNoise noise;
    std::optional<double> sigma_um;
};
RoughnessEstimate estimate_slope(const SlopeInput& input);

// Derived quantities from σ/T (with its standard error): m, θK, ξK; warnings when the larger
// polar angle of a geometry exceeds θK (§5.2: outside the model's validity). θK and ξK are
// Caron's formulas for a Gaussian correlation; for an exponential-correlation estimate they are
// still reported but a warning says so.
void fill_derived_quantities(RoughnessEstimate& estimate, const std::vector<Geometry>& geometries);

// g at each geometry and the roughness class (of the largest g) from σ and λ; a warning for each
// geometry whose class differs from the one the estimator assumes (nullopt: none assumed).
void fill_roughness_class(RoughnessEstimate& estimate, const std::vector<Geometry>& geometries,
                          double sigma_um, double wavelength_um,
                          std::optional<RoughnessClass> assumed);

// Analytic derivatives used by the propagation (exposed for tests).
// d(σ/T)/d ln(E1/E2) for Eq. 17 and Eq. 19, dT/d ln(E1/E2) and dT/dσ for Eq. 15,
// dσ/dR_spec for Eq. 13.
double d_sigma_over_T_d_log_ratio(Correlation correlation, double E1_over_E2, double theta1_rad,
                                  double theta2_rad,
                                  GeometricFactor factor = GeometricFactor::VernoldHarvey);
double d_correlation_length_d_log_ratio(double E1_over_E2, double sigma_um, double theta1_rad,
                                        double theta2_rad, double wavelength_um,
                                        GeometricFactor factor = GeometricFactor::VernoldHarvey);
double d_correlation_length_d_sigma(double E1_over_E2, double sigma_um, double theta1_rad,
                                    double theta2_rad, double wavelength_um,
                                    GeometricFactor factor = GeometricFactor::VernoldHarvey);
double d_sigma_d_specular_reflectance(double R_spec, double theta_rad, double wavelength_um,
                                      double R0 = kDefaultSmoothReflectanceR0);

// =============================================================================================
// The two-name forms kept for the photograph, CLI and Python code (src/image, python/); they
// forward to sigma_over_T_from_ratio and ratio_range.
inline double sigma_over_T_gaussian_from_ratio(  // Eq. 17
    double E1_over_E2, double theta1_rad, double theta2_rad,
    GeometricFactor factor = GeometricFactor::VernoldHarvey) {
    return sigma_over_T_from_ratio(Correlation::Gaussian, E1_over_E2, theta1_rad, theta2_rad,
                                   factor);
}
inline double sigma_over_T_exponential_from_ratio(  // Eq. 19
    double E1_over_E2, double theta1_rad, double theta2_rad,
    GeometricFactor factor = GeometricFactor::VernoldHarvey) {
    return sigma_over_T_from_ratio(Correlation::Exponential, E1_over_E2, theta1_rad, theta2_rad,
                                   factor);
}
inline RatioRange ratio_range_gaussian(  // Eq. 16
    double theta1_rad, double theta2_rad, GeometricFactor factor = GeometricFactor::VernoldHarvey) {
    return ratio_range(Correlation::Gaussian, theta1_rad, theta2_rad, factor);
}
inline RatioRange ratio_range_exponential(  // Eq. 18
    double theta1_rad, double theta2_rad, GeometricFactor factor = GeometricFactor::VernoldHarvey) {
    return ratio_range(Correlation::Exponential, theta1_rad, theta2_rad, factor);
}

}  // namespace roughscope
