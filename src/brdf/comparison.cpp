// Models against measured BRDFs (paper §5.3, Tables 3–4): the two-point estimate, every model's
// prediction, the paper's error and two scale-free ones, least-squares fits, and the outputs.
#include "roughscope/brdf/comparison.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <exception>
#include <limits>
#include <mutex>
#include <numeric>
#include <sstream>
#include <thread>

#include <Eigen/Dense>
#include <boost/math/tools/minima.hpp>
#include <nlohmann/json.hpp>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/names.hpp"
#include "roughscope/estimation/estimation.hpp"
#include "roughscope/scattering/beckmann.hpp"

namespace roughscope {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct ModelInfo {
    ComparisonModel model;
    const char* key;
    const char* label;
};

constexpr ModelInfo kModelInfo[] = {
    {ComparisonModel::OrenNayar, "oren_nayar", "O–N"},
    {ComparisonModel::Lafortune, "lafortune", "LFTG"},
    {ComparisonModel::BkGaussian, "bk_gaussian", "B–K(G)"},
    {ComparisonModel::BkExponential, "bk_exponential", "B–K(E)"},
    {ComparisonModel::VhGaussian, "vh_gaussian", "V–H–B–K(G)"},
    {ComparisonModel::VhExponential, "vh_exponential", "V–H–B–K(E)"},
    {ComparisonModel::OrenNayarFit, "oren_nayar_fit", "O–N fit"},
    {ComparisonModel::LafortuneFit, "lafortune_fit", "LFTG fit"},
    {ComparisonModel::BkGaussianFit, "bk_gaussian_fit", "B–K(G) fit"},
    {ComparisonModel::BkExponentialFit, "bk_exponential_fit", "B–K(E) fit"},
    {ComparisonModel::VhGaussianFit, "vh_gaussian_fit", "V–H–B–K(G) fit"},
    {ComparisonModel::VhExponentialFit, "vh_exponential_fit", "V–H–B–K(E) fit"},
};

const ModelInfo& info(ComparisonModel m) {
    for (const ModelInfo& i : kModelInfo)
        if (i.model == m) return i;
    return kModelInfo[0];  // unreachable
}

std::string fmt(double x, const char* spec = "%.6g") {
    char buf[64];
    std::snprintf(buf, sizeof buf, spec, x);
    return buf;
}

// ---------------------------------------------------------------------------------------------
// The used measurements with everything the model evaluations need, computed once per table.

struct Prepared {
    std::vector<Geometry> geom;
    std::vector<double> d;  // data brightness normalised by its maximum
    std::vector<double> w;
    double sum_w = 0.0;
    double sum_wdd = 0.0;
    std::vector<ScatteringDirection> q;  // very-rough shapes (beckmann.hpp)
    std::vector<double> F2_beck, F2_vh, radiometric;
    std::vector<double> cos_i, log_cos_i_cos_s;  // Lafortune diffuse lobe

