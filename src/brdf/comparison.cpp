// Models against measured BRDFs (paper §5.3, Tables 3–4): the two-point estimate, every model's
// prediction, the paper's error and two scale-free ones, least-squares fits, and the outputs.
#include "roughscope/brdf/comparison.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <exception>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <numeric>
#include <sstream>
#include <thread>

#include <Eigen/Dense>

#include "comparison_data.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/names.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/core/parallel.hpp"
#include "roughscope/estimation/estimation.hpp"
#include "roughscope/fit/engine.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/precomputed_terms.hpp"

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

// ---------------------------------------------------------------------------------------------
// The used measurements with everything the model evaluations need, computed once per table.

//
// The geometry-only terms of one model family at a time (N can be 1e6): each is built before the
// family's models are evaluated and released after them (prepare_*, release_*), so that at most
// one family's terms coexist with a fit's working set.
struct Prepared {
    std::span<const Geometry> geom;  // the comparison's (not copied: N can be 1e6)
    std::vector<double> d;           // data brightness normalised by its maximum
    std::span<const double> w;
    bool keep_predictions = true;  // ModelResult::prediction kept after the errors
    double sum_w = 0.0;
    double sum_wdd = 0.0;
    Radiometry radiometry = Radiometry::Radiance;  // §3.3 interpretation of the B–K models
    std::vector<double> cos_i, log_cos_i_cos_s;    // Lafortune diffuse lobe
    GeometricFactor factor = GeometricFactor::Beckmann;
    VeryRoughTerms very_rough_terms;  // Eq. 4/5 with `factor` (F_Beck or F_VH, §3.2)
    OrenNayarTerms oren_nayar;

    std::size_t size() const { return geom.size(); }
    const VeryRoughTerms& very_rough(GeometricFactor f) const {
        assert(f == factor && very_rough_terms.size() == size());
        (void)f;
        return very_rough_terms;
    }
};

// The data of every model (the geometries of a BrdfTable are valid: check::geometry holds).
Prepared prepare(const std::vector<Geometry>& geom, std::vector<double> d_normalised,
                 const std::vector<double>& w, Radiometry radiometry) {
    Prepared p;
    p.geom = geom;
    p.d = std::move(d_normalised);
    p.w = w;
    const std::size_t n = geom.size();
    p.radiometry = radiometry;
    for (std::size_t j = 0; j < n; ++j) {
        p.sum_w += w[j];
        p.sum_wdd += w[j] * p.d[j] * p.d[j];
    }
    return p;
}

void prepare_lafortune(Prepared& p) {
    const std::size_t n = p.size();
    p.cos_i.resize(n);
    p.log_cos_i_cos_s.resize(n);
    for (std::size_t j = 0; j < n; ++j) {
        const Geometry& g = p.geom[j];
        p.cos_i[j] = std::cos(g.theta_i_rad);
        p.log_cos_i_cos_s[j] = std::log(p.cos_i[j] * std::cos(g.theta_s_rad));
    }
}

void release_lafortune(Prepared& p) {
    std::vector<double>().swap(p.cos_i);
    std::vector<double>().swap(p.log_cos_i_cos_s);
}

void prepare_very_rough(Prepared& p, GeometricFactor factor) {
    p.very_rough_terms = VeryRoughTerms();  // the previous family's terms first
    p.factor = factor;
    p.very_rough_terms = VeryRoughTerms(p.geom, factor, p.radiometry);
}

// Very-rough brightness, Eq. 4 (Gaussian) / Eq. 5 (exponential) as published with F_Beck or F_VH,
// times the radiometric factor of §3.3: very_rough_brightness at each geometry, from the
// geometry-only terms (precomputed_terms.hpp).
void very_rough_prediction(const Prepared& p, GeometricFactor factor, Correlation c,
                           double sigma_over_T, std::vector<double>& out) {
    out.resize(p.size());
    p.very_rough(factor).brightness(sigma_over_T, c, out);
}

// Lafortune diffuse lobe E = (cos θi cos θs)^n cos θi (models.hpp), via precomputed logarithms.
void lafortune_prediction(const Prepared& p, double n, std::span<double> out) {
    for (std::size_t j = 0; j < p.size(); ++j)
        out[j] = p.cos_i[j] * std::exp(n * p.log_cos_i_cos_s[j]);
}

