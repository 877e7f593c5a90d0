// The library's one least-squares engine (Ceres, Levenberg–Marquardt with bounds). Every fit in
// roughscope goes through it: fit_roughness / compare_correlations (fit.hpp, paper §4 "least-square
// fitting techniques") and the model fits of the measured-BRDF comparison (brdf/comparison.hpp,
// paper §5.3, Table 4 "+ fit" columns).
//
// Problem: data y_i (weights w_i ≥ 0) against a caller-supplied model M_i(θ), θ = named parameters
// with inclusive bounds, optionally times an unknown linear gain K:
//      minimise Σ_i ρ(r_i²),   r_i = √w_i · residual(K M_i(θ), y_i)
// with residual = K M − y (Absolute), (K M − y)/y (Relative) or ln(K M) − ln y (Log), and ρ the
// identity or a robust loss (Huber, Cauchy, soft L1; scale `loss_scale`, in residual units).
//
// Parameters: Transform::Log optimises ln θ (positive parameters; better scaled), Transform::Linear
// optimises θ itself; bounds are Ceres bounds on the optimised variable. Derivatives are Ceres'
// central numeric differences (DynamicNumericDiffCostFunction).
//
// Gain: GainMode::Profiled eliminates K by variable projection (for given θ the optimal K has a
// closed form, optimal_gain below) so Ceres only searches θ; GainMode::Free makes K an ordinary
// unbounded parameter (needed with a robust loss, for which the closed form is not the optimum;
// solve_least_squares switches to Free by itself then). Both report K and its covariance.
//
// Starting point: a parameter's `initial` value, else the best point of a grid (log-spaced for
// Log parameters) over its start range (default: its bounds) — a tensor grid when several
// parameters lack a start, with the gain profiled out. `num_starts` > 1 runs the solver from that
// many of the best grid points and keeps the lowest cost.
//
// At the solution: residuals, SSE = Σ r_i² (unrobustified), AIC = N ln(SSE/N) + 2p and
// AICc = AIC + 2p(p+1)/(N − p − 1) (p counts the gain), and the covariance of all parameters
// (gain last) s²(JᵀJ)⁻¹ from an SVD of the Jacobian of the unprojected residuals (rows scaled by
// √ρ'(r²) for a robust loss), s² = SSE/(N − p) unless scale_covariance is false (then the weights
// must be 1/variance), mapped to natural units by the delta method.
//
// Status (one enum for the whole library):
//  * Converged        Ceres converged, every parameter strictly inside its bounds, Jacobian of
//                     full rank;
//  * AtBound          converged with one or more parameters on a bound (flagged per parameter
//                     by FitParameter::at_bound, named in the message). Such a parameter is
//                     fixed by its bound: it is left out of the identifiability test, and its
//                     standard error is not meaningful;
//  * NotIdentifiable  the data cannot determine the parameters: fewer data points (with w > 0)
//                     than parameters, or a rank-deficient Jacobian of the free parameters
//                     (repeated geometries, constant data, a parameter with no effect, two
//                     parameters that trade off exactly). The message names the parameters;
//                     `not_identifiable` lists them. Never reported as Converged;
//  * NoConvergence    the iteration limit was reached;
//  * Failed           the model could not be evaluated at the start or at the solution, or Ceres
//                     failed (message says why).
// Bad input (sizes, bounds, a start outside its bounds, non-finite data, a non-positive datum
// with relative/log residuals, bad options) throws InvalidArgument naming the value and its valid
// range. The engine never prints: Ceres' logging is silenced.
#pragma once

#include <functional>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

