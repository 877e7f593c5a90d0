// Least-squares roughness fits (paper §4, "least-square fitting techniques") on the engine
// (engine.hpp).
#include "roughscope/fit/fit.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include <Eigen/Dense>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/names.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/scattering/precomputed_terms.hpp"
#include "roughscope/scattering/validity.hpp"

namespace roughscope {

// ---------------------------------------------------------------------------------------------
// Names

namespace {
constexpr std::array<NameEntry<FitModel>, 2> kFitModelNames{{
    {"very_rough", FitModel::VeryRough},
    {"slightly_rough", FitModel::SlightlyRough},
}};
}  // namespace

std::string_view to_string(FitModel m) { return name_of(kFitModelNames, m); }

FitModel parse_fit_model(std::string_view name) {
    return parse_name(kFitModelNames, "fit model", name);
}

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

int model_parameter_count(const FitOptions& o) { return o.model == FitModel::VeryRough ? 1 : 2; }

void check_bounds(std::string_view name, double lo, double hi) {
    check::positive(std::string(name) + " lower bound", lo);
    check::positive(std::string(name) + " upper bound", hi);
    if (!(lo < hi))
        throw InvalidArgument(std::string(name) + " bounds [" + format_message(lo, 6) + ", " +
                              format_message(hi, 6) +
                              "] are empty: the lower bound must be below the upper bound");
}

void check_initial(std::string_view name, const std::optional<double>& v, double lo, double hi) {
    if (!v) return;
    check::positive(std::string("initial ") + std::string(name), *v);
    if (*v < lo || *v > hi)
        throw InvalidArgument("initial " + std::string(name) + " = " + format_message(*v, 6) +
                              " is outside its bounds [" + format_message(lo, 6) + ", " +
                              format_message(hi, 6) + "]");
}

void check_options(const FitOptions& o) {
    check::positive("wavelength", o.wavelength_um, "um");
    check::positive("loss scale", o.loss_scale);
    check_bounds("sigma/T", o.sigma_over_T_min, o.sigma_over_T_max);
    check_bounds("sigma", o.sigma_min_um, o.sigma_max_um);
    check_bounds("T", o.T_min_um, o.T_max_um);
    check_initial("sigma/T", o.initial_sigma_over_T, o.sigma_over_T_min, o.sigma_over_T_max);
    check_initial("sigma", o.initial_sigma_um, o.sigma_min_um, o.sigma_max_um);
    check_initial("T", o.initial_T_um, o.T_min_um, o.T_max_um);
    if (o.max_iterations < 1)
        throw InvalidArgument("max_iterations = " + std::to_string(o.max_iterations) +
                              " must be >= 1");
    check::positive("function tolerance", o.function_tolerance);
    check::positive("gradient tolerance", o.gradient_tolerance);
    check::positive("parameter tolerance", o.parameter_tolerance);
}

void check_measurements(const std::vector<Measurement>& ms) {
    if (ms.empty()) throw InvalidArgument("measurements: none given; at least 1 is needed");
    for (std::size_t i = 0; i < ms.size(); ++i) {
        const std::string at = "measurement " + std::to_string(i + 1) + " ";
        check::polar_angle(at + "theta_i", ms[i].geometry.theta_i_rad);
        check::polar_angle(at + "theta_s", ms[i].geometry.theta_s_rad);
        check::azimuth(at + "phi_s", ms[i].geometry.phi_s_rad);
        check::positive(at + "brightness", ms[i].brightness);
        check::positive(at + "weight", ms[i].weight);
    }
}

// The model brightness B(geom; θ) of the fit (gain 1), θ in natural units: the library's scalar
// forms, never a copy of them.
double model_brightness(const Geometry& g, const double* theta, const FitOptions& o) {
    if (o.model == FitModel::VeryRough)
        // Eq. 4 (Gaussian) / Eq. 5 (exponential) × radiometric factor (§3.3).
        return very_rough_brightness(g, theta[0], o.correlation, o.factor, o.radiometry);
    // Diffuse term of Eq. 1 in the chosen regime (Eq. 3 by default) × radiometric factor.
    ModelOptions mo;
    mo.factor = o.factor;
    mo.radiometry = o.radiometry;
    mo.regime = o.regime;
    mo.wavelength_um = o.wavelength_um;
    const ScatteredPower p =
        mean_scattered_power(g, Surface{theta[0], theta[1], o.correlation}, mo);
    return p.diffuse * radiometric_factor(o.radiometry, g);
}

// A positive parameter, log-transformed, with bounds [lower, upper].
ParameterSpec bounded(const char* name, double lower, double upper) {
    ParameterSpec s;
    s.name = name;
    s.lower = lower;
    s.upper = upper;
    return s;
}

// The engine's problem for the measurements: parameters with bounds and starts
// (docs/estimation.md), the model over every measurement, the gain profiled out.
LeastSquaresProblem make_problem(const std::vector<Measurement>& ms, const FitOptions& o) {
    LeastSquaresProblem P;
    P.residual = o.residual;
    P.gain = GainMode::Profiled;
    P.data.reserve(ms.size());
    for (const auto& m : ms) P.data.push_back(m.brightness);
    // All weights 1 is the engine's default (no weights): no N-sized copies of ones.
    if (std::any_of(ms.begin(), ms.end(), [](const Measurement& m) { return m.weight != 1.0; })) {
        P.weights.reserve(ms.size());
        for (const auto& m : ms) P.weights.push_back(m.weight);
    }
    std::vector<Geometry> geoms;
    geoms.reserve(ms.size());
    for (const auto& m : ms) geoms.push_back(m.geometry);
    if (o.model == FitModel::VeryRough) {
        // Eq. 4 / Eq. 5 × radiometric factor from the geometry-only terms, computed once
        // (precomputed_terms.hpp): very_rough_brightness to rounding, at one exponential per
        // measurement.
        auto terms = std::make_shared<const VeryRoughTerms>(geoms, o.factor, o.radiometry);
        P.model = [terms, c = o.correlation](std::span<const double> theta, std::span<double> out) {
            try {
                terms->brightness(theta[0], c, out);
            } catch (const Error&) {
                return false;
            }
            // B must be positive: it underflows to 0 far outside the lobe.
            return std::all_of(out.begin(), out.end(),
                               [](double b) { return std::isfinite(b) && b > 0.0; });
        };
    } else {
        P.model = [geoms, o](std::span<const double> theta, std::span<double> out) {
            try {
                for (std::size_t i = 0; i < geoms.size(); ++i) {
                    out[i] = model_brightness(geoms[i], theta.data(), o);
                    // B must be positive: it underflows to 0 far outside the lobe.
                    if (!(std::isfinite(out[i]) && out[i] > 0.0)) return false;
                }
            } catch (const Error&) {
                return false;
            }
            return true;
        };
    }
    if (o.model == FitModel::VeryRough) {
        ParameterSpec s = bounded("sigma_over_T", o.sigma_over_T_min, o.sigma_over_T_max);
        s.initial = o.initial_sigma_over_T;
        // Grid start: 25 log-spaced σ/T over the bounds, capped to [1e-3, 1e3].
        s.start_lower = std::max(o.sigma_over_T_min, 1e-3);
        s.start_upper = std::min(o.sigma_over_T_max, 1e3);
        if (!(*s.start_lower < *s.start_upper)) s.start_lower = s.start_upper = std::nullopt;
        s.grid_points = 25;
        P.parameters.push_back(s);
        return P;
    }
    P.parameters.push_back(bounded("sigma_um", o.sigma_min_um, o.sigma_max_um));
    P.parameters.push_back(bounded("T_um", o.T_min_um, o.T_max_um));
    double sigma0 = 0.0, T0 = 0.0;
    if (!(o.initial_sigma_um && o.initial_T_um)) {
        // Eq. 3 in logs is linear: ln E − ln(v_z² F² rad) = c − σ² v_z² − (T²/4) v_xy².
        const auto rows = static_cast<Eigen::Index>(ms.size());
        Eigen::MatrixXd A(rows, 3);
        Eigen::VectorXd y(rows);
        for (Eigen::Index i = 0; i < rows; ++i) {
            const Measurement& m = ms[static_cast<std::size_t>(i)];
            const Geometry& g = m.geometry;
            const ScatteringVector v = scattering_vector(g, o.wavelength_um);
            const double sw = std::sqrt(m.weight);
            const double F2 = geometric_factor_squared(o.factor, g);
            A(i, 0) = sw;
            A(i, 1) = -sw * v.vz * v.vz;
            A(i, 2) = -sw * v.vxy2() / 4.0;
            y(i) = sw * (std::log(m.brightness) -
                         std::log(v.vz * v.vz * F2 * radiometric_factor(o.radiometry, g)));
        }
        const Eigen::VectorXd c = A.colPivHouseholderQr().solve(y);
        if (c.allFinite() && c(1) > 0.0) sigma0 = std::sqrt(c(1));
        if (c.allFinite() && c(2) > 0.0) T0 = std::sqrt(c(2));
    }
    if (o.initial_sigma_um) sigma0 = *o.initial_sigma_um;
    if (o.initial_T_um) T0 = *o.initial_T_um;
    double s0 = sigma0, t0 = T0;
    if (!(sigma0 > 0.0 && T0 > 0.0)) {
        // Coarse profile scan around λ-scaled values (the log-linear start failed).
        double best = kInf;
        const double k = wavenumber_per_um(o.wavelength_um);
        for (int a = 0; a <= 12; ++a)
            for (int b = 0; b <= 12; ++b) {
                const double s = sigma0 > 0.0 ? sigma0 : std::pow(10.0, -2.5 + 0.25 * a) / k;
                const double t = T0 > 0.0 ? T0 : std::pow(10.0, -1.0 + 0.25 * b) / k;
                const double theta[2] = {std::clamp(s, o.sigma_min_um, o.sigma_max_um),
                                         std::clamp(t, o.T_min_um, o.T_max_um)};
                const double sse = profiled_sse(P, theta);
                if (sse < best) {
                    best = sse;
                    s0 = s;
                    t0 = t;
                }
            }
        if (!std::isfinite(best)) {
            s0 = sigma0 > 0.0 ? sigma0 : 0.05 / k;
            t0 = T0 > 0.0 ? T0 : 1.0 / k;
        }
    }
    P.parameters[0].initial = std::clamp(s0, o.sigma_min_um, o.sigma_max_um);
    P.parameters[1].initial = std::clamp(t0, o.T_min_um, o.T_max_um);
    return P;
}

// Why a fit is not identifiable, in the user's terms: how many measurements at how many distinct
// geometries for how many parameters (each parameter needs a geometry of its own: at one geometry
// the model is a single number, which the gain alone matches).
std::string identifiability_diagnosis(const std::vector<Measurement>& ms,
                                      const std::vector<FitParameter>& parameters) {
    std::vector<std::array<double, 3>> distinct;
    for (const Measurement& m : ms) {
        const std::array<double, 3> g{m.geometry.theta_i_rad, m.geometry.theta_s_rad,
                                      m.geometry.phi_s_rad};
        if (std::find(distinct.begin(), distinct.end(), g) == distinct.end()) distinct.push_back(g);
    }
    std::string unidentified;
    for (const FitParameter& fp : parameters)
        if (!fp.identified) unidentified += (unidentified.empty() ? "" : ", ") + fp.name;
    const std::size_t p = parameters.size();
    std::string s = "not identifiable: the data do not determine " + unidentified + " (" +
                    std::to_string(ms.size()) + " measurement" + (ms.size() == 1 ? "" : "s") +
                    " at " + std::to_string(distinct.size()) + " distinct geometr" +
                    (distinct.size() == 1 ? "y" : "ies") + " for " + std::to_string(p) +
                    " parameters including the gain";
    if (distinct.size() < p)
        s += "; at least " + std::to_string(p) + " distinct geometries are needed";
    return s + ")";
}

LeastSquaresOptions engine_options(const FitOptions& o) {
    LeastSquaresOptions e;
    e.max_iterations = o.max_iterations;
    e.function_tolerance = o.function_tolerance;
    e.gradient_tolerance = o.gradient_tolerance;
    e.parameter_tolerance = o.parameter_tolerance;
    e.loss = o.loss;
    e.loss_scale = o.loss_scale;
    e.scale_covariance = o.scale_covariance;
    return e;
}

std::string correlation_label(Correlation c) { return std::string(info(c).adjective); }

}  // namespace