    std::size_t size() const { return geom.size(); }
};

Prepared prepare(const std::vector<Geometry>& geom, const std::vector<double>& d_normalised,
                 const std::vector<double>& w, Radiometry radiometry) {
    Prepared p;
    p.geom = geom;
    p.d = d_normalised;
    p.w = w;
    const std::size_t n = geom.size();
    p.q.resize(n);
    p.F2_beck.resize(n);
    p.F2_vh.resize(n);
    p.radiometric.resize(n);
    p.cos_i.resize(n);
    p.log_cos_i_cos_s.resize(n);
    for (std::size_t j = 0; j < n; ++j) {
        const Geometry& g = geom[j];
        p.q[j] = scattering_direction(g);
        p.F2_beck[j] = geometric_factor_squared(GeometricFactor::Beckmann, g);
        p.F2_vh[j] = geometric_factor_squared(GeometricFactor::VernoldHarvey, g);
        p.radiometric[j] = radiometric_factor(radiometry, g);
        p.cos_i[j] = std::cos(g.theta_i_rad);
        p.log_cos_i_cos_s[j] = std::log(p.cos_i[j] * std::cos(g.theta_s_rad));
        p.sum_w += w[j];
        p.sum_wdd += w[j] * p.d[j] * p.d[j];
    }
    return p;
}

// Eq. 4 (Gaussian) / Eq. 5 (exponential) very-rough brightness shapes with F_Beck or F_VH, times
// the radiometric factor of §3.3: the same as very_rough_brightness, without per-call checks.
void very_rough_prediction(const Prepared& p, GeometricFactor factor, Correlation c, double m,
                           std::vector<double>& out) {
    out.resize(p.size());
    const std::vector<double>& F2 = factor == GeometricFactor::Beckmann ? p.F2_beck : p.F2_vh;
    for (std::size_t j = 0; j < p.size(); ++j) {
        const double shape = c == Correlation::Gaussian
                                 ? very_rough_shape_gaussian(F2[j], p.q[j], m)
                                 : very_rough_shape_exponential(F2[j], p.q[j], m);
        out[j] = shape * p.radiometric[j];
    }
}

// Lafortune diffuse lobe E = (cos θi cos θs)^n cos θi (models.hpp), via precomputed logarithms.
void lafortune_prediction(const Prepared& p, double n, std::vector<double>& out) {
    out.resize(p.size());
    for (std::size_t j = 0; j < p.size(); ++j)
        out[j] = p.cos_i[j] * std::exp(n * p.log_cos_i_cos_s[j]);
}

// Oren–Nayar with inter-reflection (models.hpp).
void oren_nayar_prediction(const Prepared& p, const OrenNayarParams& on, std::vector<double>& out) {
    out.resize(p.size());
    for (std::size_t j = 0; j < p.size(); ++j) out[j] = oren_nayar_radiance(p.geom[j], on);
}

// min over K of Σ w (K M − d)²; K returned through `gain`. A model that is zero everywhere
// explains nothing: SSE = Σ w d².
double gain_sse(const Prepared& p, const std::vector<double>& M, double* gain = nullptr) {
    double smd = 0.0, smm = 0.0;
    for (std::size_t j = 0; j < p.size(); ++j) {
        smd += p.w[j] * M[j] * p.d[j];
        smm += p.w[j] * M[j] * M[j];
    }
    if (!(smm > 0.0) || !std::isfinite(smm)) {
        if (gain) *gain = 0.0;
        return p.sum_wdd;
    }
    const double K = smd / smm;
    double sse = 0.0;
    for (std::size_t j = 0; j < p.size(); ++j) {
        const double r = K * M[j] - p.d[j];
        sse += p.w[j] * r * r;
    }
    if (gain) *gain = K;
    return sse;
}

// The paper's Table 4 error: Σ w (M/max M − d)² with d already normalised; +inf if max M ≤ 0.
double paper_sse(const Prepared& p, const std::vector<double>& M) {
    double mmax = -kInf;
    for (double v : M) mmax = std::max(mmax, v);
    if (!(mmax > 0.0) || !std::isfinite(mmax)) return kInf;
    double s = 0.0;
    for (std::size_t j = 0; j < p.size(); ++j) {
        const double r = M[j] / mmax - p.d[j];
        s += p.w[j] * r * r;
    }
    return s;
}

ErrorMeasures measures(const Prepared& p, const std::vector<double>& M) {
    ErrorMeasures e;
    e.paper_sse = paper_sse(p, M);
    e.rmse = std::sqrt(e.paper_sse / p.sum_w);
    e.gain_sse = gain_sse(p, M, &e.gain);
    return e;
}

// ---------------------------------------------------------------------------------------------
// Fits by variable projection: the gain K is eliminated in closed form, the remaining one or two
// shape parameters are found by a grid (global) then Brent's method (local), so no start value
// is needed and the bounds are honoured exactly.

constexpr int kBrentBits = std::numeric_limits<double>::digits / 2;
constexpr std::uintmax_t kBrentMaxIter = 200;

struct Minimum1D {
    double x = 0.0;
    double f = kInf;
    int evaluations = 0;
    bool at_bound = false;
};

// Minimises f on [lo, hi] (in whatever variable the caller chose) with `grid` points then Brent.
template <class F>
Minimum1D minimise_1d(F&& f, double lo, double hi, int grid) {
    Minimum1D best;
    std::vector<double> xs(static_cast<std::size_t>(grid)), fs(xs.size());
    std::size_t kbest = 0;
    for (std::size_t k = 0; k < xs.size(); ++k) {
        xs[k] = lo + (hi - lo) * static_cast<double>(k) / static_cast<double>(grid - 1);
        fs[k] = f(xs[k]);
        ++best.evaluations;
        if (fs[k] < fs[kbest]) kbest = k;
    }
    const double a = xs[kbest == 0 ? 0 : kbest - 1];
    const double b = xs[std::min(kbest + 1, xs.size() - 1)];
    std::uintmax_t iter = kBrentMaxIter;
    const auto [x, fx] = boost::math::tools::brent_find_minima(f, a, b, kBrentBits, iter);
    best.evaluations += static_cast<int>(iter);
    if (fx <= fs[kbest]) {
        best.x = x;
        best.f = fx;
    } else {
        best.x = xs[kbest];
        best.f = fs[kbest];
    }
    const double tol = 1e-6 * (hi - lo);
    best.at_bound = best.x - lo <= tol || hi - best.x <= tol;
    return best;
}

// Covariance of (params…, K) from the Jacobian of r_j = √w_j (K M_j(θ) − d_j) at the optimum:
// s² (JᵀJ)⁻¹ with s² = SSE/(N − k). Central differences (one-sided at a bound). Returns false
// when N ≤ k or JᵀJ is singular.
template <class Eval>
bool covariance(const Prepared& p, Eval&& eval, const std::vector<double>& theta,
                const std::vector<double>& lo, const std::vector<double>& hi, double K, double sse,
                std::vector<double>& cov) {
    const std::size_t np = theta.size(), k = np + 1;
    std::size_t n_used = 0;
    for (double w : p.w) n_used += w > 0.0 ? 1 : 0;
    if (n_used <= k) return false;
    Eigen::MatrixXd J(static_cast<Eigen::Index>(p.size()), static_cast<Eigen::Index>(k));
    std::vector<double> M, Mp, Mm;
    eval(theta, M);
    for (std::size_t i = 0; i < np; ++i) {
        const double h = 1e-6 * std::max(1.0, std::abs(theta[i]));
        std::vector<double> tp = theta, tm = theta;
        tp[i] = std::min(hi[i], theta[i] + h);
        tm[i] = std::max(lo[i], theta[i] - h);
        const double step = tp[i] - tm[i];
        if (!(step > 0.0)) return false;
        eval(tp, Mp);
        eval(tm, Mm);
        for (std::size_t j = 0; j < p.size(); ++j)
            J(static_cast<Eigen::Index>(j), static_cast<Eigen::Index>(i)) =
                std::sqrt(p.w[j]) * K * (Mp[j] - Mm[j]) / step;
    }
    for (std::size_t j = 0; j < p.size(); ++j)
        J(static_cast<Eigen::Index>(j), static_cast<Eigen::Index>(np)) = std::sqrt(p.w[j]) * M[j];
    const Eigen::MatrixXd JtJ = J.transpose() * J;
    Eigen::FullPivLU<Eigen::MatrixXd> lu(JtJ);
    if (!lu.isInvertible()) return false;
    const double s2 = sse / static_cast<double>(n_used - k);
    const Eigen::MatrixXd C = lu.inverse() * s2;
    cov.assign(k * k, 0.0);
    for (std::size_t a = 0; a < k; ++a)
        for (std::size_t b = 0; b < k; ++b)
            cov[a * k + b] = C(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b));
    for (std::size_t a = 0; a < k; ++a)
        if (!(cov[a * k + a] >= 0.0) || !std::isfinite(cov[a * k + a])) return false;
    return true;
}

void set_standard_errors(ModelResult& r) {
    const std::size_t k = r.parameters.size();
    if (r.covariance.size() != k * k) return;
    for (std::size_t a = 0; a < k; ++a)
        r.parameters[a].standard_error = std::sqrt(r.covariance[a * k + a]);
}

