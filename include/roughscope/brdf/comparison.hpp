// Models against measured BRDFs (paper §5.3, Tables 3–4, Fig. 10), for a CUReT sample or any
// BRDF table.
//
// Per table: the data brightness d_j = f_j cos θi_j (brdf_table.hpp) and, for each model, the
// predicted brightness M_j at the same geometry (the paper's frame). Models:
//  * oren_nayar        Oren–Nayar with inter-reflection (models.hpp) with GIVEN σ_ON, ρ_ON (for
//                      CUReT samples 25, 34, 41 the paper's Table 3 values; else user-given).
//  * lafortune         Lafortune diffuse lobe E ∝ (cos θi cos θs)^n cos θi, n_d by the paper's
//                      exhaustive search of [0.1, 20] (step 0.01) for the lowest Table-4 error.
//  * bk_gaussian, bk_exponential   original B–K (F_Beck), very-rough Eq. 4 / Eq. 5 as published,
//  * vh_gaussian, vh_exponential   V–H modification (F_VH),
//                      all four at the two-point estimate σ/T of Table 3 (Eq. 17 / Eq. 19 with
//                      F_VH from measurements 81 and 112; the B–K columns use the same σ/T,
//                      which is what reproduces Table 4).
//  * *_fit             least squares over every used measurement with an unknown gain K:
//                      min over (params, K) of Σ w_j (K M_j − d_j/max d)². σ/T for B–K and V–H,
//                      n for Lafortune, (σ_ON, ρ_ON) for Oren–Nayar (the fair comparison the
//                      paper did not make). Solved by the library's least-squares engine
//                      (fit/engine.hpp: K profiled out, grid start, Levenberg–Marquardt with
//                      bounds, covariance and identifiability from the Jacobian); the fitted
//                      gain is the parameter "gain".
//
// Error measures per model (ErrorMeasures):
//  * paper_sse  the paper's Table 4 figure: Σ_j w_j (M_j/max M − d_j/max d)², a SUM over the
//               measurements (205 for CUReT), not divided by their number;
//  * rmse       sqrt(paper_sse / Σ w);
//  * gain_sse   min over K of Σ w_j (K M_j − d_j/max d)²: scale-free, does not hinge on the
//               single brightest measurement.
//
// Non-positive data values (43 in CUReT, noise around zero) are KEPT in every error sum and fit
// (dropping them would bias the sums; the paper kept them). They are EXCLUDED only from what needs
// positive values: the two-point ratio E1/E2 (unavailable, with the reason, when measurement 81 or
// 112 is ≤ 0, as for CUReT sample 61). Each is listed in Comparison::data_issues. Measurements with
// a published overflow (saturation) fraction above ComparisonOptions::max_overflow_fraction are
// excluded from everything and listed too.
#pragma once

#include <array>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "roughscope/brdf/curet.hpp"
#include "roughscope/brdf/table.hpp"
#include "roughscope/fit/engine.hpp"
#include "roughscope/scattering/correlation.hpp"
#include "roughscope/scattering/factors.hpp"
#include "roughscope/scattering/reflectance_models.hpp"