double fit_model_brightness(const Geometry& geom, const std::vector<double>& parameters,
                            const FitOptions& options) {
    check_options(options);
    check::geometry(geom);
    const int n = model_parameter_count(options);
    if (static_cast<int>(parameters.size()) != n)
        throw InvalidArgument("parameters: " + std::to_string(parameters.size()) + " given, the " +
                              std::string(to_string(options.model)) + " model has " +
                              std::to_string(n));
    if (n == 1) {
        check::positive("sigma/T", parameters[0]);
    } else {
        check::positive("sigma", parameters[0], "um");
        check::positive("T", parameters[1], "um");
    }
    return model_brightness(geom, parameters.data(), options);
}

const FitParameter& FitResult::parameter(std::string_view name) const {
    return find_parameter(parameters, name);
}

std::string FitResult::brief_report() const {
    std::string s =
        "roughscope fit (" + std::string(to_string(options.model)) + ", " +
        correlation_label(options.correlation) + " correlation, " +
        std::string(to_string(options.factor)) + ", " + std::string(to_string(options.radiometry)) +
        ", " + std::string(to_string(options.residual)) + " residuals, loss " +
        std::string(to_string(options.loss)) + "): " + std::string(to_string(status)) + " after " +
        std::to_string(iterations) + " iterations; N = " + std::to_string(num_measurements) +
        ", p = " + std::to_string(num_parameters) + ";";
    return s + brief_report_tail(parameters, covariance_available, sse, aic, message);
}

