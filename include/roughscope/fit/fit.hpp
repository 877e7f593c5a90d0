// Least-squares roughness fits to N ≥ 3 brightness measurements (paper §4: "if a larger number of
// measurements are available then least-square fitting techniques can be used").
//
// Brightness model: E_i = K · B(geom_i; θ) with an unknown camera gain K > 0 and
//  * FitModel::VeryRough     θ = σ/T: B = Eq. 4 (Gaussian) or Eq. 5 as published (exponential)
//                            without constants, × radiometric factor (any F, any radiometry);
//  * FitModel::SlightlyRough θ = (σ, T) in µm: B = the diffuse term of mean_scattered_power in
//                            the chosen regime (Eq. 3 by default; the exact series for moderately
//                            rough surfaces), × radiometric factor, at wavelength λ.
// Solved by the library's least-squares engine (engine.hpp: Ceres Levenberg–Marquardt on the
// logarithms of the parameters, which keeps them positive and makes the problem better scaled,
// with bounds, the gain K profiled out by variable projection — or fitted jointly under a robust
// loss — and an identifiability test). The covariance of all parameters, K included, is (JᵀJ)⁻¹
// from an SVD of the Jacobian at the solution, scaled by the residual variance SSE/(N − p) unless
// scale_covariance = false (then the weights must be 1/variance of the residuals), and is mapped
// to natural units by the delta method. Status: SolverStatus (engine.hpp); a parameter on a bound
// gives AtBound and FitParameter::at_bound, a rank-deficient Jacobian NotIdentifiable.
//
// Model comparison: AIC = N ln(SSE/N) + 2p (Gaussian errors of unknown variance), also the
// small-sample AICc = AIC + 2p(p+1)/(N − p − 1). Lower is better; compare_correlations fits both
// correlation functions and reports ΔAIC.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "roughscope/estimation/estimation.hpp"
#include "roughscope/fit/engine.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/factors.hpp"
#include "roughscope/scattering/geometry.hpp"

namespace roughscope {

// One brightness measurement at a geometry (paper frame, radians).
struct Measurement {
    Geometry geometry;
    double brightness = 0.0;  // > 0 (any unit; the gain K absorbs it)
    double weight = 1.0;      // > 0; multiplies the squared residual
};

enum class FitModel { VeryRough, SlightlyRough };
// ResidualType (relative — the default here —, absolute, log), LossType, SolverStatus: engine.hpp.

std::string_view to_string(FitModel m);           // "very_rough", "slightly_rough"
FitModel parse_fit_model(std::string_view name);  // throw InvalidArgument listing the names

struct FitOptions {
    FitModel model = FitModel::VeryRough;
    Correlation correlation = Correlation::Gaussian;
    GeometricFactor factor = GeometricFactor::VernoldHarvey;  // §4.2's recommendation
    Radiometry radiometry = Radiometry::Radiance;             // Harvey (§3.3)
    // SlightlyRough model only: the regime of the diffuse term (SlightlyRough = Eq. 3 / first
    // exponential term; Series or Auto = exact series) and the wavelength.
    Regime regime = Regime::SlightlyRough;
    double wavelength_um = 0.555;

    ResidualType residual = ResidualType::Relative;
    LossType loss = LossType::None;
    double loss_scale = 0.05;  // where the robust loss starts to bend, in residual units

    // Bounds (inclusive) of the fitted parameters.
    double sigma_over_T_min = 1e-3, sigma_over_T_max = 1e3;
    double sigma_min_um = 1e-4, sigma_max_um = 100.0;
    double T_min_um = 1e-4, T_max_um = 1e4;

    // Starting values; automatic when not given (docs/estimation.md): the very-rough model scans
    // 25 log-spaced σ/T over the bounds with K profiled out; the slightly-rough model starts from
    // the linear least squares of Eq. 3 in logs (a coarse scan when that fails).
    std::optional<double> initial_sigma_over_T;
    std::optional<double> initial_sigma_um;
    std::optional<double> initial_T_um;