namespace roughscope {

enum class ComparisonModel {
    // the paper's methods (Table 4 columns)
    OrenNayar,
    Lafortune,
    BkGaussian,
    BkExponential,
    VhGaussian,
    VhExponential,
    // least-squares fits with an unknown gain
    OrenNayarFit,
    LafortuneFit,
    BkGaussianFit,
    BkExponentialFit,
    VhGaussianFit,
    VhExponentialFit,
};

inline constexpr std::array<ComparisonModel, 12> kComparisonModels = {
    ComparisonModel::OrenNayar,     ComparisonModel::Lafortune,
    ComparisonModel::BkGaussian,    ComparisonModel::BkExponential,
    ComparisonModel::VhGaussian,    ComparisonModel::VhExponential,
    ComparisonModel::OrenNayarFit,  ComparisonModel::LafortuneFit,
    ComparisonModel::BkGaussianFit, ComparisonModel::BkExponentialFit,
    ComparisonModel::VhGaussianFit, ComparisonModel::VhExponentialFit,
};
// The six columns of Table 4, in its order.
inline constexpr std::array<ComparisonModel, 6> kPaperComparisonModels = {
    ComparisonModel::OrenNayar,     ComparisonModel::Lafortune,  ComparisonModel::BkGaussian,
    ComparisonModel::BkExponential, ComparisonModel::VhGaussian, ComparisonModel::VhExponential,
};

// "oren_nayar", "lafortune", "bk_gaussian", ..., "vh_exponential_fit" (the JSON keys).
std::string_view to_string(ComparisonModel model);
// The paper's labels: "O–N", "LFTG", "B–K(G)", "B–K(E)", "V–H–B–K(G)", "V–H–B–K(E)", "+ fit".
std::string_view display_name(ComparisonModel model);
ComparisonModel parse_comparison_model(std::string_view name);  // throws InvalidArgument
bool is_fit(ComparisonModel model);

// ---------------------------------------------------------------------------------------------
// Error measures

struct ErrorMeasures {
    double paper_sse = 0.0;  // Table 4: Σ w (M/max M − d/max d)²
    double rmse = 0.0;       // sqrt(paper_sse / Σ w)
    double gain_sse = 0.0;   // min_K Σ w (K M − d/max d)²
    double gain = 0.0;       // that K
};

// The three measures for model values M and data d (same length ≥ 1, finite; weights empty = all
// 1, else same length, finite, ≥ 0 with a positive sum). max(d) and max(M) must be > 0.
// Throws InvalidArgument naming the input otherwise.
ErrorMeasures error_measures(std::span<const double> model, std::span<const double> data,
                             std::span<const double> weights = {});

// ---------------------------------------------------------------------------------------------
// Per-model results

struct ModelParameter {
    std::string name;  // "sigma_over_T", "n", "sigma_rad", "albedo", "gain"
    double value = 0.0;
    // Fits only: from the covariance at the optimum; none for a parameter on a bound of its
    // range, or when the parameters are not identifiable.
    std::optional<double> standard_error;
    // False when the data do not determine it (a NotIdentifiable fit or search): `value` is then
    // an arbitrary point of a flat direction, not a result; reports show no number for it.
    bool identified = true;
};

struct ModelResult {
    ComparisonModel model = ComparisonModel::OrenNayar;
    bool available = false;
    std::string reason;  // why the model is unavailable (empty when available)
    std::string method;  // how its parameters were obtained
    std::vector<ModelParameter> parameters;
    // Fits (engine.hpp's status: converged, at_bound, not_identifiable, no_convergence,
    // failed) and the exhaustive Lafortune search (converged, or at_bound at an end of its grid).
    std::optional<SolverStatus> fit_status;
    std::string fit_message;
    std::vector<double> covariance;  // fits: row-major over `parameters` (incl. gain last);
                                     // empty when unavailable
    int evaluations = 0;             // model evaluations over the whole table
    ErrorMeasures errors;
    std::vector<double> prediction;  // model brightness at each used measurement (empty when
                                     // ComparisonOptions::keep_predictions is false)