FitResult fit_roughness(const std::vector<Measurement>& measurements, const FitOptions& options) {
    check_options(options);
    const int n = model_parameter_count(options);
    const int p = n + 1;
    check_measurements(measurements);

    const LeastSquaresResult lsq =
        solve_least_squares(make_problem(measurements, options), engine_options(options));

    FitResult result;
    result.options = options;
    result.status = lsq.status;
    result.message = lsq.message;
    result.parameters = lsq.parameters;
    result.parameters.back().lower = 0.0;  // the gain of a positive brightness model is > 0
    result.not_identifiable = lsq.not_identifiable;
    result.covariance_available = lsq.covariance_available;
    result.covariance = lsq.covariance;
    result.residuals = lsq.residuals;
    result.predicted = lsq.predicted;
    result.sse = lsq.sse;
    result.aic = lsq.aic;
    result.aicc = lsq.aicc;
    result.num_measurements = lsq.num_data;
    result.num_parameters = lsq.num_parameters;
    result.iterations = lsq.iterations;
    result.evaluations = lsq.evaluations;
    result.initial_cost = lsq.initial_cost;
    result.final_cost = lsq.final_cost;
    if (result.status == SolverStatus::NotIdentifiable)
        result.message =
            identifiability_diagnosis(measurements, result.parameters) + "; " + result.message;
    std::vector<double> natural(static_cast<std::size_t>(p));
    for (int j = 0; j < p; ++j)
        natural[static_cast<std::size_t>(j)] = lsq.parameters[static_cast<std::size_t>(j)].value;

    // Derived quantities.
    RoughnessEstimate& est = result.estimate;
    est.correlation = options.correlation;
    std::vector<Geometry> geoms;
    geoms.reserve(measurements.size());
    for (const auto& m : measurements) geoms.push_back(m.geometry);
    auto se = [&](int j) {
        return result.covariance_available ? result.parameters[j].std_error : 0.0;
    };
    // A parameter the data do not determine gives no estimate (std::nullopt), nor do the
    // quantities derived from it.
    auto identified = [&](int j) {
        return result.parameters[static_cast<std::size_t>(j)].identified;
    };
    if (options.model == FitModel::VeryRough) {
        if (identified(0)) est.sigma_over_T = Estimate{natural[0], se(0)};
        est.roughness_class = RoughnessClass::VeryRough;
        est.roughness_class_assumed = true;
    } else if (!identified(0) || !identified(1)) {
        if (identified(0)) est.sigma_um = Estimate{natural[0], se(0)};
        if (identified(1)) est.T_um = Estimate{natural[1], se(1)};
        est.roughness_class = RoughnessClass::SlightlyRough;  // the model's assumption (Eq. 3)
        est.roughness_class_assumed = true;
    } else {
        const double s = natural[0] / natural[1];
        double sd_s = 0.0;
        if (result.covariance_available) {
            // var ln(σ/T) = var ln σ + var ln T − 2 cov(ln σ, ln T).
            const Eigen::MatrixXd& Cn = result.covariance;
            const double v = Cn(0, 0) / (natural[0] * natural[0]) +
                             Cn(1, 1) / (natural[1] * natural[1]) -
                             2.0 * Cn(0, 1) / (natural[0] * natural[1]);
            sd_s = s * std::sqrt(std::max(0.0, v));
        }
        est.sigma_um = Estimate{natural[0], se(0)};
        est.T_um = Estimate{natural[1], se(1)};
        est.sigma_over_T = Estimate{s, sd_s};
        fill_roughness_class(est, geoms, natural[0], options.wavelength_um,
                             options.regime == Regime::SlightlyRough
                                 ? std::optional<RoughnessClass>(RoughnessClass::SlightlyRough)
                                 : std::nullopt);
    }
    fill_derived_quantities(est, geoms);
    for (const auto& fp : result.parameters)
        if (fp.at_bound && fp.identified)
            est.warnings.push_back(fp.name + " = " + format_message(fp.value, 6) +
                                   " is at a bound of its range [" + format_message(fp.lower, 6) +
                                   ", " + format_message(fp.upper, 6) +
                                   "]: the data do not constrain it there; its standard error "
                                   "is not meaningful");
    if (result.status == SolverStatus::NotIdentifiable)
        est.warnings.push_back(result.message);
    else if (result.status == SolverStatus::NoConvergence || result.status == SolverStatus::Failed)
        est.warnings.push_back("the fit did not converge: " + result.message);
    return result;
}

