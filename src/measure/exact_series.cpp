// The exact series where the capture set allows it (measure/exact_series.hpp, docs/uncertainty.md
// "Model error"): T given σ in Regime::Series, or σ and T fitted jointly to ≥ 3 captures.
#include "roughscope/measure/exact_series.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "exact_series_profile.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/fit/fit.hpp"
#include "roughscope/measure/measure.hpp"
#include "roughscope/scattering/factors.hpp"

namespace roughscope::image {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kZ95 = 1.959963984540054;  // the normal distribution's 97.5 % quantile
// The starting g = σ² v_z² (v_z of the captures' mean) of the joint fit's starts, beside the
// fit's own (Eq. 3 in logs): the series' minimum in (σ, T) need not be the nearest one.
constexpr double kStartG[] = {0.3, 3.0, 30.0};

const QuantityBudget* budget_quantity(const MeasureResult& r, const std::string& name) {
    if (!r.uncertainty) return nullptr;
    for (const QuantityBudget& q : r.uncertainty->quantities)
        if (q.quantity == name) return &q;
    return nullptr;
}

// The closed form's σ/T of the first pair (Eq. 17 / 19, or the very-rough solver) and the 95 %
// interval it states: the budget's (which carries the very-rough model error when σ is unknown),
// else ± 1.96 of its standard error.
struct ClosedForm {
    std::optional<double> value;
    double low = kNaN, high = kNaN;
};

ClosedForm closed_form(const MeasureResult& r, Correlation c) {
    ClosedForm out;
    const auto& slope = c == Correlation::Gaussian ? r.slope_gaussian : r.slope_exponential;
    if (!slope || !slope->sigma_over_T) return out;
    out.value = slope->sigma_over_T->value;
    if (const QuantityBudget* q = budget_quantity(r, correlation_key("sigma_over_T", c))) {
        out.low = q->result.interval95_low;
        out.high = q->result.interval95_high;
    } else {
        const double u = slope->sigma_over_T->std_error;
        out.low = *out.value - kZ95 * u;
        out.high = *out.value + kZ95 * u;
    }
    return out;
}

std::vector<double> g_at(double sigma_um, const std::vector<Geometry>& geoms, double lambda_um) {
    std::vector<double> g;
    g.reserve(geoms.size());
    for (const Geometry& geom : geoms) g.push_back(roughness_g(geom, sigma_um, lambda_um));
    return g;
}

// The closed form beside the series: the deviation, and whether it is off by more than either
// estimate's 95 % interval admits.
void compare_closed_form(const MeasureResult& r, ExactSeriesCorrelation& e,
                         std::vector<std::string>& warnings) {
    const ClosedForm closed = closed_form(r, e.correlation);
    if (!closed.value || !e.sigma_over_T) return;
    const double series = e.sigma_over_T->value;
    e.closed_form_sigma_over_T = closed.value;
    e.closed_form_deviation_rel = (*closed.value - series) / series;
    const bool outside_series =
        e.interval95_low && e.interval95_high &&
        (*closed.value < *e.interval95_low || *closed.value > *e.interval95_high);
    const bool outside_closed = !(series >= closed.low && series <= closed.high);
    e.closed_form_off = outside_series && outside_closed;
    if (!e.closed_form_off) return;
    std::string g_list;
    for (const double g : e.g)
        g_list += concat(g_list.empty() ? "" : ", ", format_significant(g, 3));
    warnings.push_back(concat(
        "exact series (", to_string(e.correlation),
        "): the closed form σ/T = ", format_significant(*closed.value, 4), " (Eq. ",
        e.correlation == Correlation::Gaussian ? "17" : "19", ", very-rough limit) is ",
        format_significant(100.0 * *e.closed_form_deviation_rel, 3), " % off the exact series' ",
        format_significant(series, 4), " (95 % [", format_significant(*e.interval95_low, 4), ", ",
        format_significant(*e.interval95_high, 4),
        "]), beyond its own stated uncertainty; g at the captures: ", g_list,
        ": take the exact series' value (\"exact_series\")"));
}

// σ known and a diffuse pair: T given σ in Regime::Series, σ/T = σ/T_series, with the budget's
// uncertainty (sigma_over_T_series_*, T_um_series_*).
ExactSeriesEstimate sigma_known(const MeasureRequest& request, const MeasureResult& r,
                                const std::vector<std::size_t>& diffuse, Estimate sigma) {
    ExactSeriesEstimate out;
    out.method = ExactSeriesMethod::SigmaKnown;
    out.captures = {diffuse[0], diffuse[1]};
    out.covers = r.uncertainty
                     ? "the budget: angles, exposures, black level, response, wavelength, σ's "
                       "uncertainty and pixel noise (uncertainty_budget)"
                     : "nothing (no budget)";
    const CaptureMeasurement& c1 = r.captures[diffuse[0]];
    const CaptureMeasurement& c2 = r.captures[diffuse[1]];
    const std::vector<Geometry> geoms{c1.spec.geometry, c2.spec.geometry};
    TwoGeometryOptions options;
    options.factor = request.factor;
    options.radiometry = request.radiometry;
    options.wavelength_um = request.wavelength_um;
    options.regime = Regime::Series;
    const double ratio = c1.brightness / c2.brightness;
    for (const Correlation c : {Correlation::Gaussian, Correlation::Exponential}) {
        ExactSeriesCorrelation e;
        e.correlation = c;
        e.sigma_um = sigma;
        e.g = g_at(sigma.value, geoms, request.wavelength_um);
        try {
            const double T = correlation_length_two_geometries(ratio, geoms[0], geoms[1],
                                                               sigma.value, c, options);
            const QuantityBudget* qs =
                budget_quantity(r, correlation_key("sigma_over_T_series", c));
            const QuantityBudget* qt = budget_quantity(r, correlation_key("T_um_series", c));
            e.T_um = Estimate{T, qt ? qt->result.uncertainty : kNaN};
            e.sigma_over_T = Estimate{sigma.value / T, qs ? qs->result.uncertainty : kNaN};
            if (qs) {
                e.interval95_low = qs->result.interval95_low;
                e.interval95_high = qs->result.interval95_high;
            }
        } catch (const Error& error) {
            e.failure = concat("T given σ (exact series): ", error.what());
        }
        compare_closed_form(r, e, out.warnings);
        out.correlations.push_back(std::move(e));
    }
    return out;
}

// One capture's relative brightness noise for the fit: the region's (pixel noise or texture) and
// the exposure tolerance in quadrature (independent per capture, like the noise).
double fit_noise_rel(const MeasureRequest& request, const CaptureMeasurement& c) {
    const bool needs_exposure =
        c.exposure_source.rfind("not needed", 0) != 0 && c.spec.bracket.empty();
    const double exposure =
        !needs_exposure ? 0.0
        : c.spec.uncertainty.exposure_rel
            ? *c.spec.uncertainty.exposure_rel
            : request.uncertainty.exposure_rel.value_or(kDefaultExposureUncertaintyRel);
    return std::hypot(c.brightness_relative_stderr, exposure);
}

// The best of the fit's own start and kStartG's (lowest SSE among the converged ones).
FitResult best_fit(const std::vector<Measurement>& data, FitOptions options, double vz,
                   double slope) {
    FitResult best = fit_roughness(data, options);
    for (const double g : kStartG) {
        options.initial_sigma_um = std::sqrt(g) / vz;
        options.initial_T_um = *options.initial_sigma_um / slope;
        FitResult f = fit_roughness(data, options);
        const bool better_status =
            f.status == SolverStatus::Converged && best.status != SolverStatus::Converged;
        const bool same_status = f.status == best.status;
        if (better_status || (same_status && f.sse < best.sse)) best = std::move(f);
    }
    return best;
}

// σ, T (and σ/T by the delta method) from a converged fit whose covariance is from the
// captures' noise, scaled by the reduced χ² when that exceeds 1.
void read_fit(const FitResult& f, ExactSeriesCorrelation& e, bool noise_weights) {
    e.fit_status = std::string(to_string(f.status));
    const FitParameter& s = f.parameter("sigma_um");
    const FitParameter& t = f.parameter("T_um");
    if (f.status == SolverStatus::NotIdentifiable || f.status == SolverStatus::Failed) {
        e.failure = concat("fit (exact series): ", f.message);
        return;
    }
    const int dof = f.num_measurements - f.num_parameters;
    double scale = 1.0;
    if (noise_weights && dof > 0) scale = std::max(1.0, f.sse / dof);
    const bool errors =
        f.covariance_available && f.status == SolverStatus::Converged && (noise_weights || dof > 0);
    const double var_s = errors ? f.covariance(0, 0) * scale : kNaN;
    const double var_t = errors ? f.covariance(1, 1) * scale : kNaN;
    const double cov_st = errors ? f.covariance(0, 1) * scale : kNaN;
    const double q = s.value / t.value;
    // Delta method: var(σ/T) = q² (var σ/σ² + var T/T² − 2 cov/(σ T)).
    const double var_q = q * q *
                         (var_s / (s.value * s.value) + var_t / (t.value * t.value) -
                          2.0 * cov_st / (s.value * t.value));
    e.sigma_um = Estimate{s.value, std::sqrt(var_s)};
    e.T_um = Estimate{t.value, std::sqrt(var_t)};
    e.sigma_over_T = Estimate{q, var_q >= 0.0 ? std::sqrt(var_q) : kNaN};
    if (std::isfinite(e.sigma_over_T->std_error)) {
        e.interval95_low = q - kZ95 * e.sigma_over_T->std_error;
        e.interval95_high = q + kZ95 * e.sigma_over_T->std_error;
    }
}

// The profile-likelihood intervals (exact_series_profile.hpp) in place of the covariance's: the
// fit is started again from the grid's minimum when that is better than the fit's (a local
// minimum), and σ or T not determined by the captures is said.
void apply_profile(const std::vector<Measurement>& data, FitOptions options,
                   ExactSeriesCorrelation& e, std::vector<std::string>& warnings) {
    detail::ProfileIntervals p =
        detail::profile_intervals(data, options, e.sigma_um->value, e.T_um->value);
    if (!p.ok) return;
    const double rel = std::abs(p.best_sigma_um / e.sigma_um->value - 1.0) +
                       std::abs(p.best_T_um / e.T_um->value - 1.0);
    if (rel > 1e-6) {
        options.initial_sigma_um = p.best_sigma_um;
        options.initial_T_um = p.best_T_um;
        ExactSeriesCorrelation again = e;
        const bool noise_weights = !options.scale_covariance;
        read_fit(fit_roughness(data, options), again, noise_weights);
        if (again.sigma_um && again.T_um) {
            const detail::ProfileIntervals q =
                detail::profile_intervals(data, options, again.sigma_um->value, again.T_um->value);
            if (q.ok && q.chi2_min <= p.chi2_min + 1e-9 * (1.0 + p.chi2_min)) {
                e = std::move(again);
                p = q;
            }
        }
    }
    e.sigma_um_interval95 = std::array<double, 2>{p.sigma_um.low, p.sigma_um.high};
    e.T_um_interval95 = std::array<double, 2>{p.T_um.low, p.T_um.high};
    e.interval95_low = p.sigma_over_T.low;
    e.interval95_high = p.sigma_over_T.high;
    e.sigma_determined = !p.sigma_um.open_low && !p.sigma_um.open_high;
    e.T_determined = !p.T_um.open_low && !p.T_um.open_high;
    for (const auto& [name, determined, interval] :
         {std::tuple{"σ", e.sigma_determined, p.sigma_um}, std::tuple{"T", e.T_determined, p.T_um}})
        if (!determined)
            warnings.push_back(concat(
                "fit (exact series, ", to_string(e.correlation),
                "): the captures do not determine ", name, ": its 95 % interval [",
                format_significant(interval.low, 3), ", ", format_significant(interval.high, 3),
                "] µm reaches the range searched (at small g the diffuse term is nearly "
                "proportional to σ², which the gain absorbs)"));
}

// σ unknown and ≥ 3 diffuse captures at distinct geometries: σ and T jointly (with a gain).
ExactSeriesEstimate joint_fit(const MeasureRequest& request, const MeasureResult& r,
                              const std::vector<std::size_t>& diffuse) {
    ExactSeriesEstimate out;
    out.method = ExactSeriesMethod::Fit;
    out.captures = diffuse;
    std::vector<Measurement> data;
    std::vector<Geometry> geoms;
    bool noise_weights = true;
    double vz = 0.0;
    for (const std::size_t k : diffuse) {
        const CaptureMeasurement& c = r.captures[k];
        Measurement m;
        m.geometry = c.spec.geometry;
        m.brightness = c.brightness;
        const double e = fit_noise_rel(request, c);
        noise_weights = noise_weights && e > 0.0;
        m.weight = e > 0.0 ? 1.0 / (e * e) : 1.0;
        data.push_back(m);
        geoms.push_back(m.geometry);
        vz += std::abs(scattering_vector(m.geometry, request.wavelength_um).vz) /
              static_cast<double>(diffuse.size());
    }
    out.covers = noise_weights
                     ? "the fit's covariance from each capture's pixel noise and exposure "
                       "tolerance (scaled by the reduced chi-square when above 1); the angles, "
                       "black level, response and wavelength are not propagated"
                     : "the fit's residual scatter only (a capture without measurable noise); "
                       "the setup's tolerances are not propagated";
    FitOptions options;
    options.model = FitModel::SlightlyRough;
    options.regime = Regime::Series;
    options.factor = request.factor;
    options.radiometry = request.radiometry;
    options.wavelength_um = request.wavelength_um;
    options.scale_covariance = !noise_weights;
    for (const Correlation c : {Correlation::Gaussian, Correlation::Exponential}) {
        ExactSeriesCorrelation e;
        e.correlation = c;
        options.correlation = c;
        const ClosedForm closed = closed_form(r, c);
        const double slope = closed.value && *closed.value > 0.0 ? *closed.value : 0.3;
        try {
            read_fit(best_fit(data, options, vz, slope), e, noise_weights);
            if (e.sigma_um && e.T_um) apply_profile(data, options, e, out.warnings);
        } catch (const Error& error) {
            e.failure = concat("fit (exact series): ", error.what());
        }
        if (e.sigma_um) e.g = g_at(e.sigma_um->value, geoms, request.wavelength_um);
        compare_closed_form(r, e, out.warnings);
        out.correlations.push_back(std::move(e));
    }
    return out;
}

bool same_geometry(const Geometry& a, const Geometry& b) {
    return a.theta_i_rad == b.theta_i_rad && a.theta_s_rad == b.theta_s_rad &&
           a.phi_s_rad == b.phi_s_rad;
}

}  // namespace