    int max_iterations = 200;
    double function_tolerance = 1e-12;
    double gradient_tolerance = 1e-14;
    double parameter_tolerance = 1e-12;
    bool scale_covariance = true;  // multiply by SSE/(N − p) (noise level unknown)
};

struct FitResult {
    SolverStatus status = SolverStatus::Failed;
    std::string message;                        // Ceres' termination message and our notes
    FitOptions options;                         // what was fitted
    std::vector<FitParameter> parameters;       // "sigma_over_T" or "sigma_um", "T_um"; then "gain"
                                                // (gain bounds: 0, inf)
    std::vector<std::string> not_identifiable;  // names, when status is NotIdentifiable
    bool covariance_available = false;
    Eigen::MatrixXd covariance;     // natural units, order of `parameters`
    std::vector<double> residuals;  // weighted residuals at the solution
    std::vector<double> predicted;  // K · B(geom_i) at the solution
    double sse = 0.0;               // Σ residual²
    double aic = 0.0;               // N ln(SSE/N) + 2p
    double aicc = 0.0;              // AIC + 2p(p+1)/(N − p − 1) (inf when N ≤ p + 1)
    int num_measurements = 0;
    int num_parameters = 0;
    int iterations = 0;
    int evaluations = 0;        // model evaluations over all measurements
    double initial_cost = 0.0;  // Ceres cost ½ Σ ρ(r²) at the start and the end
    double final_cost = 0.0;
    RoughnessEstimate estimate;  // σ/T (σ, T), m, θK, ξK, g, class, warnings

    const FitParameter& parameter(std::string_view name) const;  // throws InvalidArgument
    std::string brief_report() const;  // one paragraph, like ceres::Solver::Summary::BriefReport
};

// Fits the model of `options` to the measurements. Throws InvalidArgument for bad input
// (no measurement, brightness or weight not > 0, a geometry outside [0°, 90°), bad options); a
// solver failure is reported in the result's status, not thrown. Data that cannot determine the
// parameters — fewer distinct geometries than parameters (gain included), e.g. one measurement
// or repeated geometries, or a rank-deficient Jacobian — give SolverStatus::NotIdentifiable:
// the message says why (measurements, distinct geometries, parameters), the parameters the data
// do not determine have FitParameter::identified = false, and the estimate leaves them (and
// what derives from them) empty. N = p measurements at distinct geometries determine the
// parameters exactly but give no standard errors (N − p = 0 degrees of freedom).
FitResult fit_roughness(const std::vector<Measurement>& measurements,
                        const FitOptions& options = {});

// Fits the same data with every correlation function (kCorrelations: Gaussian, exponential),
// all other options as given. preferred is the one with the lowest AIC (the first on a tie);
// delta_aic = AIC(next best) − AIC(preferred). A NotIdentifiable fit is never preferred over an
// identifiable one; delta_aic is NaN unless all are identifiable.
struct CorrelationComparison {
    // One fit per correlation function, read by correlation through operator[] (the two named
    // members are the form the photograph, CLI and Python code read).
    FitResult gaussian;
    FitResult exponential;
    Correlation preferred = Correlation::Gaussian;
    double delta_aic = 0.0;
    FitResult& operator[](Correlation c) {
        return c == Correlation::Gaussian ? gaussian : exponential;
    }
    const FitResult& operator[](Correlation c) const {
        return c == Correlation::Gaussian ? gaussian : exponential;
    }
};
CorrelationComparison compare_correlations(const std::vector<Measurement>& measurements,
                                           const FitOptions& options = {});

// The model brightness B(geom) the fit uses (gain 1), for the parameters of a model:
// {σ/T} for VeryRough, {σ_um, T_um} for SlightlyRough. Validates its inputs.
double fit_model_brightness(const Geometry& geom, const std::vector<double>& parameters,
                            const FitOptions& options);

}  // namespace roughscope