// The end of every fit at its minimum θ (gain K, SSE `sse`, prediction M): covariance and
// standard errors when available, the prediction and its error measures.
template <class Eval>
void finish_fit(const Prepared& p, ModelResult& r, Eval&& eval, const std::vector<double>& theta,
                const std::vector<double>& lo, const std::vector<double>& hi, double K, double sse,
                const std::vector<double>& M) {
    std::vector<double> cov;
    if (covariance(p, eval, theta, lo, hi, K, sse, cov)) {
        r.covariance = cov;
        set_standard_errors(r);
    } else {
        r.fit_message += "; covariance unavailable (singular Jacobian or too few measurements)";
    }
    r.prediction = M;
    r.errors = measures(p, M);
}

// One-parameter family (σ/T or n) with a positive parameter, searched in log space.
template <class Eval>
void fit_positive_parameter(const Prepared& p, ModelResult& r, const char* name, double lo,
                            double hi, Eval&& eval_param) {
    std::vector<double> M;
    auto objective = [&](double u) {
        eval_param(std::exp(u), M);
        return gain_sse(p, M);
    };
    const Minimum1D m = minimise_1d(objective, std::log(lo), std::log(hi), 41);
    const double value = std::exp(m.x);
    eval_param(value, M);
    double K = 0.0;
    const double sse = gain_sse(p, M, &K);
    r.available = true;
    r.evaluations = m.evaluations + 1;
    r.fit_status = m.at_bound ? FitStatus::AtBound : FitStatus::Converged;
    r.fit_message = m.at_bound ? std::string(name) + " = " + fmt(value) +
                                     " lies on a bound of the search interval [" + fmt(lo) + ", " +
                                     fmt(hi) + "]"
                               : "minimum of the gain-optimal SSE found (grid of 41 + Brent)";
    r.parameters = {{name, value, std::nullopt}, {"gain", K, std::nullopt}};
    auto eval_vec = [&](const std::vector<double>& t, std::vector<double>& out) {
        eval_param(t[0], out);
    };
    finish_fit(p, r, eval_vec, {value}, {lo}, {hi}, K, sse, M);
}

// Oren–Nayar (σ, ρ) with gain. L = ρ A(σ) + ρ² B(σ) (L1 ∝ ρ, L2 ∝ ρ², models.hpp); A and B
// come from two calls of the core model, so the inner search over ρ costs no model calls.
void fit_oren_nayar(const Prepared& p, ModelResult& r, double sigma_max) {
    constexpr double kRhoMin = 1e-3;  // ρ → 0 leaves the shape A alone with an infinite gain
    std::vector<double> A(p.size()), B(p.size()), L1, Lh, S(p.size());
    int evaluations = 0;
    auto components = [&](double sigma) {
        oren_nayar_prediction(p, {sigma, 1.0}, L1);
        oren_nayar_prediction(p, {sigma, 0.5}, Lh);
        evaluations += 2;
        for (std::size_t j = 0; j < p.size(); ++j) {
            B[j] = 2.0 * (L1[j] - 2.0 * Lh[j]);
            A[j] = L1[j] - B[j];
        }
    };
    auto inner = [&](double rho) {
        for (std::size_t j = 0; j < p.size(); ++j) S[j] = rho * A[j] + rho * rho * B[j];
        return gain_sse(p, S);
    };
    double best_rho = 1.0;
    auto outer = [&](double sigma) {
        components(sigma);
        const Minimum1D m = minimise_1d(inner, kRhoMin, 1.0, 21);
        best_rho = m.x;
        return m.f;
    };
    const Minimum1D ms = minimise_1d(outer, 0.0, sigma_max, 16);
    const double sigma = ms.x;
    outer(sigma);
    const double rho = best_rho;
    std::vector<double> M;
    oren_nayar_prediction(p, {sigma, rho}, M);
    ++evaluations;
    double K = 0.0;
    const double sse = gain_sse(p, M, &K);
    const bool rho_at_bound = rho - kRhoMin <= 1e-6 || 1.0 - rho <= 1e-6;
    r.available = true;
    r.evaluations = evaluations;
    r.fit_status = (ms.at_bound || rho_at_bound) ? FitStatus::AtBound : FitStatus::Converged;
    r.fit_message = (ms.at_bound || rho_at_bound)
                        ? "sigma_rad = " + fmt(sigma) + ", albedo = " + fmt(rho) +
                              ": on a bound of sigma_rad in [0, " + fmt(sigma_max) +
                              "], albedo in [0.001, 1]"
                        : "minimum of the gain-optimal SSE found (nested grid + Brent over "
                          "sigma_rad and albedo)";
    r.parameters = {{"sigma_rad", sigma, std::nullopt},
                    {"albedo", rho, std::nullopt},
                    {"gain", K, std::nullopt}};
    auto eval_vec = [&](const std::vector<double>& t, std::vector<double>& out) {
        oren_nayar_prediction(p, {t[0], t[1]}, out);
    };
    finish_fit(p, r, eval_vec, {sigma, rho}, {0.0, kRhoMin}, {sigma_max, 1.0}, K, sse, M);
}

// ---------------------------------------------------------------------------------------------