// Oren–Nayar with inter-reflection (models.hpp).
void oren_nayar_prediction(const Prepared& p, const OrenNayarParams& on, std::vector<double>& out) {
    out.resize(p.size());
    p.oren_nayar.radiance(on, out);
}

// "N measurements at K distinct geometries": why a fit or search cannot determine its parameters.
std::string distinct_geometries_text(std::span<const Geometry> geom) {
    std::vector<std::array<double, 3>> distinct;
    distinct.reserve(geom.size());
    for (const Geometry& g : geom) distinct.push_back({g.theta_i_rad, g.theta_s_rad, g.phi_s_rad});
    std::sort(distinct.begin(), distinct.end());
    const auto count =
        static_cast<std::size_t>(std::unique(distinct.begin(), distinct.end()) - distinct.begin());
    return std::to_string(geom.size()) + " measurement" + (geom.size() == 1 ? "" : "s") + " at " +
           std::to_string(count) + " distinct geometr" + (count == 1 ? "y" : "ies");
}

// The Lafortune diffuse lobe cos θi exp(n ln(cos θi cos θs)) depends on the measurement through
// (cos θi, ln(cos θi cos θs)) only: the distinct pairs (`cos_i`, `log_cos_i_cos_s`) and, per
// measurement, the index of its pair (`group`). Tables measured on a grid repeat each (θi, θs)
// at many azimuths, so that the search evaluates far fewer exponentials than measurements.
struct LafortuneGroups {
    std::vector<double> cos_i, log_cos_i_cos_s;
    std::vector<std::uint32_t> group;
};

LafortuneGroups lafortune_groups(const Prepared& p) {
    LafortuneGroups g;
    std::vector<std::uint32_t> order(p.size());
    std::iota(order.begin(), order.end(), 0U);
    const auto key = [&p](std::uint32_t j) { return std::pair(p.cos_i[j], p.log_cos_i_cos_s[j]); };
    std::sort(order.begin(), order.end(),
              [&key](std::uint32_t a, std::uint32_t b) { return key(a) < key(b); });
    g.group.resize(p.size());
    for (std::size_t k = 0; k < order.size(); ++k) {
        if (k == 0 || key(order[k]) != key(order[k - 1])) {
            g.cos_i.push_back(p.cos_i[order[k]]);
            g.log_cos_i_cos_s.push_back(p.log_cos_i_cos_s[order[k]]);
        }
        g.group[order[k]] = static_cast<std::uint32_t>(g.cos_i.size() - 1);
    }
    return g;
}