std::string_view to_string(ExactSeriesMethod method) {
    return method == ExactSeriesMethod::SigmaKnown ? "t_given_sigma" : "fit";
}

std::string describe(const ExactSeriesEstimate& estimate) {
    return estimate.method == ExactSeriesMethod::SigmaKnown
               ? std::string("T given σ")
               : concat("fit of ", std::to_string(estimate.captures.size()), " captures");
}

const ExactSeriesCorrelation* ExactSeriesEstimate::operator[](Correlation c) const {
    for (const ExactSeriesCorrelation& e : correlations)
        if (e.correlation == c) return &e;
    return nullptr;
}

std::optional<ExactSeriesEstimate> exact_series_estimate(const MeasureRequest& request,
                                                         const MeasureResult& result) {
    if (request.object.shape != ObjectShape::Plane) return std::nullopt;
    std::vector<std::size_t> diffuse;
    std::vector<Geometry> distinct;
    for (std::size_t k = 0; k < result.captures.size(); ++k) {
        const CaptureMeasurement& c = result.captures[k];
        if (c.spec.role != CaptureRole::Diffuse || !(c.brightness > 0.0)) continue;
        diffuse.push_back(k);
        if (std::none_of(distinct.begin(), distinct.end(),
                         [&](const Geometry& g) { return same_geometry(g, c.spec.geometry); }))
            distinct.push_back(c.spec.geometry);
    }
    std::optional<Estimate> sigma;
    if (request.sigma_um)
        sigma = Estimate{*request.sigma_um, request.sigma_um_stderr};
    else if (result.sigma && result.sigma->sigma_um)
        sigma = result.sigma->sigma_um;
    if (sigma && sigma->value > 0.0 && diffuse.size() >= 2)
        return sigma_known(request, result, diffuse, *sigma);
    if (!sigma && distinct.size() >= 3) return joint_fit(request, result, diffuse);
    return std::nullopt;
}

}  // namespace roughscope::image