TwoPointEstimate two_point_estimate(const BrdfTable& table, const std::vector<bool>& used,
                                    const ComparisonOptions& o) {
    TwoPointEstimate t;
    t.measurement1 = o.measurement1;
    t.measurement2 = o.measurement2;
    const std::optional<std::size_t> k1 = table.find(o.measurement1);
    const std::optional<std::size_t> k2 = table.find(o.measurement2);
    if (!k1 || !k2) {
        t.reason = "measurement " + std::to_string(!k1 ? o.measurement1 : o.measurement2) +
                   " is not in the table";
        return t;
    }
    const BrdfMeasurement& m1 = table.measurements[*k1];
    const BrdfMeasurement& m2 = table.measurements[*k2];
    t.theta1_rad = o.theta1_rad.value_or(m1.theta_i_rad);
    t.theta2_rad = o.theta2_rad.value_or(m2.theta_i_rad);
    t.E1 = brightness_from_brdf(m1.value, t.theta1_rad);
    t.E2 = brightness_from_brdf(m2.value, t.theta2_rad);
    for (const BrdfMeasurement* m : {&m1, &m2}) {
        if (!used[m == &m1 ? *k1 : *k2]) {
            t.reason = "measurement " + std::to_string(m->index) +
                       " is excluded (zero weight or saturated)";
            return t;
        }
        if (m->theta_v_rad > o.normal_view_tolerance_rad) {
            t.reason = "measurement " + std::to_string(m->index) +
                       " has theta_v = " + fmt(rad_to_deg(m->theta_v_rad)) +
                       " deg: Eq. 16-19 need the viewer on the normal (theta_v <= " +
                       fmt(rad_to_deg(o.normal_view_tolerance_rad)) + " deg)";
            return t;
        }
    }
    std::string bad;
    for (const BrdfMeasurement* m : {&m1, &m2})
        if (!(m->value > 0.0))
            bad += (bad.empty() ? "" : " and ") + std::string("measurement ") +
                   std::to_string(m->index) + " has f = " + fmt(m->value, "%.6g") + " <= 0";
    if (!bad.empty()) {
        t.reason = bad +
                   ": the ratio E1/E2 needs two positive brightness values (non-positive "
                   "BRDF values are calibration noise)";
        return t;
    }
    t.available = true;
    t.E1_over_E2 = *t.E1 / *t.E2;
    try {
        t.sigma_over_T_gaussian = sigma_over_T_gaussian_from_ratio(
            *t.E1_over_E2, t.theta1_rad, t.theta2_rad, GeometricFactor::VernoldHarvey);
    } catch (const Error& e) {
        t.gaussian_reason = e.what();
    }
    try {
        t.sigma_over_T_exponential = sigma_over_T_exponential_from_ratio(
            *t.E1_over_E2, t.theta1_rad, t.theta2_rad, GeometricFactor::VernoldHarvey);
    } catch (const Error& e) {
        t.exponential_reason = e.what();
    }
    return t;
}

void pick_winners(Comparison& c) {
    double best = kInf, best_paper = kInf;
    for (const ModelResult& r : c.models) {
        if (!r.available) continue;
        if (r.errors.gain_sse < best) {
            best = r.errors.gain_sse;
            c.winner = r.model;
        }
        if (!is_fit(r.model) && r.errors.paper_sse < best_paper) {
            best_paper = r.errors.paper_sse;
            c.winner_paper_metric = r.model;
        }
    }
}

}  // namespace

// ---------------------------------------------------------------------------------------------

std::string_view to_string(ComparisonModel model) { return info(model).key; }
std::string_view display_name(ComparisonModel model) { return info(model).label; }

ComparisonModel parse_comparison_model(std::string_view name) {
    std::string list;
    for (const ModelInfo& i : kModelInfo) {
        if (name_matches(i.key, name)) return i.model;
        list += (list.empty() ? "" : ", ") + std::string(i.key);
    }
    throw_unknown_name("comparison model", name, list);
}

bool is_fit(ComparisonModel model) {
    switch (model) {
        case ComparisonModel::OrenNayarFit:
        case ComparisonModel::LafortuneFit:
        case ComparisonModel::BkGaussianFit:
        case ComparisonModel::BkExponentialFit:
        case ComparisonModel::VhGaussianFit:
        case ComparisonModel::VhExponentialFit:
            return true;
        default:
            return false;
    }
}

std::string_view to_string(FitStatus status) {
    static constexpr std::array<NameEntry<FitStatus>, 3> kFitStatusNames{{
        {"converged", FitStatus::Converged},
        {"at_bound", FitStatus::AtBound},
        {"failed", FitStatus::Failed},
    }};
    return name_of(kFitStatusNames, status);
}

std::optional<double> ModelResult::parameter(std::string_view name) const {
    for (const ModelParameter& p : parameters)
        if (p.name == name) return p.value;
    return std::nullopt;
}

const ModelResult& Comparison::result(ComparisonModel model) const {
    for (const ModelResult& r : models)
        if (r.model == model) return r;
    throw InvalidArgument("model '" + std::string(to_string(model)) +
                          "' is not in this comparison");
}

ErrorMeasures error_measures(std::span<const double> model, std::span<const double> data,
                             std::span<const double> weights) {
    if (model.empty() || model.size() != data.size())
        throw InvalidArgument("model and data must have the same non-zero length (model: " +
                              std::to_string(model.size()) +
                              ", data: " + std::to_string(data.size()) + ")");
    if (!weights.empty() && weights.size() != data.size())
        throw InvalidArgument("weights must be empty or as long as the data (" +
                              std::to_string(weights.size()) + " vs " +
                              std::to_string(data.size()) + ")");
    double dmax = -kInf, mmax = -kInf;
    for (std::size_t j = 0; j < data.size(); ++j) {
        check::finite("data[" + std::to_string(j) + "]", data[j]);
        check::finite("model[" + std::to_string(j) + "]", model[j]);
        if (!weights.empty()) check::non_negative("weights[" + std::to_string(j) + "]", weights[j]);
        dmax = std::max(dmax, data[j]);
        mmax = std::max(mmax, model[j]);
    }
    if (!(dmax > 0.0))
        throw InvalidArgument("max(data) = " + check::format_number(dmax) +
                              " must be > 0 to normalise the data");
    if (!(mmax > 0.0))
        throw InvalidArgument("max(model) = " + check::format_number(mmax) +
                              " must be > 0 to normalise the model");
    Prepared p;
    p.w.assign(data.size(), 1.0);
    if (!weights.empty()) p.w.assign(weights.begin(), weights.end());
    p.geom.resize(data.size());
    p.d.resize(data.size());
    for (std::size_t j = 0; j < data.size(); ++j) {
        p.d[j] = data[j] / dmax;
        p.sum_w += p.w[j];
        p.sum_wdd += p.w[j] * p.d[j] * p.d[j];
    }
    if (!(p.sum_w > 0.0)) throw InvalidArgument("the weights sum to 0: nothing to compare");
    return measures(p, std::vector<double>(model.begin(), model.end()));
}

