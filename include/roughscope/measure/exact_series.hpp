// The exact series where the capture set allows it (docs/uncertainty.md "Model error"): Eq. 17 /
// 19 assume the very-rough limit g ≫ 1 and are tens of percent off at g ≈ 0.2–30; the diffuse
// term summed exactly (Eq. 2's series, scattering/beckmann.hpp Regime::Series) holds at any g.
//
//  * σ known (MeasureRequest::sigma_um, or Eq. 13 from a specular capture) and a diffuse pair:
//    T given σ from the first pair's E1/E2 in Regime::Series for each correlation, σ/T = σ/T_series
//    ("T given σ"); its uncertainty is the budget's (budget.hpp: sigma_over_T_series_*,
//    T_um_series_*): angles, exposures, black level, response, λ, σ's uncertainty, pixel noise.
//  * otherwise ≥ 3 diffuse captures at distinct geometries: σ and T fitted jointly with a gain
//    (fit.hpp, FitModel::SlightlyRough, Regime::Series) for each correlation ("fit of N
//    captures"); its ± is the fit's covariance from each capture's brightness noise (pixel noise
//    and the exposure tolerance in quadrature), scaled up by the reduced χ² when that exceeds 1:
//    the angles, black level and response are not propagated (ExactSeriesEstimate::covers). The
//    95 % intervals are the profile likelihood's (Δχ² ≤ 3.84 × max(1, χ²/(N − 3)) over a grid
//    of (σ, T), the gain profiled out), which also finds a better minimum than the fit's when
//    there is one and shows when σ or T is not determined (σ at small g, where the diffuse term
//    is nearly ∝ σ²: the gain absorbs it).
//
// Each correlation's estimate is set beside the closed form of the first pair (Eq. 17 / 19, or
// the very-rough solver off the normal view): closed_form_deviation_rel = (closed − series)/series.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "roughscope/estimation/estimation.hpp"
#include "roughscope/scattering/correlation.hpp"

namespace roughscope::image {

struct MeasureRequest;
struct MeasureResult;

enum class ExactSeriesMethod { SigmaKnown, Fit };
std::string_view to_string(ExactSeriesMethod method);  // "t_given_sigma", "fit"

// One correlation function's exact-series estimate.
struct ExactSeriesCorrelation {
    Correlation correlation = Correlation::Gaussian;
    std::optional<Estimate> sigma_um;  // given / from the specular capture, or fitted
    std::optional<Estimate> T_um;
    // std_error: the standard uncertainty (k = 1) of what `covers` says; NaN when unknown.
    std::optional<Estimate> sigma_over_T;
    std::optional<double> interval95_low;  // σ/T's 95 % interval
    std::optional<double> interval95_high;
    // The fit only: profile-likelihood 95 % intervals of σ and T (the σ/T interval above is the
    // profile's too), and whether the captures determine each: a parameter whose interval reaches
    // the searched range (100× either side of the estimate, within the fit's bounds) is not
    // determined on that side (a warning says so).
    std::optional<std::array<double, 2>> sigma_um_interval95;
    std::optional<std::array<double, 2>> T_um_interval95;
    bool sigma_determined = true;
    bool T_determined = true;
    std::optional<double> closed_form_sigma_over_T;  // Eq. 17 / 19 (first pair)
    std::optional<double> closed_form_deviation_rel;
    // The closed form lies outside the exact series' 95 % interval and its own stated
    // uncertainty does not reach the series value (a warning says so).
    bool closed_form_off = false;
    std::vector<double> g;   // g = σ² v_z² at each capture used (σ of this estimate)
    std::string fit_status;  // fit only: SolverStatus of the fit ("converged", ...)
    std::string failure;     // empty, else why this correlation has no estimate
};

struct ExactSeriesEstimate {
    ExactSeriesMethod method = ExactSeriesMethod::SigmaKnown;
    std::vector<std::size_t> captures;  // indices into MeasureResult::captures (diffuse, used)
    std::string covers;                 // what the ± of the estimates covers
    std::vector<ExactSeriesCorrelation> correlations;  // Gaussian, exponential
    std::vector<std::string> warnings;

    const ExactSeriesCorrelation* operator[](Correlation c) const;
};

// "T given σ", or "fit of N captures" (N = ExactSeriesEstimate::captures.size()).
std::string describe(const ExactSeriesEstimate& estimate);

// The exact-series estimate of a flat sample's measurement (after the budget: the T-given-σ path
// reads its uncertainty from result.uncertainty). nullopt when the capture set allows neither
// path (σ unknown and fewer than 3 diffuse captures at distinct geometries). Never throws for a
// ratio or fit without solution: that correlation's `failure` says why.
std::optional<ExactSeriesEstimate> exact_series_estimate(const MeasureRequest& request,
                                                         const MeasureResult& result);

}  // namespace roughscope::image