CorrelationComparison compare_correlations(const std::vector<Measurement>& measurements,
                                           const FitOptions& options) {
    CorrelationComparison c;
    FitOptions o = options;
    for (const Correlation k : kCorrelations) {
        o.correlation = k;
        c[k] = fit_roughness(measurements, o);
    }
    // AIC ranks fits that determine their parameters; an unidentifiable fit never wins, and the
    // difference is unknown (NaN) unless all are identifiable.
    const auto identifiable = [&](Correlation k) {
        return c[k].status != SolverStatus::NotIdentifiable;
    };
    const bool any_ok = std::any_of(kCorrelations.begin(), kCorrelations.end(), identifiable);
    const bool all_ok = std::all_of(kCorrelations.begin(), kCorrelations.end(), identifiable);
    std::optional<Correlation> best;
    for (const Correlation k : kCorrelations) {
        if (any_ok && !identifiable(k)) continue;
        if (!best || !(c[*best].aic <= c[k].aic)) best = k;
    }
    c.preferred = *best;
    c.delta_aic = std::numeric_limits<double>::quiet_NaN();
    if (all_ok) {
        c.delta_aic = std::numeric_limits<double>::infinity();
        for (const Correlation k : kCorrelations)
            if (k != c.preferred)
                c.delta_aic = std::min(c.delta_aic, std::abs(c[k].aic - c[c.preferred].aic));
    }
    return c;
}

}  // namespace roughscope