// paper_sse (below) of the Lafortune diffuse lobe with exponent n, through the distinct pairs:
// the same operations on the same values as paper_sse of lafortune_prediction, so the same result
// to the last bit. `M` is scratch space (one value per pair).
double lafortune_paper_sse(const Prepared& p, const LafortuneGroups& g, double n,
                           std::vector<double>& M) {
    M.resize(g.cos_i.size());
    double mmax = -kInf;
    for (std::size_t u = 0; u < M.size(); ++u) {
        M[u] = g.cos_i[u] * std::exp(n * g.log_cos_i_cos_s[u]);
        mmax = std::max(mmax, M[u]);
    }
    if (!(mmax > 0.0) || !std::isfinite(mmax)) return kInf;
    for (double& m : M) m /= mmax;
    double s = 0.0;
    for (std::size_t j = 0; j < p.size(); ++j) {
        const double r = M[g.group[j]] - p.d[j];
        s += p.w[j] * r * r;
    }
    return s;
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

// The errors of the model's prediction; the prediction itself is then released unless kept.
void set_errors(const Prepared& p, ModelResult& r) {
    r.errors = measures(p, r.prediction);
    if (!p.keep_predictions) std::vector<double>().swap(r.prediction);
}

// ---------------------------------------------------------------------------------------------
// Fits (the "+ fit" columns): min over (θ, gain) of Σ w (gain · M(θ) − d)² with d = data/max data,
// on the library's least-squares engine (fit/engine.hpp): absolute residuals, the gain profiled out
// by variable projection, a grid start over the bounds (no start value needed), Levenberg–Marquardt
// with the bounds honoured, covariance of (θ, gain) from the Jacobian, identifiability checked.

using Prediction = std::function<void(std::span<const double> theta, std::span<double> out)>;

// The engine's problem for one model family over the used measurements; its data are lent by
// run_fit (p.d, not copied: N can be 1e6).
LeastSquaresProblem fit_problem(const Prepared& p, std::vector<ParameterSpec> parameters,
                                Prediction predict) {
    LeastSquaresProblem P;
    P.parameters = std::move(parameters);
    // All weights 1 (every table without a weight column) is the engine's default: no copy.
    if (std::any_of(p.w.begin(), p.w.end(), [](double v) { return v != 1.0; }))
        P.weights.assign(p.w.begin(), p.w.end());
    P.residual = ResidualType::Absolute;
    P.gain = GainMode::Profiled;
    P.model = [predict = std::move(predict)](std::span<const double> theta, std::span<double> out) {
        predict(theta, out);
        return true;
    };
    return P;
}

ParameterSpec fit_parameter(const char* name, double lower, double upper, Transform transform,
                            int grid_points) {
    ParameterSpec s;
    s.name = name;
    s.lower = lower;
    s.upper = upper;
    s.transform = transform;
    s.grid_points = grid_points;
    return s;
}

// Solves and fills the model's result: parameters (gain last) with standard errors (none for a
// parameter on a bound), status, covariance, prediction M(θ) at the solution and its errors.
void run_fit(Prepared& p, ModelResult& r, LeastSquaresProblem problem) {
    LeastSquaresOptions options;
    options.function_tolerance = 1e-15;  // flat minima: converge the parameters, not only the SSE
    // The data are lent to the problem for the solve and given back (also on an exception).
    struct Lend {
        std::vector<double>& owner;
        std::vector<double>& borrower;
        Lend(std::vector<double>& o, std::vector<double>& b) : owner(o), borrower(b) {
            borrower = std::move(owner);
        }
        ~Lend() { owner = std::move(borrower); }
        Lend(const Lend&) = delete;
        Lend& operator=(const Lend&) = delete;
    };
    LeastSquaresResult lsq;
    {
        const Lend lend(p.d, problem.data);
        lsq = solve_least_squares(problem, options);
    }
    r.evaluations = lsq.evaluations;
    r.fit_status = lsq.status;
    r.fit_message = lsq.message;
    if (lsq.status == SolverStatus::NotIdentifiable)
        r.fit_message = "not identifiable (" + distinct_geometries_text(p.geom) + " for " +
                        std::to_string(lsq.num_parameters) + " parameters including the gain); " +
                        r.fit_message;
    if (lsq.model.empty()) {
        r.reason = "the fit failed: " + lsq.message;
        return;
    }
    r.available = true;
    r.parameters.clear();
    for (const FitParameter& fp : lsq.parameters)
        r.parameters.push_back({fp.name, fp.value,
                                lsq.covariance_available && !fp.at_bound && fp.identified
                                    ? std::optional<double>(fp.std_error)
                                    : std::nullopt,
                                fp.identified});
    if (lsq.covariance_available) {
        const auto k = lsq.covariance.rows();
        r.covariance.assign(static_cast<std::size_t>(k * k), 0.0);
        for (Eigen::Index a = 0; a < k; ++a)
            for (Eigen::Index b = 0; b < k; ++b)
                r.covariance[static_cast<std::size_t>(a * k + b)] = lsq.covariance(a, b);
    }
    r.prediction = lsq.model;
    set_errors(p, r);
}

// σ/T (B–K or V–H, Gaussian or exponential): 41 log-spaced starts over the bounds.
void fit_very_rough(Prepared& p, ModelResult& r, GeometricFactor factor, Correlation c,
                    double lower, double upper) {
    run_fit(p, r,
            fit_problem(p, {fit_parameter("sigma_over_T", lower, upper, Transform::Log, 41)},
                        [&terms = p.very_rough(factor), c](std::span<const double> theta,
                                                           std::span<double> out) {
                            terms.brightness(theta[0], c, out);
                        }));
}

// Lafortune exponent n: 41 log-spaced starts over the bounds.
void fit_lafortune(Prepared& p, ModelResult& r, double lower, double upper) {
    run_fit(p, r,
            fit_problem(p, {fit_parameter("n", lower, upper, Transform::Log, 41)},
                        [&p](std::span<const double> theta, std::span<double> out) {
                            lafortune_prediction(p, theta[0], out);
                        }));
}

// Whether σ_ON = 0 is a minimum of the profiled Oren–Nayar SSE for every ρ ∈ [rho_min, 1]: the
// slope dSSE/d(σ²) of fit_oren_nayar's comment is positive at both ends of the ρ range (it is
// linear in ρ). A'(0) and B'(0) by a difference in s = σ² (the components are analytic in s).
bool lambert_minimum(const Prepared& p, double rho_min, int& evaluations) {
    const std::size_t n = p.size();
    std::vector<double> A0(n), B0(n), A1(n), B1(n);
    constexpr double kSigma = 1e-4, kS = kSigma * kSigma;
    p.oren_nayar.components(0.0, A0, B0);
    p.oren_nayar.components(kSigma, A1, B1);
    evaluations += 2;
    const double lambda = optimal_gain(A0, p.d, p.w, ResidualType::Absolute);
    if (!(lambda > 0.0) || !std::isfinite(lambda)) return false;
    double alpha = 0.0, beta = 0.0, scale = 0.0;
    for (std::size_t j = 0; j < n; ++j) {
        const double res = p.w[j] * (lambda * A0[j] - p.d[j]);
        alpha += res * (A1[j] - A0[j]) / kS;
        beta += res * B1[j] / kS;
        scale += std::abs(res) * (std::abs(A1[j] - A0[j]) + rho_min * std::abs(B1[j])) / kS;
    }
    // A margin well above the O(s) error of the differences and the rounding of the sums.
    const double margin = 1e-6 * scale;
    return alpha + rho_min * beta > margin && alpha + beta > margin;
}

// The Oren–Nayar fit's result at σ_ON = 0 (lambert_minimum holds): the engine's verdict there
// (NotIdentifiable: albedo and gain trade off exactly; σ_ON held by its lower bound), with the
// start's albedo and the Lambert gain, no covariance.
void finish_at_lambert(const Prepared& p, ModelResult& r, double rho, double sigma_max,
                       int evaluations) {
    std::vector<double> A(p.size()), B(p.size());
    p.oren_nayar.components(0.0, A, B);
    r.prediction.resize(p.size());
    for (std::size_t j = 0; j < p.size(); ++j) r.prediction[j] = rho * A[j] + rho * rho * B[j];
    r.evaluations = evaluations + 1;
    r.available = true;
    r.fit_status = SolverStatus::NotIdentifiable;
    set_errors(p, r);
    r.parameters = {{"sigma_rad", 0.0, std::nullopt, true},
                    {"albedo", rho, std::nullopt, false},
                    {"gain", r.errors.gain, std::nullopt, false}};
    r.covariance.clear();
    r.fit_message =
        "Lambert limit: the grid start has sigma_rad = 0 and the slope of the profiled SSE in "
        "sigma_rad^2 is positive there for every albedo, so the fit ends at the start; the "
        "Jacobian is rank deficient: the data do not determine albedo, gain (a parameter without "
        "effect, repeated geometries or constant data, or parameters that trade off exactly); on "
        "a bound: sigma_rad = 0 in [0, " +
        format_message(sigma_max, 6) + "]";
}

// Oren–Nayar (σ_ON, ρ_ON): a 16 × 21 grid over σ_ON ∈ [0, sigma_max] rad, ρ_ON ∈ [0.001, 1]
// (ρ → 0 leaves the shape of the first term alone with an infinite gain). At σ_ON = 0 the model
// is Lambert's, ρ_ON · (first term), so ρ_ON and the gain trade off exactly: NotIdentifiable.
//
// With L = ρ A(σ) + ρ² B(σ) (L1 ∝ ρ, L2 ∝ ρ², precomputed_terms.hpp) the SSE with the gain
// profiled out is, for each σ, a rational function of ρ of five weighted sums:
//   SSE(σ, ρ) = Σw d² − (ρ Σw A d + ρ² Σw B d)² / (ρ² Σw A² + 2ρ³ Σw A B + ρ⁴ Σw B²),
// so the grid start (the engine's grid, in the engine's order) costs one evaluation of A and B
// per σ, and the engine starts from its best point.
//
// The Lambert limit: the model depends on σ through σ² only, so with s = σ², at s = 0 and the
// Lambert gain λ = K ρ (K M = λ A(0)), by variable projection
//   dSSE/ds = 2λ (Σ w r A'(0) + ρ Σ w r B'(0)),   r = λ A(0) − d   (' = d/ds),
// linear in ρ. When the grid start lies at σ = 0 and this slope is positive at both ends of the
// ρ range, and a finer scan up to the grid's next σ finds nothing lower, σ = 0 is taken as the
// minimum (held by its bound) for every ρ; the profiled SSE does not depend
// on ρ there: the fit ends at the start, with the engine's NotIdentifiable verdict (albedo and gain
// trade off exactly; σ on its bound), without a solver run that would only creep along the flat
// direction.
void fit_oren_nayar(Prepared& p, ModelResult& r, double sigma_max) {
    constexpr double kRhoMin = 1e-3;
    constexpr int kSigmaPoints = 16, kRhoPoints = 21;
    const std::size_t n = p.size();
    int evaluations = 0;
    // Weighted sums of σ's components; false when the profiled SSE is undefined at every ρ.
    struct Sums {
        double ad = 0, bd = 0, aa = 0, ab = 0, bb = 0;
    };
    auto sums = [&](double sigma) {
        const OrenNayarTerms::Coefficients coefficients = OrenNayarTerms::coefficients(sigma);
        ++evaluations;
        Sums S;
        for (std::size_t j = 0; j < n; ++j) {
            const double w = p.w[j];
            const double A = p.oren_nayar.term_a(j, coefficients);
            const double B = p.oren_nayar.term_b(j, coefficients);
            S.ad += w * A * p.d[j];
            S.bd += w * B * p.d[j];
            S.aa += w * A * A;
            S.ab += w * A * B;
            S.bb += w * B * B;
        }
        return S;
    };
    auto profiled = [&p](const Sums& S, double rho) -> double {
        const double md = rho * S.ad + rho * rho * S.bd;
        const double mm = rho * rho * (S.aa + 2.0 * rho * S.ab + rho * rho * S.bb);
        if (!(mm > 0.0) || !std::isfinite(mm)) return kInf;
        const double sse = p.sum_wdd - md * md / mm;
        if (!std::isfinite(sse)) return kInf;
        return sse;
    };
    // The engine's grid (engine.cpp, grid_starts): σ the inner axis, the first lowest point wins.
    std::vector<Sums> by_sigma(kSigmaPoints);
    for (int k = 0; k < kSigmaPoints; ++k)
        by_sigma[static_cast<std::size_t>(k)] = sums(sigma_max * k / (kSigmaPoints - 1));
    double best = kInf, sigma0 = 0.0, rho0 = kRhoMin;
    for (int m = 0; m < kRhoPoints; ++m) {
        const double rho = kRhoMin + (1.0 - kRhoMin) * m / (kRhoPoints - 1);
        for (int k = 0; k < kSigmaPoints; ++k) {
            const double sse = profiled(by_sigma[static_cast<std::size_t>(k)], rho);
            if (sse < best) {
                best = sse;
                sigma0 = sigma_max * k / (kSigmaPoints - 1);
                rho0 = rho;
            }
        }
    }

    // A finer scan between σ = 0 and the grid's next σ (a dip there, where the ρ² term wins
    // beyond the slope at 0, sends the fit to the engine).
    auto no_dip = [&] {
        constexpr int kFine = 10;
        for (int k = 1; k < kFine; ++k) {
            const Sums S = sums(sigma_max / (kSigmaPoints - 1) * k / kFine);
            for (int m = 0; m < kRhoPoints; ++m)
                if (profiled(S, kRhoMin + (1.0 - kRhoMin) * m / (kRhoPoints - 1)) < best)
                    return false;
        }
        return true;
    };
    if (std::isfinite(best) && sigma0 == 0.0 && lambert_minimum(p, kRhoMin, evaluations) &&
        no_dip()) {
        finish_at_lambert(p, r, rho0, sigma_max, evaluations);
        return;
    }

    // L = ρ A(σ) + ρ² B(σ), A and B computed per geometry from the σ-only coefficients (a few
    // multiplications: no N-sized buffer of components).
    ParameterSpec sigma_spec = fit_parameter("sigma_rad", 0.0, sigma_max, Transform::Linear, 16);
    ParameterSpec rho_spec = fit_parameter("albedo", kRhoMin, 1.0, Transform::Linear, 21);
    // At σ = 0 the grid's ρ values tie up to rounding (the start there is the engine's own grid).
    if (std::isfinite(best) && sigma0 > 0.0) {
        sigma_spec.initial = sigma0;
        rho_spec.initial = rho0;
    }
    run_fit(
        p, r,
        fit_problem(
            p, {sigma_spec, rho_spec}, [&p](std::span<const double> theta, std::span<double> out) {
                const OrenNayarTerms::Coefficients c = OrenNayarTerms::coefficients(theta[0]);
                const double rho = theta[1];
                for (std::size_t j = 0; j < p.size(); ++j) {
                    const double A = p.oren_nayar.term_a(j, c), B = p.oren_nayar.term_b(j, c);
                    out[j] = rho * A + rho * rho * B;
                }
            }));
    r.evaluations += evaluations;
}

// ---------------------------------------------------------------------------------------------

void pick_winners(Comparison& c) {
    double best = kInf, best_paper = kInf;
    for (const ModelResult& r : c.models) {
        if (!r.identified()) continue;
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

bool ModelResult::identified() const {
    if (!available) return false;
    if (fit_status != SolverStatus::NotIdentifiable) return true;
    return std::any_of(parameters.begin(), parameters.end(),
                       [](const ModelParameter& q) { return q.identified && q.name != "gain"; });
}

std::optional<double> ModelResult::parameter(std::string_view name) const {
    for (const ModelParameter& p : parameters)
        if (p.name == name) return p.identified ? std::optional<double>(p.value) : std::nullopt;
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
    std::vector<double> w(data.size(), 1.0);
    if (!weights.empty()) w.assign(weights.begin(), weights.end());
    p.w = w;
    const std::vector<Geometry> geom(data.size());  // only its size is used
    p.geom = geom;
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

namespace {

// One ModelResult per model, in kComparisonModels order (indexed by the enum).
std::vector<ModelResult> empty_results() {
    std::vector<ModelResult> models;
    models.reserve(kComparisonModels.size());
    for (ComparisonModel m : kComparisonModels) {
        ModelResult r;
        r.model = m;
        models.push_back(r);
    }
    return models;
}

ModelResult& result_of(Comparison& c, ComparisonModel m) {
    return c.models[static_cast<std::size_t>(m)];
}

// Oren–Nayar with the given parameters, then (with fits) its least-squares fit.
void compare_oren_nayar(Prepared& p, Comparison& c, const ComparisonOptions& o) {
    p.oren_nayar = OrenNayarTerms(p.geom);
    {
        ModelResult& r = result_of(c, ComparisonModel::OrenNayar);
        if (o.oren_nayar) {
            r.available = true;
            r.method = "given parameters (" + o.oren_nayar_source + ")";
            r.parameters = {{"sigma_rad", o.oren_nayar->sigma_rad, std::nullopt, true},
                            {"albedo", o.oren_nayar->albedo, std::nullopt, true}};
            oren_nayar_prediction(p, *o.oren_nayar, r.prediction);
            r.evaluations = 1;
            set_errors(p, r);
            if (!std::isfinite(r.errors.paper_sse)) {  // albedo 0: the model is 0 everywhere
                r.available = false;
                r.reason = "the Oren-Nayar model with albedo = " +
                           check::format_number(o.oren_nayar->albedo) +
                           " is 0 at every measurement: it cannot be normalised to the data";
            }
        } else {
            r.reason =
                "no given Oren-Nayar parameters (the paper's Table 3 lists them for CUReT "
                "samples 25, 34 and 41 only; give sigma_rad and albedo); see "
                "oren_nayar_fit";
        }
    }
    if (o.fits) {
        ModelResult& r = result_of(c, ComparisonModel::OrenNayarFit);
        r.method = "least squares over sigma_rad, albedo and the gain";
        fit_oren_nayar(p, r, o.fit_oren_nayar_sigma_max_rad);
    }
    p.oren_nayar = OrenNayarTerms();
}

// The Table-4 error of every n_d of the Lafortune search grid (n_min + k · n_step, k = 0..steps),
// on fixed bands of the grid (one slot each): the same values whatever the number of threads.
std::vector<double> lafortune_search_errors(const Prepared& p, const ComparisonOptions& o,
                                            long steps) {
    const LafortuneGroups groups = lafortune_groups(p);
    const auto grid_size = static_cast<std::size_t>(steps + 1);
    std::vector<double> error(grid_size);
    constexpr std::size_t kBand = 64;
    run_bands((grid_size + kBand - 1) / kBand, o.threads, [&](std::size_t band) {
        std::vector<double> M;
        for (std::size_t k = band * kBand; k < std::min(grid_size, (band + 1) * kBand); ++k)
            error[k] = lafortune_paper_sse(
                p, groups, o.lafortune_n_min + static_cast<double>(k) * o.lafortune_n_step, M);
    });
    return error;
}

// Lafortune: the paper's exhaustive search for the lowest Table-4 error (the lowest in grid
// order), with a verdict on whether the data determine n_d.
void lafortune_search(const Prepared& p, ModelResult& r, const ComparisonOptions& o) {
    const auto steps = static_cast<long>(
        std::floor((o.lafortune_n_max - o.lafortune_n_min) / o.lafortune_n_step + 1e-9));
    const std::vector<double> error = lafortune_search_errors(p, o, steps);
    double best_err = kInf, worst_err = -kInf, best_n = o.lafortune_n_min;
    long best_k = 0;
    for (std::size_t k = 0; k < error.size(); ++k) {
        const double e = error[k];
        worst_err = std::max(worst_err, e);
        if (e < best_err) {
            best_err = e;
            best_n = o.lafortune_n_min + static_cast<double>(k) * o.lafortune_n_step;
            best_k = static_cast<long>(k);
        }
    }
    // The data do not determine n_d when every n of the search gives the same error (to
    // rounding): one geometry (the normalised model is 1 there whatever n), or several with
    // the same cos θi cos θs.
    const bool flat =
        std::isfinite(worst_err) && worst_err - best_err <= 1e-12 * std::max(1.0, worst_err);
    r.available = true;
    r.method = "exhaustive search of n_d in [" + format_significant(o.lafortune_n_min, 6) + ", " +
               format_significant(o.lafortune_n_max, 6) + "] in steps of " +
               format_significant(o.lafortune_n_step, 6) + " for the lowest Table-4 error (" +
               std::to_string(steps + 1) + " values)";
    r.evaluations = static_cast<int>(steps + 1);
    const bool at_bound = best_k == 0 || best_k == steps;
    r.fit_status = flat       ? SolverStatus::NotIdentifiable
                   : at_bound ? SolverStatus::AtBound
                              : SolverStatus::Converged;
    r.fit_message =
        flat ? "not identifiable: every n_d of the search gives the same Table-4 "
               "error (" +
                   distinct_geometries_text(p.geom) + ")"
        : at_bound ? "n_d = " + format_significant(best_n, 6) + " is an end of the search interval"
                   : "interior minimum of the search";
    r.parameters = {{"n", best_n, std::nullopt, !flat}};
    r.prediction.resize(p.size());
    lafortune_prediction(p, best_n, r.prediction);
    set_errors(p, r);
}

// Lafortune's search, then (with fits) its least-squares fit.
void compare_lafortune(Prepared& p, Comparison& c, const ComparisonOptions& o) {
    prepare_lafortune(p);
    lafortune_search(p, result_of(c, ComparisonModel::Lafortune), o);
    if (o.fits) {
        ModelResult& r = result_of(c, ComparisonModel::LafortuneFit);
        r.method = "least squares over n and the gain";
        fit_lafortune(p, r, o.fit_lafortune_n_min, o.fit_lafortune_n_max);
    }
    release_lafortune(p);
}

// One very-rough model of Table 4: B–K (F_Beck) or V–H (F_VH), Gaussian or exponential.
struct VeryRoughVariant {
    ComparisonModel model, fit;
    GeometricFactor factor;
    Correlation correlation;
};

constexpr VeryRoughVariant kVeryRoughVariants[] = {
    {ComparisonModel::BkGaussian, ComparisonModel::BkGaussianFit, GeometricFactor::Beckmann,
     Correlation::Gaussian},
    {ComparisonModel::BkExponential, ComparisonModel::BkExponentialFit, GeometricFactor::Beckmann,
     Correlation::Exponential},
    {ComparisonModel::VhGaussian, ComparisonModel::VhGaussianFit, GeometricFactor::VernoldHarvey,
     Correlation::Gaussian},
    {ComparisonModel::VhExponential, ComparisonModel::VhExponentialFit,
     GeometricFactor::VernoldHarvey, Correlation::Exponential},
};

// The very-rough model `v` at the two-point estimate of σ/T (unavailable without it).
void very_rough_at_two_point(const Prepared& p, Comparison& c, const ComparisonOptions& o,
                             const VeryRoughVariant& v) {
    ModelResult& r = result_of(c, v.model);
    const CorrelationInfo& ci = info(v.correlation);
    const std::optional<double> sigma_over_T = c.two_point.sigma_over_T(v.correlation);
    if (!sigma_over_T) {
        r.reason = "two-point estimate unavailable: " +
                   (!c.two_point.available ? c.two_point.reason
                                           : c.two_point.correlation_reason(v.correlation));
        return;
    }
    r.available = true;
    r.method = std::string("two-point estimate of sigma/T (") + std::string(ci.inverse_equation) +
               ", F_VH, measurements " + std::to_string(o.measurement1) + " and " +
               std::to_string(o.measurement2) + "); " + std::string(ci.very_rough_equation) +
               " with " + (v.factor == GeometricFactor::Beckmann ? "F_Beck" : "F_VH") + ", " +
               std::string(to_string(o.radiometry));
    r.parameters = {{"sigma_over_T", *sigma_over_T, std::nullopt, true}};
    r.evaluations = 1;
    very_rough_prediction(p, v.factor, v.correlation, *sigma_over_T, r.prediction);
    set_errors(p, r);
}

// B–K (F_Beck) and V–H (F_VH), per factor: its terms, the two-point models, the fits.
void compare_very_rough(Prepared& p, Comparison& c, const ComparisonOptions& o) {
    for (const GeometricFactor factor :
         {GeometricFactor::Beckmann, GeometricFactor::VernoldHarvey}) {
        prepare_very_rough(p, factor);
        for (const VeryRoughVariant& v : kVeryRoughVariants)
            if (v.factor == factor) very_rough_at_two_point(p, c, o, v);
        if (!o.fits) continue;
        for (const VeryRoughVariant& v : kVeryRoughVariants) {
            if (v.factor != factor) continue;
            ModelResult& r = result_of(c, v.fit);
            r.method = std::string("least squares over sigma/T and the gain; ") +
                       std::string(info(v.correlation).very_rough_equation) + " with " +
                       (v.factor == GeometricFactor::Beckmann ? "F_Beck" : "F_VH") + ", " +
                       std::string(to_string(o.radiometry));
            fit_very_rough(p, r, v.factor, v.correlation, o.fit_sigma_over_T_min,
                           o.fit_sigma_over_T_max);
        }
    }
    p.very_rough_terms = VeryRoughTerms();
}

// compare_brdf; `release`, when given, is `table` itself, whose measurements are released as soon
// as the comparison has taken what it needs of them.
Comparison compare(const BrdfTable& table, const ComparisonOptions& o, BrdfTable* release) {
    validate(o);
    if (table.measurements.empty())
        throw InvalidArgument("BRDF table '" + table.name + "' has no measurements");

    Comparison c;
    c.name = table.name;
    c.channel = table.channel;
    c.total_measurements = table.size();
    const std::vector<bool> used = detail::select_measurements(table, o, c.data_issues);
    const double dmax = detail::copy_used_measurements(table, used, c);
    c.two_point = detail::two_point_estimate(table, used, o);
    if (release) std::vector<BrdfMeasurement>().swap(release->measurements);

    c.models = empty_results();
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
    Prepared p = prepare(c.geometry, std::move(d), c.weight, o.radiometry);
    p.keep_predictions = o.keep_predictions;

    // One model family at a time (Prepared): its terms, its paper method, its fit. Each model's
    // result depends on its own computation only, so the order does not change any number.
    compare_oren_nayar(p, c, o);
    compare_lafortune(p, c, o);
    compare_very_rough(p, c, o);
    if (!o.fits)
        for (ModelResult& r : c.models)
            if (is_fit(r.model)) r.reason = "fits not requested";
    pick_winners(c);
    return c;
}

}  // namespace

Comparison compare_brdf(const BrdfTable& table, const ComparisonOptions& o) {
    return compare(table, o, nullptr);
}

Comparison compare_brdf(BrdfTable&& table, const ComparisonOptions& o) {
    return compare(table, o, &table);
}

}  // namespace roughscope