void validate(const ComparisonOptions& o) {
    if (o.measurement1 == o.measurement2)
        throw InvalidArgument("measurement1 = measurement2 = " + std::to_string(o.measurement1) +
                              ": the two-point estimate needs two different measurements");
    if (o.theta1_rad) check::polar_angle("theta1", *o.theta1_rad);
    if (o.theta2_rad) check::polar_angle("theta2", *o.theta2_rad);
    check::non_negative("normal_view_tolerance", o.normal_view_tolerance_rad, "rad");
    if (o.oren_nayar) {
        check::non_negative("Oren-Nayar sigma", o.oren_nayar->sigma_rad, "rad");
        if (!(o.oren_nayar->albedo >= 0.0 && o.oren_nayar->albedo <= 1.0))
            throw InvalidArgument(
                "Oren-Nayar albedo = " + check::format_number(o.oren_nayar->albedo) +
                " is outside the valid range [0, 1]");
    }
    check::positive("lafortune_n_min", o.lafortune_n_min);
    check::positive("lafortune_n_step", o.lafortune_n_step);
    check::finite("lafortune_n_max", o.lafortune_n_max);
    if (!(o.lafortune_n_max >= o.lafortune_n_min))
        throw InvalidArgument(
            "lafortune_n_max = " + check::format_number(o.lafortune_n_max) +
            " must be >= lafortune_n_min = " + check::format_number(o.lafortune_n_min));
    if ((o.lafortune_n_max - o.lafortune_n_min) / o.lafortune_n_step > 1e7)
        throw InvalidArgument(
            "the Lafortune search grid [" + check::format_number(o.lafortune_n_min) + ", " +
            check::format_number(o.lafortune_n_max) + "] with step " +
            check::format_number(o.lafortune_n_step) + " has more than 1e7 points");
    auto bounds = [](const char* lo_name, double lo, const char* hi_name, double hi) {
        check::positive(lo_name, lo);
        check::positive(hi_name, hi);
        if (!(hi > lo))
            throw InvalidArgument(std::string(hi_name) + " = " + check::format_number(hi) +
                                  " must be > " + lo_name + " = " + check::format_number(lo));
    };
    bounds("fit_sigma_over_T_min", o.fit_sigma_over_T_min, "fit_sigma_over_T_max",
           o.fit_sigma_over_T_max);
    bounds("fit_lafortune_n_min", o.fit_lafortune_n_min, "fit_lafortune_n_max",
           o.fit_lafortune_n_max);
    check::positive("fit_oren_nayar_sigma_max", o.fit_oren_nayar_sigma_max_rad, "rad");
    if (o.max_overflow_fraction &&
        !(*o.max_overflow_fraction >= 0.0 && *o.max_overflow_fraction <= 1.0))
        throw InvalidArgument(
            "max_overflow_fraction = " + check::format_number(*o.max_overflow_fraction) +
            " is outside the valid range [0, 1]");
}