    // The value of parameter `name`; none when there is no such parameter or the data do not
    // determine it (ModelParameter::identified false).
    std::optional<double> parameter(std::string_view name) const;
    // Available, and its parameters are determined by the data: not a NotIdentifiable fit or
    // search none of whose shape parameters (the gain aside) is identified. Only such models
    // enter the winners.
    bool identified() const;
};

// The two-point estimate of Table 3 (paper §4.2, Eq. 16–19, F_VH, viewer on the normal).
struct TwoPointEstimate {
    bool available = false;  // E1/E2 computed (both brightness values > 0, geometry valid)
    std::string reason;      // why not
    int measurement1 = 0, measurement2 = 0;
    double theta1_rad = 0.0, theta2_rad = 0.0;
    std::optional<double> E1, E2;  // f cos θi of the two measurements, when they exist
    std::optional<double> E1_over_E2;
    std::optional<double> sigma_over_T_gaussian;     // Eq. 17
    std::string gaussian_reason;                     // why unavailable (e.g. NoSolution)
    std::optional<double> sigma_over_T_exponential;  // Eq. 19
    std::string exponential_reason;
    // The same by correlation (the named members are the form the CLI reads).
    std::optional<double>& sigma_over_T(Correlation c) {
        return c == Correlation::Gaussian ? sigma_over_T_gaussian : sigma_over_T_exponential;
    }
    const std::optional<double>& sigma_over_T(Correlation c) const {
        return c == Correlation::Gaussian ? sigma_over_T_gaussian : sigma_over_T_exponential;
    }
    std::string& correlation_reason(Correlation c) {
        return c == Correlation::Gaussian ? gaussian_reason : exponential_reason;
    }
    const std::string& correlation_reason(Correlation c) const {
        return c == Correlation::Gaussian ? gaussian_reason : exponential_reason;
    }
};

// A measurement the comparison treats specially.
struct DataIssue {
    int measurement = 0;
    double value = 0.0;                      // the BRDF value
    std::string issue;                       // "non_positive", "saturated", "zero_weight"
    std::vector<std::string> excluded_from;  // "two_point_estimate" or "all"; empty = kept
    std::string note;                        // one sentence for people
};

struct ComparisonOptions {
    // §3.3 interpretation for the B–K models; Radiance (Harvey) reproduces Table 4.
    Radiometry radiometry = Radiometry::Radiance;
    // Two-point pair (measurement numbers) and, optionally, their incidence angles; by default the
    // table's θi of the two measurements are used (CUReT: 45° and 67.5° to 1e−6 rad).
    int measurement1 = kCuretTwoPointMeasurement1;
    int measurement2 = kCuretTwoPointMeasurement2;
    std::optional<double> theta1_rad;
    std::optional<double> theta2_rad;
    // The pair must have θv below this (Eq. 16–19 assume the viewer on the normal).
    double normal_view_tolerance_rad = 1e-4;
    // Given Oren–Nayar parameters (compare_curet_sample fills in Table 3 for 25, 34, 41).
    std::optional<OrenNayarParams> oren_nayar;
    std::string oren_nayar_source = "given";
    // The paper's exhaustive search for the Lafortune exponent.
    double lafortune_n_min = 0.1;
    double lafortune_n_max = 20.0;
    double lafortune_n_step = 0.01;
    // Least-squares fits (set false for the paper's methods only).
    bool fits = true;
    double fit_sigma_over_T_min = 0.01;  // bounds of the σ/T fits
    double fit_sigma_over_T_max = 100.0;
    double fit_lafortune_n_min = 0.01;  // bounds of the continuous Lafortune fit
    double fit_lafortune_n_max = 100.0;
    double fit_oren_nayar_sigma_max_rad = 1.5;  // σ_ON in [0, this], ρ_ON in [0, 1]
    // Exclude measurements whose published overflow fraction exceeds this (default: keep all).
    std::optional<double> max_overflow_fraction;
    // Keep ModelResult::prediction (N values per model); false leaves it empty once the errors
    // are computed (a large table whose predictions are not output).
    bool keep_predictions = true;
    // Worker threads of the Lafortune search (0 = all cores); the result does not depend on it.
    std::size_t threads = 0;
};

struct Comparison {
    std::string name;
    int sample = 0;  // CUReT sample number, 0 for other tables
    std::string channel;
    std::size_t total_measurements = 0;
    // The measurements used (table order): index, geometry, data brightness d = f cos θi, weight.
    std::vector<int> measurement;
    std::vector<Geometry> geometry;
    std::vector<double> brightness;
    std::vector<double> weight;
    TwoPointEstimate two_point;
    std::vector<ModelResult> models;  // one per kComparisonModels entry, same order
    std::vector<DataIssue> data_issues;
    // Lowest gain_sse among every identified model (ModelResult::identified; fits included): the
    // scale-free verdict. None when no model is identified (e.g. a one-row table).
    std::optional<ComparisonModel> winner;
    // Lowest paper_sse among the paper's six methods that are identified (the Table 4 verdict).
    std::optional<ComparisonModel> winner_paper_metric;

    const ModelResult& result(ComparisonModel model) const;
};

// Validates the options (InvalidArgument naming the field).
void validate(const ComparisonOptions& options);

// Compares every model with one BRDF table. Throws InvalidArgument for bad options or an empty
// table; data problems (non-positive values, a missing pair, no positive value at all) are
// reported in the result, never thrown.
Comparison compare_brdf(const BrdfTable& table, const ComparisonOptions& options = {});
// The same, releasing the table's measurements as soon as they have been read (less memory for
// a large table); `table` is left with its name and channel only.
Comparison compare_brdf(BrdfTable&& table, const ComparisonOptions& options = {});

// One CUReT sample: compare_brdf on its table, with the paper's Table 3 O–N parameters when the
// options give none and the sample has them. InvalidArgument for a sample not in the database.
Comparison compare_curet_sample(const CuretDatabase& db, int sample,
                                const ComparisonOptions& options = {});

// Every sample of the database, in file order, on `threads` threads (0: hardware concurrency).
std::vector<Comparison> compare_curet_all(const CuretDatabase& db,
                                          const ComparisonOptions& options = {}, int threads = 0);

}  // namespace roughscope
