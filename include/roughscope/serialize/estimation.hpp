// JSON schemas of the §4 estimates and the least-squares fits: the documents of
// `roughscope estimate ... --json` and the dicts of roughscope.estimate_* / fit_roughness /
// compare_correlations (keys in docs/estimation.md). Both front ends call these functions.
//
// `with_stderr`: add `<key>_stderr` beside every estimated quantity (when a noise level or a
// standard error of σ was given; fits always have them, null when the covariance is unavailable).
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include "roughscope/estimation/estimation.hpp"
#include "roughscope/estimation/propagation.hpp"
#include "roughscope/fit/fit.hpp"
#include "roughscope/serialize/json.hpp"

namespace roughscope::serialize {

// ---- Options built from JSON (the one place a front end's options become a FitOptions) -------
// Keys (all optional; null = the default of FitOptions): model, correlation, factor, radiometry,
// regime, residual, loss (names as in docs/estimation.md), wavelength_um, loss_scale,
// initial_sigma_over_T, initial_sigma_um, initial_T_um, sigma_over_T_bounds, sigma_bounds_um,
// T_bounds_um ([lower, upper]), max_iterations, scale_covariance. An unknown key or a value of the
// wrong type throws InvalidArgument naming the key.
FitOptions fit_options_from(const Json& options);

// ---- RoughnessEstimate ------------------------------------------------------------------------
// sigma_um, T_um, sigma_over_T, theta_K_deg, xi_K, rms_slope (each with _stderr when asked),
// roughness_class, roughness_class_assumed, g (list, null when σ is unknown), warnings.
Json to_json(const RoughnessEstimate& estimate, bool with_stderr);

// An uncertainty budget (estimation/propagation.hpp): [{"source", "u_input", "sensitivity",
// "contribution", "fraction"}, ...] in its order (largest contribution first).
Json budget_json(const std::vector<BudgetLine>& budget);

// ---- The estimators' documents --------------------------------------------------------------
// `estimate specular`: estimator, sigma_um, R_spec, R0, theta_deg, wavelength_um, derived keys.
Json specular_estimate_json(const SpecularInput& input, const RoughnessEstimate& estimate,
                            bool with_stderr);

// `estimate correlation-length`: estimator (Eq. 14–15 or the two-geometry solver, as the library
// chose), sigma_um, T_um, sigma_over_T, derived keys, E1_over_E2, geometry1/2, correlation,
// factor, regime, wavelength_um.
Json correlation_length_estimate_json(const CorrelationLengthInput& input,
                                      const RoughnessEstimate& estimate, bool with_stderr);

// `estimate slope` with one or more correlation functions (input.correlation is ignored; give the
// estimates that were computed). θK, ξK, m come from the Gaussian estimate when there is one (as
// in Table 2; the first given in kCorrelations order). Keys (<c> = each correlation's name,
// scattering/correlation.hpp): estimator, sigma_over_T, sigma_over_T_<c> (sigma_over_T_gaussian,
// sigma_over_T_exponential), sigma_um, T_um (T_um_<c> with all and σ known), derived keys,
// E1_over_E2, valid_ratio_range_<c> of each given ([lower, upper|null]; null off normal view),
// geometry1/2, factor, radiometry, warnings (prefixed "<c>: " when more than one is given).
// InvalidArgument if no estimate is given.
Json slope_estimate_json(const SlopeInput& input,
                         const PerCorrelation<std::optional<RoughnessEstimate>>& estimates,
                         bool with_stderr);
// The two-name form kept for the CLI and Python code: forwards to the one above.
Json slope_estimate_json(const SlopeInput& input, const std::optional<RoughnessEstimate>& gaussian,
                         const std::optional<RoughnessEstimate>& exponential, bool with_stderr);

// ---- Fits ------------------------------------------------------------------------------------
// One fit: correlation, status, sigma_over_T (sigma_um, T_um for the slightly-rough model), gain
// (each with _stderr), derived keys, sse, aic, aicc, n, parameters (their number), iterations,
// parameter_table (name, value, stderr, lower, upper, at_bound), covariance (null when
// unavailable), residuals and predicted (with_residuals), message, report, warnings.
Json to_json(const FitResult& fit, bool with_residuals);

// Every correlation function: preferred_correlation, delta_aic, the preferred fit's σ/T (and σ,
// T), sigma_over_T_<c> (+ _stderr; sigma_over_T_gaussian, sigma_over_T_exponential), θK, ξK, m,
// class and g of the Gaussian fit, then one to_json(FitResult) per correlation under its name
// (gaussian, exponential), warnings (prefixed by the correlation).
Json to_json(const CorrelationComparison& comparison, bool with_residuals);

// `estimate fit`: estimator, measurements, factor, radiometry, residual, loss, then the keys of
// the fit (one correlation) or of the comparison (both).
Json fit_estimate_json(const FitOptions& options, std::size_t measurements, const FitResult& fit,
                       bool with_residuals);
Json fit_estimate_json(const FitOptions& options, std::size_t measurements,
                       const CorrelationComparison& comparison, bool with_residuals);

// The text report of an `estimate` document (any of the above, without --json): "key  value"
// lines in the document's order, numbers with 10 significant digits, null as "unknown", a valid
// ratio range as "(lower, upper)" or "> lower", nested objects left out (JSON only), then
// "warning: ..." lines.
std::string estimate_text(const Json& record);

}  // namespace roughscope::serialize