Comparison compare_brdf(const BrdfTable& table, const ComparisonOptions& o) {
    validate(o);
    if (table.measurements.empty())
        throw InvalidArgument("BRDF table '" + table.name + "' has no measurements");

    Comparison c;
    c.name = table.name;
    c.channel = table.channel;
    c.total_measurements = table.size();

    // Which measurements are used, and why not.
    std::vector<bool> used(table.size(), true);
    for (std::size_t k = 0; k < table.size(); ++k) {
        const BrdfMeasurement& m = table.measurements[k];
        if (m.weight == 0.0) {
            used[k] = false;
            c.data_issues.push_back({m.index,
                                     m.value,
                                     "zero_weight",
                                     {"all"},
                                     "weight 0: left out of every sum and fit"});
            continue;
        }
        if (o.max_overflow_fraction && m.overflow_fraction &&
            *m.overflow_fraction > *o.max_overflow_fraction) {
            used[k] = false;
            c.data_issues.push_back({m.index,
                                     m.value,
                                     "saturated",
                                     {"all"},
                                     "overflow fraction " + fmt(*m.overflow_fraction) + " > " +
                                         fmt(*o.max_overflow_fraction) +
                                         ": left out of every sum, fit and estimate"});
            continue;
        }
        if (!(m.value > 0.0)) {
            const bool pair = m.index == o.measurement1 || m.index == o.measurement2;
            DataIssue issue{m.index, m.value, "non_positive", {}, ""};
            if (pair) {
                issue.excluded_from = {"two_point_estimate"};
                issue.note =
                    "non-positive BRDF (noise): no ratio E1/E2, so no two-point "
                    "estimate; kept in the error sums and fits";
            } else {
                issue.note =
                    "non-positive BRDF (noise around zero): kept in the error sums "
                    "and fits";
            }
            c.data_issues.push_back(issue);
        }
    }
    double dmax = -kInf;
    for (std::size_t k = 0; k < table.size(); ++k) {
        if (!used[k]) continue;
        const BrdfMeasurement& m = table.measurements[k];
        c.measurement.push_back(m.index);
        c.geometry.push_back(m.geometry);
        c.brightness.push_back(brightness_from_brdf(m.value, m.theta_i_rad));
        c.weight.push_back(m.weight);
        dmax = std::max(dmax, c.brightness.back());
    }

    c.two_point = two_point_estimate(table, used, o);

    c.models.reserve(kComparisonModels.size());
    for (ComparisonModel m : kComparisonModels) {
        ModelResult r;
        r.model = m;
        c.models.push_back(r);
    }
    auto result = [&](ComparisonModel m) -> ModelResult& {
        return c.models[static_cast<std::size_t>(m)];
    };

    if (c.measurement.empty() || !(dmax > 0.0)) {
        const std::string why = c.measurement.empty()
                                    ? "no measurement is used (all excluded)"
                                    : "no positive brightness among the used measurements: the "
                                      "data cannot be normalised";
        for (ModelResult& r : c.models) r.reason = why;
        return c;
    }
    std::vector<double> d(c.brightness.size());
    for (std::size_t j = 0; j < d.size(); ++j) d[j] = c.brightness[j] / dmax;
    const Prepared p = prepare(c.geometry, d, c.weight, o.radiometry);

    // Oren–Nayar with given parameters.
    {
        ModelResult& r = result(ComparisonModel::OrenNayar);
        if (o.oren_nayar) {
            r.available = true;
            r.method = "given parameters (" + o.oren_nayar_source + ")";
            r.parameters = {{"sigma_rad", o.oren_nayar->sigma_rad, std::nullopt},
                            {"albedo", o.oren_nayar->albedo, std::nullopt}};
            oren_nayar_prediction(p, *o.oren_nayar, r.prediction);
            r.evaluations = 1;
            r.errors = measures(p, r.prediction);
        } else {
            r.reason =
                "no given Oren-Nayar parameters (the paper's Table 3 lists them for CUReT "
                "samples 25, 34 and 41 only; give sigma_rad and albedo); see "
                "oren_nayar_fit";
        }
    }
    // Lafortune: the paper's exhaustive search for the lowest Table-4 error.
    {
        ModelResult& r = result(ComparisonModel::Lafortune);
        const auto steps = static_cast<long>(
            std::floor((o.lafortune_n_max - o.lafortune_n_min) / o.lafortune_n_step + 1e-9));
        std::vector<double> M;
        double best_err = kInf, best_n = o.lafortune_n_min;
        long best_k = 0;
        for (long k = 0; k <= steps; ++k) {
            const double n = o.lafortune_n_min + static_cast<double>(k) * o.lafortune_n_step;
            lafortune_prediction(p, n, M);
            const double e = paper_sse(p, M);
            if (e < best_err) {
                best_err = e;
                best_n = n;
                best_k = k;
            }
        }
        r.available = true;
        r.method = "exhaustive search of n_d in [" + fmt(o.lafortune_n_min) + ", " +
                   fmt(o.lafortune_n_max) + "] in steps of " + fmt(o.lafortune_n_step) +
                   " for the lowest Table-4 error (" + std::to_string(steps + 1) + " values)";
        r.evaluations = static_cast<int>(steps + 1);
        const bool at_bound = best_k == 0 || best_k == steps;
        r.fit_status = at_bound ? FitStatus::AtBound : FitStatus::Converged;
        r.fit_message = at_bound ? "n_d = " + fmt(best_n) + " is an end of the search interval"
                                 : "interior minimum of the search";
        r.parameters = {{"n", best_n, std::nullopt}};
        lafortune_prediction(p, best_n, r.prediction);
        r.errors = measures(p, r.prediction);
    }
    // B–K (F_Beck) and V–H (F_VH) at the two-point estimate.
    struct VeryRoughVariant {
        ComparisonModel model, fit;
        GeometricFactor factor;
        Correlation correlation;
    };
    const VeryRoughVariant variants[] = {
        {ComparisonModel::BkGaussian, ComparisonModel::BkGaussianFit, GeometricFactor::Beckmann,
         Correlation::Gaussian},
        {ComparisonModel::BkExponential, ComparisonModel::BkExponentialFit,
         GeometricFactor::Beckmann, Correlation::Exponential},
        {ComparisonModel::VhGaussian, ComparisonModel::VhGaussianFit,
         GeometricFactor::VernoldHarvey, Correlation::Gaussian},
        {ComparisonModel::VhExponential, ComparisonModel::VhExponentialFit,
         GeometricFactor::VernoldHarvey, Correlation::Exponential},
    };
    for (const VeryRoughVariant& v : variants) {
        ModelResult& r = result(v.model);
        const bool gaussian = v.correlation == Correlation::Gaussian;
        const std::optional<double> m =
            gaussian ? c.two_point.sigma_over_T_gaussian : c.two_point.sigma_over_T_exponential;
        if (!m) {
            r.reason = "two-point estimate unavailable: " +
                       (!c.two_point.available ? c.two_point.reason
                                               : (gaussian ? c.two_point.gaussian_reason
                                                           : c.two_point.exponential_reason));
            continue;
        }
        r.available = true;
        r.method = std::string("two-point estimate of sigma/T (") +
                   (gaussian ? "Eq. 17" : "Eq. 19") + ", F_VH, measurements " +
                   std::to_string(o.measurement1) + " and " + std::to_string(o.measurement2) +
                   "); " + (gaussian ? "Eq. 4" : "Eq. 5") + " with " +
                   (v.factor == GeometricFactor::Beckmann ? "F_Beck" : "F_VH") + ", " +
                   std::string(to_string(o.radiometry));
        r.parameters = {{"sigma_over_T", *m, std::nullopt}};
        r.evaluations = 1;
        very_rough_prediction(p, v.factor, v.correlation, *m, r.prediction);
        r.errors = measures(p, r.prediction);
    }

    if (o.fits) {
        {
            ModelResult& r = result(ComparisonModel::OrenNayarFit);
            r.method = "least squares over sigma_rad, albedo and the gain";
            fit_oren_nayar(p, r, o.fit_oren_nayar_sigma_max_rad);
        }
        {
            ModelResult& r = result(ComparisonModel::LafortuneFit);
            r.method = "least squares over n and the gain";
            fit_positive_parameter(
                p, r, "n", o.fit_lafortune_n_min, o.fit_lafortune_n_max,
                [&](double n, std::vector<double>& out) { lafortune_prediction(p, n, out); });
        }
        for (const VeryRoughVariant& v : variants) {
            ModelResult& r = result(v.fit);
            r.method = std::string("least squares over sigma/T and the gain; ") +
                       (v.correlation == Correlation::Gaussian ? "Eq. 4" : "Eq. 5") + " with " +
                       (v.factor == GeometricFactor::Beckmann ? "F_Beck" : "F_VH") + ", " +
                       std::string(to_string(o.radiometry));
            fit_positive_parameter(p, r, "sigma_over_T", o.fit_sigma_over_T_min,
                                   o.fit_sigma_over_T_max, [&](double m, std::vector<double>& out) {
                                       very_rough_prediction(p, v.factor, v.correlation, m, out);
                                   });
        }
    } else {
        for (ModelResult& r : c.models)
            if (is_fit(r.model)) r.reason = "fits not requested";
    }
    pick_winners(c);
    return c;
}

Comparison compare_curet_sample(const CuretDatabase& db, int sample,
                                const ComparisonOptions& options) {
    const BrdfTable table = db.sample_table(sample);  // throws for an unknown sample
    ComparisonOptions o = options;
    if (!o.oren_nayar) {
        if (const auto on = paper_oren_nayar_params(sample)) {
            o.oren_nayar = on;
            o.oren_nayar_source = "the paper's Table 3, from the CUReT database";
        }
    }
    Comparison c = compare_brdf(table, o);
    c.sample = sample;
    const std::string_view name = curet_sample_name(sample);
    if (!name.empty()) c.name = std::string(name);
    return c;
}

