// Planning a capture (docs/uncertainty.md "Planning a capture"): the pair of light zeniths θ1 < θ2
// (camera on the normal, both lights on one side) whose measurement of σ/T by Eq. 17 / Eq. 19 has
// the smallest standard uncertainty, predicted before any photograph is taken from the setup's
// tolerances (measure/budget.hpp) and a model of the camera.
//
// The measurement model is the budget's (src/measure/budget.cpp): E_k = m_k(δb)(1 + n_k) /
// (s_k(1 + ε_k)) for each capture k, the angles of each light and the camera's tilt (one error
// for both captures) moving the geometries the ratio is inverted with. The true ratio E1/E2 is
// the forward model's (model_ratio_very_rough) at the expected σ/T; each pair's u(σ/T) is the
// first-order propagation (estimation/propagation.hpp) of those inputs.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "roughscope/estimation/propagation.hpp"
#include "roughscope/measure/budget.hpp"
#include "roughscope/scattering/correlation.hpp"
#include "roughscope/scattering/factors.hpp"

namespace roughscope::image {

// How the two exposures are chosen. PerCapture: each capture is exposed so that the sample
// reaches `fill` of full scale (its region mean m_k = fill): both have the same relative pixel
// noise, and a black-level error moves both means alike (it cancels in E1/E2 to first order).
// Common: one exposure for both, the brighter capture at `fill`, the darker at fill · E_dark /
// E_bright: its relative noise grows as √(fill / m_k) (shot noise) and a black-level error δb
// moves its E by −δb/(m_k (W − b)), more than the brighter one's.
enum class PlanExposure { PerCapture, Common };
std::string_view to_string(PlanExposure exposure);  // "per_capture", "common"
PlanExposure parse_plan_exposure(std::string_view name);

struct PlanRequest {
    // The expected σ/T (> 0); with sigma_over_T_max, the range [sigma_over_T, sigma_over_T_max]
    // at range_points points evenly spaced (both ends included), the worst case minimised.
    double sigma_over_T = 0.0;
    std::optional<double> sigma_over_T_max;
    std::size_t range_points = 5;  // 2–50 (a range only)
    Correlation correlation = Correlation::Gaussian;
    GeometricFactor factor = GeometricFactor::VernoldHarvey;
    // The setup's standard uncertainties (the capture file's "uncertainty" keys): angle_deg (each
    // light's zenith and the camera's tilt) and exposure_rel are used; black_level_dn with
    // full_scale_dn (W − b, DN) gives black_level_rel. Unset: the defaults of budget.hpp, listed
    // in CapturePlan::assumed. response_gamma, wavelength_um and flat_field_rel do not enter σ/T
    // of a linear capture and are not used.
    SetupTolerances tolerances;
    std::optional<double> black_level_rel;  // u(b)/(W − b); default kDefaultBlackLevelFraction
    std::optional<double> full_scale_dn;    // W − b, to read tolerances.black_level_dn
    // The camera: the relative standard uncertainty of the region mean of a capture at `fill` of
    // full scale (0 ≤ noise_rel < 0.5), and the fraction of full scale reached (0 < fill ≤ 1).
    double noise_rel = 0.002;
    double fill = 0.8;
    PlanExposure exposure = PlanExposure::PerCapture;
    // The grid of light zeniths θ (degrees, 0 ≤ min ≤ max < 90, step > 0) and the smallest
    // θ2 − θ1 allowed (≥ 0; pairs closer carry little information about σ/T).
    double theta_min_deg = 5.0;
    double theta_max_deg = 75.0;
    double theta_step_deg = 1.0;
    double min_difference_deg = 5.0;
    std::size_t top = 10;  // pairs listed in CapturePlan::top (1–1000)
    // How the recommended and the reference pair are propagated once chosen (Auto: Monte Carlo
    // where the model is not near-linear); the search is first order.
    PropagationOptions propagation;
    std::size_t threads = 0;  // 0: every core; the result does not depend on it
};

// One pair of light zeniths and its predicted σ/T uncertainty.
struct PlannedPair {
    double theta1_deg = 0.0;
    double theta2_deg = 0.0;
    bool has_value = false;  // u(σ/T) is known at every σ/T of the request
    std::string reason;      // why not (E1/E2 outside the model's range, ...), else empty
    // The σ/T (of the request's points) where u(σ/T)/(σ/T) is largest, the predicted E1/E2
    // there, and the propagation there: result.value = that σ/T, result.uncertainty = u (k = 1).
    double sigma_over_T = 0.0;
    double E1_over_E2 = 0.0;
    double relative_uncertainty = 0.0;  // u/(σ/T): the ranking key, smallest first
    OutputUncertainty result;
    PropagationMethod method = PropagationMethod::FirstOrder;
};

struct CapturePlan {
    PlanRequest request;  // as given
    // The tolerances used (the request's, else the defaults) and the σ/T evaluated.
    double angle_deg = 0.0;
    double exposure_rel = 0.0;
    double black_level_rel = 0.0;
    std::vector<double> sigma_over_T_points;
    std::size_t pairs = 0;             // pairs of the grid with θ2 − θ1 ≥ min_difference_deg
    std::size_t pairs_with_value = 0;  // of which u(σ/T) is known at every point
    PlannedPair recommended;           // the smallest u(σ/T)/(σ/T) (worst case over a range)
    PlannedPair reference;             // the paper's 30°/45°, whatever the grid
    std::vector<PlannedPair> top;      // the best `top` pairs, best first (first order)
    std::vector<std::string> assumed;  // tolerances taken from the defaults ("angle_deg = 0.5°")
    std::vector<std::string> warnings;
};

// The pair of light zeniths with the smallest predicted u(σ/T). Throws InvalidArgument naming
// the field and its valid range for a request out of range (σ/T ≤ 0, an empty grid, a negative
// tolerance, ...), and NoSolution when no pair of the grid has a value at every σ/T.
CapturePlan plan_capture(const PlanRequest& request);

}  // namespace roughscope::image