namespace roughscope {

enum class ResidualType {
    Relative,  // √w (K M − y)/y: suited to a relative (multiplicative) noise
    Absolute,  // √w (K M − y)
    Log,       // √w (ln(K M) − ln y)
};
enum class LossType { None, Huber, Cauchy, SoftLOne };
enum class SolverStatus { Converged, AtBound, NotIdentifiable, NoConvergence, Failed };
enum class Transform { Log, Linear };
enum class GainMode { None, Profiled, Free };

std::string_view to_string(ResidualType r);  // "relative", "absolute", "log"
std::string_view to_string(LossType l);      // "none", "huber", "cauchy", "soft_l_one"
// "converged", "at_bound", "not_identifiable", "no_convergence", "failed"
std::string_view to_string(SolverStatus s);
ResidualType parse_residual_type(std::string_view name);  // throw InvalidArgument listing names
LossType parse_loss_type(std::string_view name);

// A parameter of the model.
struct ParameterSpec {
    std::string name;
    double lower = 0.0;  // inclusive bounds; ±inf allowed (Log: lower ≥ 0, upper > 0)
    double upper = std::numeric_limits<double>::infinity();
    Transform transform = Transform::Log;
    std::optional<double> initial;  // start value (inside the bounds); else a grid start
    // Grid start for this parameter: range (default the bounds, which must then be finite; Log
    // needs a positive lower end) and number of points (0: LeastSquaresOptions::grid_points).
    std::optional<double> start_lower, start_upper;
    int grid_points = 0;
};

// Computes the model values M_i(θ) for every data point (out has the data's size) from the
// parameters in natural units. Returns false when the model cannot be evaluated there.
using ModelFunction = std::function<bool(std::span<const double> theta, std::span<double> out)>;

struct LeastSquaresProblem {
    std::vector<ParameterSpec> parameters;
    ModelFunction model;
    std::vector<double> data;     // y_i, finite (> 0 for Relative and Log residuals)
    std::vector<double> weights;  // empty: all 1; else finite, ≥ 0, one per datum
    ResidualType residual = ResidualType::Absolute;
    GainMode gain = GainMode::None;  // y ≈ K · M(θ) with K profiled or free
};

struct LeastSquaresOptions {
    int max_iterations = 200;
    double function_tolerance = 1e-12;  // Ceres' tolerances (relative cost change,
    double gradient_tolerance = 1e-14;  // projected gradient, relative step)
    double parameter_tolerance = 1e-12;
    LossType loss = LossType::None;
    double loss_scale = 0.05;      // where the robust loss starts to bend, in residual units
    bool scale_covariance = true;  // multiply (JᵀJ)⁻¹ by SSE/(N − p) (noise level unknown)
    int grid_points = 25;          // default points per parameter of the grid start
    int num_starts = 1;            // solver runs from the best grid points
    // Identifiability: the Jacobian of the free parameters (columns scaled to unit norm) is
    // rank deficient when its smallest singular value is below rank_tolerance × the largest (two
    // parameters whose effects are parallel to within ~1e-6 rad), or a column norm is below
    // rank_tolerance × the largest column norm (a parameter with no effect: an e-fold change of a
    // Log parameter, a unit change of a Linear one, moves the predictions by less than 1e-6 of
    // what the strongest parameter does — e.g. a lobe width run off to where the lobe is flat).
    double rank_tolerance = 1e-6;
};

// One fitted parameter (the model's, then "gain").
struct FitParameter {
    std::string name;
    double value = 0.0;
    double std_error = 0.0;  // valid when the result's covariance_available (0 otherwise)
    double lower = 0.0;      // bounds (gain: −inf, inf)
    double upper = 0.0;
    bool at_bound = false;  // the solution sits on a bound: its std_error is not meaningful
    // False when the data do not determine it (listed in the result's not_identifiable): `value`
    // is then only where the solver stopped, an arbitrary point of a flat direction, and is not
    // a result (reports show "not identifiable" instead of the number).
    bool identified = true;
};

// The end of a brief report: " name = value +/- std_error; ...; SSE = ..., AIC = .... message"
// (std_error only when the covariance is available and the parameter is not on a bound; a
// parameter that is not identified shows " name not identifiable;" and no number).
std::string brief_report_tail(const std::vector<FitParameter>& parameters,
                              bool covariance_available, double sse, double aic,
                              const std::string& message);

// The parameter called `name`; throws InvalidArgument listing the names there are.
const FitParameter& find_parameter(const std::vector<FitParameter>& parameters,
                                   std::string_view name);

struct LeastSquaresResult {
    SolverStatus status = SolverStatus::Failed;
    std::string message;                        // Ceres' termination message and the engine's notes
    std::vector<FitParameter> parameters;       // the problem's parameters, then "gain" if fitted
    std::vector<std::string> not_identifiable;  // names, when status is NotIdentifiable
    bool covariance_available = false;
    Eigen::MatrixXd covariance;     // natural units, order of `parameters`
    std::vector<double> model;      // M_i(θ) at the solution (gain 1)
    std::vector<double> predicted;  // K M_i(θ) (M_i without a gain)
    std::vector<double> residuals;  // √w_i residual_i at the solution (unrobustified)
    double gain = 1.0;              // K (1 without a gain)
    double sse = 0.0;               // Σ residual²
    double aic = 0.0;               // N ln(SSE/N) + 2p
    double aicc = 0.0;              // AIC + 2p(p+1)/(N − p − 1) (inf when N ≤ p + 1)
    int num_data = 0;               // data points with w > 0
    int num_parameters = 0;         // p, including the gain
    int iterations = 0;             // Ceres iterations (sum over the starts)
    int evaluations = 0;            // model evaluations over the whole data set
    double initial_cost = 0.0;      // Ceres cost ½ Σ ρ(r²) at the start and the end
    double final_cost = 0.0;

    const FitParameter& parameter(std::string_view name) const;  // throws InvalidArgument
    double value(std::string_view name) const { return parameter(name).value; }
    std::string brief_report() const;  // one paragraph, like ceres::Solver::Summary::BriefReport
};

// Solves the problem. Throws InvalidArgument for bad input; solver outcomes are in the status.
LeastSquaresResult solve_least_squares(const LeastSquaresProblem& problem,
                                       const LeastSquaresOptions& options = {});

// The gain K minimising Σ w (residual(K M, y))² for fixed model values (closed form):
// Absolute Σw M y / Σw M², Relative Σw (M/y) / Σw (M/y)², Log exp(Σw (ln y − ln M) / Σw).
// NaN when undefined (Σw M² = 0, a non-positive value under Log).
double optimal_gain(std::span<const double> model, std::span<const double> data,
                    std::span<const double> weights, ResidualType residual);

// Σ w residual² with the gain profiled out (or no gain), +inf when the model cannot be evaluated:
// the objective of the grid start, for callers that scan or plot it.
double profiled_sse(const LeastSquaresProblem& problem, std::span<const double> theta,
                    double* gain = nullptr);

}  // namespace roughscope