std::vector<Comparison> compare_curet_all(const CuretDatabase& db, const ComparisonOptions& options,
                                          int threads) {
    validate(options);
    if (threads < 0)
        throw InvalidArgument("threads = " + std::to_string(threads) + " must be >= 0");
    const std::size_t n = db.samples.size();
    std::vector<Comparison> out(n);
    std::size_t workers = threads > 0 ? static_cast<std::size_t>(threads)
                                      : std::max(1u, std::thread::hardware_concurrency());
    workers = std::max<std::size_t>(1, std::min(workers, n));
    std::atomic<std::size_t> next{0};
    std::exception_ptr error;
    std::mutex error_mutex;
    auto work = [&] {
        while (true) {
            const std::size_t k = next.fetch_add(1);
            if (k >= n) return;
            try {
                out[k] = compare_curet_sample(db, db.samples[k], options);
            } catch (...) {
                std::lock_guard<std::mutex> lock(error_mutex);
                if (!error) error = std::current_exception();
                next.store(n);
            }
        }
    };
    if (workers == 1) {
        work();
    } else {
        std::vector<std::thread> pool;
        for (std::size_t t = 0; t < workers; ++t) pool.emplace_back(work);
        for (std::thread& t : pool) t.join();
    }
    if (error) std::rethrow_exception(error);
    return out;
}

// ---------------------------------------------------------------------------------------------
// Output

namespace {

using json = nlohmann::ordered_json;

json number(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }
json number(const std::optional<double>& v) { return v ? number(*v) : json(nullptr); }
json text_or_null(const std::string& s) { return s.empty() ? json(nullptr) : json(s); }

std::vector<double> normalised(const std::vector<double>& v) {
    double mx = -kInf;
    for (double x : v) mx = std::max(mx, x);
    std::vector<double> out(v.size(), 0.0);
    if (mx > 0.0)
        for (std::size_t j = 0; j < v.size(); ++j) out[j] = v[j] / mx;
    return out;
}

json comparison_json(const Comparison& c, bool series) {
    json j;
    j["sample"] = c.sample > 0 ? json(c.sample) : json(nullptr);
    j["name"] = text_or_null(c.name);
    j["channel"] = text_or_null(c.channel);
    j["measurements"] = c.total_measurements;
    j["used"] = c.measurement.size();
    const TwoPointEstimate& t = c.two_point;
    j["E1_over_E2"] = number(t.E1_over_E2);
    j["sigma_over_T_gaussian"] = number(t.sigma_over_T_gaussian);
    j["sigma_over_T_exponential"] = number(t.sigma_over_T_exponential);
    json tp;
    tp["available"] = t.available;
    tp["reason"] = text_or_null(t.reason);
    tp["measurement1"] = t.measurement1;
    tp["measurement2"] = t.measurement2;
    tp["theta1_deg"] = t.E1 ? number(rad_to_deg(t.theta1_rad)) : json(nullptr);
    tp["theta2_deg"] = t.E2 ? number(rad_to_deg(t.theta2_rad)) : json(nullptr);
    tp["E1"] = number(t.E1);
    tp["E2"] = number(t.E2);
    tp["factor"] = "vh";
    tp["gaussian_reason"] = text_or_null(t.gaussian_reason);
    tp["exponential_reason"] = text_or_null(t.exponential_reason);
    if (t.sigma_over_T_gaussian) {
        tp["theta_K_deg_gaussian"] =
            number(rad_to_deg(caron_theta_K_rad(*t.sigma_over_T_gaussian)));
        tp["rms_slope_gaussian"] = number(rms_slope(*t.sigma_over_T_gaussian));
    }
    j["two_point"] = tp;
    json sse, rmse, gsse;
    for (const ModelResult& r : c.models) {
        const char* key = info(r.model).key;
        sse[key] = r.available ? number(r.errors.paper_sse) : json(nullptr);
        rmse[key] = r.available ? number(r.errors.rmse) : json(nullptr);
        gsse[key] = r.available ? number(r.errors.gain_sse) : json(nullptr);
    }
    j["sse"] = sse;
    j["rmse"] = rmse;
    j["sse_gain"] = gsse;
    j["winner"] = c.winner ? json(to_string(*c.winner)) : json(nullptr);
    j["winner_paper_metric"] =
        c.winner_paper_metric ? json(to_string(*c.winner_paper_metric)) : json(nullptr);
    json models;
    for (const ModelResult& r : c.models) {
        json m;
        m["label"] = info(r.model).label;
        m["available"] = r.available;
        m["reason"] = text_or_null(r.reason);
        m["method"] = text_or_null(r.method);
        json params = json::object(), errs = json::object();
        for (const ModelParameter& p : r.parameters) {
            params[p.name] = number(p.value);
            if (p.standard_error) errs[p.name] = number(*p.standard_error);
        }
        m["parameters"] = params;
        m["standard_errors"] = errs;
        m["fit_status"] = r.fit_status ? json(to_string(*r.fit_status)) : json(nullptr);
        m["fit_message"] = text_or_null(r.fit_message);
        m["evaluations"] = r.evaluations;
        m["sse"] = r.available ? number(r.errors.paper_sse) : json(nullptr);
        m["rmse"] = r.available ? number(r.errors.rmse) : json(nullptr);
        m["sse_gain"] = r.available ? number(r.errors.gain_sse) : json(nullptr);
        m["gain"] = r.available ? number(r.errors.gain) : json(nullptr);
        models[info(r.model).key] = m;
    }
    j["models"] = models;
    json issues = json::array();
    for (const DataIssue& d : c.data_issues) {
        json i;
        i["measurement"] = d.measurement;
        i["f"] = number(d.value);
        i["issue"] = d.issue;
        i["excluded_from"] = d.excluded_from;
        i["note"] = d.note;
        issues.push_back(i);
    }
    j["data_issues"] = issues;
    if (series) {
        json s;
        s["measurement"] = c.measurement;
        std::vector<double> ti, ts, ps;
        for (const Geometry& g : c.geometry) {
            ti.push_back(rad_to_deg(g.theta_i_rad));
            ts.push_back(rad_to_deg(g.theta_s_rad));
            ps.push_back(rad_to_deg(g.phi_s_rad));
        }
        s["theta_i_deg"] = ti;
        s["theta_s_deg"] = ts;
        s["phi_s_deg"] = ps;
        s["data"] = normalised(c.brightness);
        json ms, mg;
        for (const ModelResult& r : c.models) {
            ms[info(r.model).key] = r.available ? json(normalised(r.prediction)) : json(nullptr);
            if (!r.available) {
                mg[info(r.model).key] = nullptr;
                continue;
            }
            std::vector<double> scaled(r.prediction.size());
            for (std::size_t k = 0; k < scaled.size(); ++k)
                scaled[k] = r.errors.gain * r.prediction[k];
            mg[info(r.model).key] = scaled;
        }
        s["models"] = ms;       // each model / its maximum (the paper's Fig. 10)
        s["models_gain"] = mg;  // K · model with the optimal gain K (compare with `data`)
        j["series"] = s;
    }
    return j;
}

std::string csv_number(double v) { return std::isfinite(v) ? fmt(v, "%.10g") : ""; }
std::string csv_number(const std::optional<double>& v) { return v ? csv_number(*v) : ""; }

std::string csv_text(const std::string& s) {
    if (s.find_first_of(",\"\n") == std::string::npos) return s;
    std::string out = "\"";
    for (char ch : s) {
        if (ch == '"') out += '"';
        out += ch;
    }
    return out + "\"";
}

std::string issues_summary(const Comparison& c) {
    std::string s;
    for (const DataIssue& d : c.data_issues) {
        if (!s.empty()) s += "; ";
        s += std::to_string(d.measurement) + ":" + d.issue;
        if (!d.excluded_from.empty()) {
            s += " (excluded from";
            for (const std::string& e : d.excluded_from) s += " " + e;
            s += ")";
        }
    }
    return s;
}

std::string md_escape(std::string s) {
    std::string out;
    for (char ch : s) {
        if (ch == '|')
            out += "\\|";
        else if (ch == '\n')
            out += ' ';
        else
            out += ch;
    }
    return out;
}

}  // namespace

std::string to_json(const Comparison& comparison, bool series, int indent) {
    return comparison_json(comparison, series).dump(indent) + "\n";
}

std::string to_json(const std::vector<Comparison>& comparisons, bool series, int indent) {
    json arr = json::array();
    for (const Comparison& c : comparisons) arr.push_back(comparison_json(c, series));
    return arr.dump(indent) + "\n";
}

std::string to_csv(const std::vector<Comparison>& comparisons) {
    std::ostringstream out;
    out << "sample,name,channel,used,E1_over_E2,sigma_over_T_gaussian,sigma_over_T_exponential";
    for (const char* measure : {"sse", "rmse", "sse_gain"})
        for (ComparisonModel m : kComparisonModels) out << "," << measure << "_" << to_string(m);
    out << ",lafortune_n,winner,winner_paper_metric,two_point_reason,nonpositive_count,"
           "data_issues\n";
    for (const Comparison& c : comparisons) {
        out << (c.sample > 0 ? std::to_string(c.sample) : "") << "," << csv_text(c.name) << ","
            << csv_text(c.channel) << "," << c.measurement.size() << ","
            << csv_number(c.two_point.E1_over_E2) << ","
            << csv_number(c.two_point.sigma_over_T_gaussian) << ","
            << csv_number(c.two_point.sigma_over_T_exponential);
        for (int measure = 0; measure < 3; ++measure)
            for (const ModelResult& r : c.models) {
                out << ",";
                if (!r.available) continue;
                out << csv_number(measure == 0   ? r.errors.paper_sse
                                  : measure == 1 ? r.errors.rmse
                                                 : r.errors.gain_sse);
            }
        std::size_t nonpositive = 0;
        for (const DataIssue& d : c.data_issues) nonpositive += d.issue == "non_positive";
        out << "," << csv_number(c.result(ComparisonModel::Lafortune).parameter("n")) << ","
            << (c.winner ? std::string(to_string(*c.winner)) : "") << ","
            << (c.winner_paper_metric ? std::string(to_string(*c.winner_paper_metric)) : "") << ","
            << csv_text(c.two_point.available ? "" : c.two_point.reason) << "," << nonpositive
            << "," << csv_text(issues_summary(c)) << "\n";
    }
    return out.str();
}

std::string to_markdown(const std::vector<Comparison>& comparisons) {
    std::ostringstream out;
    out << "| sample | name | E1/E2 | σ/T_G | σ/T_E";
    for (ComparisonModel m : kPaperComparisonModels) out << " | " << display_name(m);
    out << " | n_d | best fit (gain SSE) | winner, Table-4 metric | notes |\n";
    out << "|---:|---|---:|---:|---:";
    for (std::size_t k = 0; k < kPaperComparisonModels.size(); ++k) out << "|---:";
    out << "|---:|---|---|---|\n";
    auto cell = [](const std::optional<double>& v, const char* spec) {
        return v && std::isfinite(*v) ? fmt(*v, spec) : std::string("—");
    };
    for (const Comparison& c : comparisons) {
        out << "| " << (c.sample > 0 ? std::to_string(c.sample) : "") << " | " << md_escape(c.name)
            << " | " << cell(c.two_point.E1_over_E2, "%.6f") << " | "
            << cell(c.two_point.sigma_over_T_gaussian, "%.4f") << " | "
            << cell(c.two_point.sigma_over_T_exponential, "%.4f");
        for (ComparisonModel m : kPaperComparisonModels) {
            const ModelResult& r = c.result(m);
            out << " | " << (r.available ? cell(r.errors.paper_sse, "%.3f") : std::string("—"));
        }
        out << " | " << cell(c.result(ComparisonModel::Lafortune).parameter("n"), "%.2f");
        out << " | "
            << (c.winner ? std::string(display_name(*c.winner)) + " (" +
                               fmt(c.result(*c.winner).errors.gain_sse, "%.3f") + ")"
                         : std::string("—"));
        out << " | "
            << (c.winner_paper_metric ? std::string(display_name(*c.winner_paper_metric))
                                      : std::string("—"));
        std::string notes;
        if (!c.two_point.available) notes = "two-point estimate unavailable: " + c.two_point.reason;
        std::size_t nonpositive = 0;
        for (const DataIssue& d : c.data_issues) nonpositive += d.issue == "non_positive";
        if (nonpositive)
            notes += (notes.empty() ? "" : "; ") + std::to_string(nonpositive) +
                     " non-positive value(s) kept in the sums";
        out << " | " << md_escape(notes) << " |\n";
    }
    return out.str();
}

}  // namespace roughscope
