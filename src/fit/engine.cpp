// The least-squares engine (engine.hpp): Ceres Levenberg–Marquardt with bounds, variable
// projection of a linear gain, grid starts, identifiability test and covariance from an SVD.
#include "roughscope/fit/engine.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <exception>
#include <memory>
#include <numeric>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <ceres/ceres.h>

#include "rank.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/names.hpp"
#include "roughscope/core/numbers.hpp"
#include "solver_log.hpp"

namespace roughscope {

// ---------------------------------------------------------------------------------------------
// Names

namespace {
constexpr std::array<NameEntry<ResidualType>, 3> kResidualNames{{
    {"relative", ResidualType::Relative},
    {"absolute", ResidualType::Absolute},
    {"log", ResidualType::Log},
}};
constexpr std::array<NameEntry<LossType>, 4> kLossNames{{
    {"none", LossType::None},
    {"huber", LossType::Huber},
    {"cauchy", LossType::Cauchy},
    {"soft_l_one", LossType::SoftLOne},
}};
constexpr std::array<NameEntry<SolverStatus>, 5> kSolverStatusNames{{
    {"converged", SolverStatus::Converged},
    {"at_bound", SolverStatus::AtBound},
    {"not_identifiable", SolverStatus::NotIdentifiable},
    {"no_convergence", SolverStatus::NoConvergence},
    {"failed", SolverStatus::Failed},
}};
}  // namespace

std::string_view to_string(ResidualType r) { return name_of(kResidualNames, r); }
std::string_view to_string(LossType l) { return name_of(kLossNames, l); }
std::string_view to_string(SolverStatus s) { return name_of(kSolverStatusNames, s); }

ResidualType parse_residual_type(std::string_view name) {
    return parse_name(kResidualNames, "residual type", name);
}
LossType parse_loss_type(std::string_view name) { return parse_name(kLossNames, "loss", name); }

namespace {

using detail::inverse_normal_matrix;
using detail::SolverLogCapture;
using detail::triangular_factor;
using detail::unidentified;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double residual_of(ResidualType rt, double sw, double KM, double y) {
    switch (rt) {
        case ResidualType::Relative:
            return sw * (KM - y) / y;
        case ResidualType::Absolute:
            return sw * (KM - y);
        case ResidualType::Log:
            return sw * (std::log(KM) - std::log(y));
    }
    return 0.0;
}

std::unique_ptr<ceres::LossFunction> make_loss(LossType loss, double scale) {
    switch (loss) {
        case LossType::None:
            return nullptr;
        case LossType::Huber:
            return std::make_unique<ceres::HuberLoss>(scale);
        case LossType::Cauchy:
            return std::make_unique<ceres::CauchyLoss>(scale);
        case LossType::SoftLOne:
            return std::make_unique<ceres::SoftLOneLoss>(scale);
    }
    return nullptr;
}

// Bounds of the optimised variable u (ln θ for Log, θ for Linear).
double to_u(Transform t, double theta) { return t == Transform::Log ? std::log(theta) : theta; }
double to_theta(Transform t, double u) { return t == Transform::Log ? std::exp(u) : u; }

void validate(const LeastSquaresProblem& P, const LeastSquaresOptions& O) {
    if (P.parameters.empty())
        throw InvalidArgument("parameters: none given; the model needs at least 1");
    if (!P.model) throw InvalidArgument("model: no model function given");
    if (P.data.empty()) throw InvalidArgument("data: empty; at least 1 data point is needed");
    if (!P.weights.empty() && P.weights.size() != P.data.size())
        throw InvalidArgument("weights: " + std::to_string(P.weights.size()) + " given for " +
                              std::to_string(P.data.size()) +
                              " data points; give none (all 1) or one per datum");
    for (std::size_t i = 0; i < P.parameters.size(); ++i) {
        const ParameterSpec& s = P.parameters[i];
        const std::string nm = "parameter '" + s.name + "'";
        if (s.name.empty())
            throw InvalidArgument("parameter " + std::to_string(i + 1) + ": empty name");
        for (std::size_t k = 0; k < i; ++k)
            if (P.parameters[k].name == s.name)
                throw InvalidArgument(nm + " is given twice; names must be unique");
        if (P.gain != GainMode::None && s.name == "gain")
            throw InvalidArgument(nm + ": the name 'gain' is reserved for the fitted gain");
        if (std::isnan(s.lower) || std::isnan(s.upper) || !(s.lower < s.upper))
            throw InvalidArgument(nm + " bounds [" + format_message(s.lower, 6) + ", " +
                                  format_message(s.upper, 6) +
                                  "] are invalid: need lower < upper (±inf allowed)");
        if (s.transform == Transform::Log && !(s.lower >= 0.0))
            throw InvalidArgument(nm + " lower bound = " + format_message(s.lower, 6) +
                                  " is negative, but a log-transformed parameter must lie in "
                                  "[0, inf); use Transform::Linear");
        if (s.initial) {
            check::finite("initial " + s.name, *s.initial);
            if (*s.initial < s.lower || *s.initial > s.upper)
                throw InvalidArgument("initial " + s.name + " = " + format_message(*s.initial, 6) +
                                      " is outside its bounds [" + format_message(s.lower, 6) +
                                      ", " + format_message(s.upper, 6) + "]");
            if (s.transform == Transform::Log && !(*s.initial > 0.0))
                throw InvalidArgument("initial " + s.name + " = " + format_message(*s.initial, 6) +
                                      " must be > 0 (log-transformed parameter)");
        } else {
            const double lo = s.start_lower.value_or(s.lower);
            const double hi = s.start_upper.value_or(s.upper);
            if (!std::isfinite(lo) || !std::isfinite(hi) || !(lo < hi) || lo < s.lower ||
                hi > s.upper || (s.transform == Transform::Log && !(lo > 0.0)))
                throw InvalidArgument(
                    nm + " has no initial value and its start range [" + format_message(lo, 6) +
                    ", " + format_message(hi, 6) +
                    "] cannot be gridded: give an initial value or a finite range " +
                    "inside the bounds [" + format_message(s.lower, 6) + ", " +
                    format_message(s.upper, 6) + "]" +
                    (s.transform == Transform::Log ? " with a positive lower end" : ""));
            if (s.grid_points == 1 || s.grid_points < 0)
                throw InvalidArgument(nm + " grid_points = " + std::to_string(s.grid_points) +
                                      " must be 0 (default) or >= 2");
        }
    }
    double sum_w = 0.0;
    auto at = [](const char* what, std::size_t i) {
        std::string s = what;
        s += '[';
        s += std::to_string(i);
        s += ']';
        return s;
    };
    for (std::size_t i = 0; i < P.data.size(); ++i) {
        const double y = P.data[i];
        if (!std::isfinite(y)) check::finite(at("data", i), y);
        if (P.residual != ResidualType::Absolute && !(y > 0.0))
            throw InvalidArgument(at("data", i) + " = " + format_message(y, 6) +
                                  " must be > 0 for " + std::string(to_string(P.residual)) +
                                  " residuals (valid range (0, inf)); use absolute residuals");
        if (!P.weights.empty()) {
            const double wi = P.weights[i];
            if (!(std::isfinite(wi) && wi >= 0.0))
                throw InvalidArgument(at("weights", i) + " = " + format_message(wi, 6) +
                                      " is outside the valid range [0, inf)");
            sum_w += wi;
        }
    }
    if (!P.weights.empty() && !(sum_w > 0.0))
        throw InvalidArgument("weights: all zero; at least one must be > 0");
    if (O.max_iterations < 1)
        throw InvalidArgument("max_iterations = " + std::to_string(O.max_iterations) +
                              " must be >= 1");
    check::positive("function_tolerance", O.function_tolerance);
    check::positive("gradient_tolerance", O.gradient_tolerance);
    check::positive("parameter_tolerance", O.parameter_tolerance);
    check::positive("loss_scale", O.loss_scale);
    if (O.grid_points < 2)
        throw InvalidArgument("grid_points = " + std::to_string(O.grid_points) + " must be >= 2");
    if (O.num_starts < 1)
        throw InvalidArgument("num_starts = " + std::to_string(O.num_starts) + " must be >= 1");
    if (!(O.rank_tolerance > 0.0 && O.rank_tolerance < 1.0))
        throw InvalidArgument("rank_tolerance = " + format_message(O.rank_tolerance, 6) +
                              " is outside the valid range (0, 1)");
}

// Residual evaluation shared by Ceres' cost function, the grid start and the covariance.
class Evaluator {
  public:
    Evaluator(const LeastSquaresProblem& P, const LeastSquaresOptions& O, GainMode gain)
        : P_(P),
          gain_(gain),
          n_(static_cast<int>(P.parameters.size())),
          loss_(make_loss(O.loss, O.loss_scale)) {
        const std::size_t N = P.data.size();
        // No weights: all 1, nothing stored (N can be 1e6).
        if (!P.weights.empty()) {
            sw_.resize(N);
            w_.resize(N);
            for (std::size_t i = 0; i < N; ++i) {
                w_[i] = P.weights[i];
                sw_[i] = std::sqrt(w_[i]);
            }
        }
        theta_.resize(static_cast<std::size_t>(n_));
        for (const ParameterSpec& s : P.parameters) {
            const bool has_lower = s.transform == Transform::Linear || s.lower > 0.0;
            lower_.push_back(has_lower ? to_u(s.transform, s.lower) : -kInf);
            upper_.push_back(to_u(s.transform, s.upper));
        }
    }
    // Bounds of the optimised variable j (the gain, j = n, is unbounded).
    double lower(int j) const {
        if (j < n_) return lower_[static_cast<std::size_t>(j)];
        return -kInf;
    }
    double upper(int j) const {
        if (j < n_) return upper_[static_cast<std::size_t>(j)];
        return kInf;
    }
    int n() const { return n_; }
    std::size_t size() const { return P_.data.size(); }
    GainMode gain() const { return gain_; }
    const ceres::LossFunction* loss() const { return loss_.get(); }
    // The weights, empty when all are 1; w_i and √w_i.
    const std::vector<double>& weights() const { return w_; }
    double weight(std::size_t i) const { return w_.empty() ? 1.0 : w_[i]; }
    double sqrt_weight(std::size_t i) const { return sw_.empty() ? 1.0 : sw_[i]; }
    int evaluations() const { return evaluations_; }

    // M(θ(u)) into M (size()); false when the model fails or gives a non-finite value.
    bool model(const double* u, std::span<double> M) const {
        for (int j = 0; j < n_; ++j)
            theta_[static_cast<std::size_t>(j)] =
                to_theta(P_.parameters[static_cast<std::size_t>(j)].transform, u[j]);
        ++evaluations_;
        try {
            if (!P_.model(std::span<const double>(theta_), M)) return false;
        } catch (const std::exception&) {
            return false;  // an exception must not cross Ceres: the point is unusable
        }
        for (double m : M)
            if (!std::isfinite(m)) return false;
        return true;
    }
    bool model(const double* u, std::vector<double>& M) const {
        M.resize(size());
        return model(u, std::span<double>(M));
    }

    // Residuals r_i = √w_i residual(K M_i, y_i) at x = [u..., (K if `mode` is Free)], the gain
    // profiled out (mode Profiled), explicit (Free) or 1 (None); robust: r̃ = sign(r) √ρ(r²), so
    // that Σ r̃² = Σ ρ(r²) is the robust cost. K through `gain` when given.
    // The model values are computed into r itself and replaced by the residuals (no N-sized
    // buffer of model values beside r).
    bool residuals(const double* x, GainMode mode, bool robust, double* r,
                   double* gain = nullptr) const {
        const std::span<const double> M(r, size());
        if (!model(x, std::span<double>(r, size()))) return false;
        double K = 1.0;
        if (mode == GainMode::Profiled)
            K = optimal_gain(M, P_.data, w_, P_.residual);
        else if (mode == GainMode::Free)
            K = x[n_];
        if (!std::isfinite(K)) return false;
        for (std::size_t i = 0; i < size(); ++i) {
            const double KM = K * M[i];  // read before r[i] (the same element) is written
            if (P_.residual == ResidualType::Log && !(KM > 0.0)) {
                if (weight(i) == 0.0) {
                    r[i] = 0.0;
                    continue;
                }
                return false;
            }
            double ri = residual_of(P_.residual, sqrt_weight(i), KM, P_.data[i]);
            if (robust && loss_) {
                double rho[3];
                loss_->Evaluate(ri * ri, rho);
                ri = std::copysign(std::sqrt(std::max(rho[0], 0.0)), ri);
            }
            if (!std::isfinite(ri)) return false;
            r[i] = ri;
        }
        if (gain) *gain = K;
        return true;
    }

  private:
    const LeastSquaresProblem& P_;
    GainMode gain_;
    int n_;
    std::unique_ptr<ceres::LossFunction> loss_;
    std::vector<double> sw_, w_, lower_, upper_;
    mutable std::vector<double> theta_;
    mutable int evaluations_ = 0;
};

// Central difference of the vector function f in coordinate j of x, the step (1e-6 max(1, |x_j|))
// kept inside [lo, hi]: one-sided at a bound, or when one side cannot be evaluated. f0 = f(x).
template <class F>
bool bounded_difference(F&& f, std::vector<double>& x, std::size_t j, double lo, double hi,
                        const std::vector<double>& f0, std::vector<double>& d) {
    const double xj = x[j];
    const double h = 1e-6 * std::max(1.0, std::abs(xj));
    double a = std::max(lo, xj - h), b = std::min(hi, xj + h);
    // f(b) is evaluated into d itself (one residual vector less at a time: N can be 1e6).
    std::vector<double> fa;
    x[j] = b;
    const bool okb = b > xj && f(x.data(), d);
    x[j] = a;
    const bool oka = a < xj && f(x.data(), fa);
    x[j] = xj;
    if (!okb) b = xj;
    if (!oka) a = xj;
    if (!(b > a)) return false;
    if (!okb) d = f0;
    const std::vector<double>& dn = oka ? fa : f0;
    for (std::size_t i = 0; i < f0.size(); ++i) d[i] = (d[i] - dn[i]) / (b - a);
    return true;
}

// Ceres' cost: the N (robustified, gain-projected) residuals as one block over [u..., (gain)],
// Jacobian by bounded central differences, so that the model is never evaluated outside the
// bounds (e.g. σ_ON < 0).
class EngineCost final : public ceres::CostFunction {
  public:
    EngineCost(const Evaluator& e, int size) : e_(e) {
        set_num_residuals(static_cast<int>(e.size()));
        mutable_parameter_block_sizes()->push_back(size);
    }
    bool Evaluate(double const* const* x, double* r, double** J) const override {
        const int size = parameter_block_sizes()[0];
        const std::size_t N = e_.size();
        // Ceres evaluates a candidate point without, then (once accepted) with the Jacobian: the
        // residuals of the last point are reused.
        if (last_x_.size() == static_cast<std::size_t>(size) &&
            std::equal(last_x_.begin(), last_x_.end(), x[0])) {
            std::copy(last_r_.begin(), last_r_.end(), r);
        } else {
            if (!e_.residuals(x[0], e_.gain(), true, r)) return false;
            last_x_.assign(x[0], x[0] + size);
            last_r_.assign(r, r + N);
        }
        if (J == nullptr || J[0] == nullptr) return true;
        std::vector<double> xv(x[0], x[0] + size);
        if (size <= 2) {
            // last_r_ (the residuals at x, as r) is the scratch column, then restored from r.
            const bool ok = jacobian_in_place(xv, r, J[0], last_r_);
            last_r_.assign(r, r + N);
            return ok;
        }
        // last_r_ holds the residuals r at x (no copy of N values).
        const std::vector<double>& r0 = last_r_;
        std::vector<double> d;
        auto f = [this, N](const double* xx, std::vector<double>& out) {
            out.resize(N);
            return e_.residuals(xx, e_.gain(), true, out.data());
        };
        for (int j = 0; j < size; ++j) {
            if (!bounded_difference(f, xv, static_cast<std::size_t>(j), e_.lower(j), e_.upper(j),
                                    r0, d))
                return false;
            for (std::size_t i = 0; i < N; ++i)
                J[0][i * static_cast<std::size_t>(size) + static_cast<std::size_t>(j)] = d[i];
        }
        return true;
    }

  private:
    // The Jacobian (row-major N × size, size 1 or 2) by the differences of bounded_difference,
    // with Ceres' own Jacobian block as the scratch space of the perturbed residuals and
    // `column0` (N values) beside it (N can be 1e6). r0: the residuals at x.
    bool jacobian_in_place(std::vector<double>& x, const double* r0, double* J,
                           std::vector<double>& column0) const {
        const std::size_t N = e_.size();
        const auto size = x.size();
        column0.resize(N);
        auto f = [this](const double* xx, double* out) {
            return e_.residuals(xx, e_.gain(), true, out);
        };
        // Column j: f(b) into fb, f(a) into fa, the difference into fb.
        auto column = [&](std::size_t j, double* fb, double* fa) {
            const double xj = x[j];
            const double h = 1e-6 * std::max(1.0, std::abs(xj));
            const auto jj = static_cast<int>(j);
            double a = std::max(e_.lower(jj), xj - h), b = std::min(e_.upper(jj), xj + h);
            x[j] = b;
            const bool okb = b > xj && f(x.data(), fb);
            x[j] = a;
            const bool oka = a < xj && f(x.data(), fa);
            x[j] = xj;
            if (!okb) b = xj;
            if (!oka) a = xj;
            if (!(b > a)) return false;
            const double* up = okb ? fb : r0;
            const double* dn = oka ? fa : r0;
            for (std::size_t i = 0; i < N; ++i) fb[i] = (up[i] - dn[i]) / (b - a);
            return true;
        };
        if (size == 1) return column(0, J, column0.data());
        // Two columns: the first into column0 (f(a) in J's second half), the second into J's
        // second half (f(b) in its first half), then interleaved into rows: row i's second
        // value is read before rows ≤ i are written, and rows < i never overwrite it.
        if (!column(0, column0.data(), J + N) || !column(1, J + N, J)) return false;
        for (std::size_t i = 0; i < N; ++i) {
            const double second = J[N + i];
            J[2 * i] = column0[i];
            J[2 * i + 1] = second;
        }
        return true;
    }

    const Evaluator& e_;
    mutable std::vector<double> last_x_, last_r_;
};

// Ceres solve from start x (size n, or n + 1 with a free gain).
struct Run {
    std::vector<double> x;
    ceres::Solver::Summary summary;  // of the last solve (initial_cost: of the first)
    int iterations = 0;              // over every solve
};

// From this many residuals on, the trust-region steps use the normal equations (solve_from).
constexpr std::size_t kNormalEquationsResiduals = 100000;

// Whether the optimised variable j sits on one of its bounds.
bool on_bound(const Evaluator& e, int j, double u) {
    const double tol = 1e-9 * std::max(1.0, std::abs(u));
    return std::abs(u - e.lower(j)) <= tol || std::abs(u - e.upper(j)) <= tol;
}

// Ceres from start x. When parameters end on a bound, the projected Levenberg–Marquardt step can
// stall the others (the step that leaves the box is cut back); an active-set polish then solves
// again with the parameters that the gradient holds on their bounds fixed there, then once more
// with everything free, until that set is stable.
Run solve_from(const Evaluator& e, const LeastSquaresOptions& O, std::vector<double> x) {
    Run run;
    run.x = std::move(x);
    const int size = static_cast<int>(run.x.size());
    ceres::Problem problem;  // takes ownership of the cost function
    problem.AddResidualBlock(new EngineCost(e, size), nullptr, run.x.data());
    for (int j = 0; j < e.n(); ++j) {
        if (std::isfinite(e.lower(j))) problem.SetParameterLowerBound(run.x.data(), j, e.lower(j));
        if (std::isfinite(e.upper(j))) problem.SetParameterUpperBound(run.x.data(), j, e.upper(j));
    }
    ceres::Solver::Options so;
    // Dense QR of the N × p Jacobian for the step, except for very long data: there Ceres's QR
    // keeps two more N × p copies and the Householder workspaces (~40 bytes per residual), so the
    // step comes from the p × p normal equations instead (p ≤ a few, well conditioned after the
    // parameter scaling). The rank test and the covariance always use our own QR (below).
    so.linear_solver_type =
        e.size() >= kNormalEquationsResiduals ? ceres::DENSE_NORMAL_CHOLESKY : ceres::DENSE_QR;
    so.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
    so.max_num_iterations = O.max_iterations;
    so.function_tolerance = O.function_tolerance;
    so.gradient_tolerance = O.gradient_tolerance;
    so.parameter_tolerance = O.parameter_tolerance;
    so.logging_type = ceres::SILENT;
    so.minimizer_progress_to_stdout = false;
    so.num_threads = 1;
    ceres::Solve(so, &problem, &run.summary);
    const double initial_cost = run.summary.initial_cost;
    int iterations = std::max(0, static_cast<int>(run.summary.iterations.size()) - 1);
    auto count = [&](const ceres::Solver::Summary& sm) {
        iterations += std::max(0, static_cast<int>(sm.iterations.size()) - 1);
    };
    // Held: on a bound with the gradient of the cost pointing out of the box (a KKT multiplier
    // of the right sign). False when the cost cannot be evaluated.
    auto held_set = [&](std::vector<int>& held) {
        double cost = 0.0;
        std::vector<double> gradient;
        if (!problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, &gradient,
                              nullptr))
            return false;
        held.clear();
        for (int j = 0; j < e.n(); ++j) {
            const double u = run.x[static_cast<std::size_t>(j)];
            const double g = gradient[static_cast<std::size_t>(j)];
            if (!on_bound(e, j, u)) continue;
            const bool at_lower = std::abs(u - e.lower(j)) <= 1e-9 * std::max(1.0, std::abs(u));
            if (at_lower ? g > 0.0 : g < 0.0) held.push_back(j);
        }
        return true;
    };
    std::vector<int> held, held_before;
    for (int pass = 0; pass < 4; ++pass) {
        const bool usable = run.summary.termination_type == ceres::CONVERGENCE ||
                            run.summary.termination_type == ceres::NO_CONVERGENCE;
        if (!usable || !held_set(held) || held.empty() || static_cast<int>(held.size()) == size ||
            held == held_before)
            break;
        held_before = held;
        ceres::Solver::Summary polished;
        problem.SetManifold(run.x.data(), new ceres::SubsetManifold(size, held));
        ceres::Solve(so, &problem, &polished);
        count(polished);
        problem.SetManifold(run.x.data(), nullptr);
        // The same parameters still held (KKT holds at the polished point): done, without a
        // free solve that would only crawl against the bounds again.
        std::vector<int> held_after;
        if (held_set(held_after) && held_after == held) {
            run.summary = polished;
            break;
        }
        ceres::Solve(so, &problem, &run.summary);
        count(run.summary);
    }
    run.summary.initial_cost = initial_cost;
    run.iterations = iterations;
    return run;
}

// The grid-start points: the `count` best of the tensor grid over the parameters without an
// initial value (others at their initial value), in u coordinates, by profiled SSE.
std::vector<std::vector<double>> grid_starts(const Evaluator& e, const LeastSquaresProblem& P,
                                             const LeastSquaresOptions& O, int count) {
    const int n = e.n();
    std::vector<double> base(static_cast<std::size_t>(n));
    std::vector<int> free;
    std::vector<std::vector<double>> axes;
    for (int j = 0; j < n; ++j) {
        const ParameterSpec& s = P.parameters[static_cast<std::size_t>(j)];
        if (s.initial) {
            base[static_cast<std::size_t>(j)] = to_u(s.transform, *s.initial);
            continue;
        }
        const double lo = to_u(s.transform, s.start_lower.value_or(s.lower));
        const double hi = to_u(s.transform, s.start_upper.value_or(s.upper));
        const int g = s.grid_points > 0 ? s.grid_points : O.grid_points;
        std::vector<double> axis(static_cast<std::size_t>(g));
        for (int k = 0; k < g; ++k)
            axis[static_cast<std::size_t>(k)] = lo + (hi - lo) * k / (g - 1);
        free.push_back(j);
        axes.push_back(std::move(axis));
    }
    if (free.empty()) return {base};
    double total = 1.0;
    for (const auto& a : axes) total *= static_cast<double>(a.size());
    if (total > 1e6)
        throw InvalidArgument("grid start: " + format_message(total, 6) +
                              " points (more than 1e6); give initial values or fewer points");
    std::vector<std::pair<double, std::vector<double>>> scored;
    std::vector<std::size_t> idx(free.size(), 0);
    std::vector<double> r(e.size());
    for (;;) {
        std::vector<double> u = base;
        for (std::size_t a = 0; a < free.size(); ++a)
            u[static_cast<std::size_t>(free[a])] = axes[a][idx[a]];
        double sse = kInf;
        if (e.residuals(u.data(), e.gain() == GainMode::None ? GainMode::None : GainMode::Profiled,
                        false, r.data())) {
            sse = 0.0;
            for (double v : r) sse += v * v;
            if (!std::isfinite(sse)) sse = kInf;
        }
        scored.emplace_back(sse, std::move(u));
        std::size_t a = 0;
        while (a < free.size() && ++idx[a] == axes[a].size()) idx[a++] = 0;
        if (a == free.size()) break;
    }
    std::stable_sort(scored.begin(), scored.end(),
                     [](const auto& l, const auto& rr) { return l.first < rr.first; });
    std::vector<std::vector<double>> out;
    for (const auto& [sse, u] : scored) {
        if (static_cast<int>(out.size()) >= count) break;
        if (std::isfinite(sse) || out.empty()) out.push_back(u);
    }
    return out;
}

// Jacobian of the unprojected residuals r_i = √w_i residual(K M_i(θ(u)), y_i) over [u..., K] at
// the solution: dM/du by bounded central differences, the chain rule through the residual, the
// gain column analytic; rows scaled by √ρ'(r²) for a robust loss. False when it cannot be computed.
bool jacobian(const Evaluator& e, const LeastSquaresProblem& P, std::vector<double> u, double K,
              const std::vector<double>& M, const std::vector<double>& r, Eigen::MatrixXd& J) {
    const int n = e.n();
    const bool has_gain = e.gain() != GainMode::None;
    const auto N = static_cast<Eigen::Index>(e.size());
    J.setZero(N, n + (has_gain ? 1 : 0));
    // d r_i / d(K M_i).
    std::vector<double> drdKM(e.size(), 0.0);
    for (std::size_t i = 0; i < e.size(); ++i) {
        if (e.weight(i) == 0.0) continue;
        const double sw = e.sqrt_weight(i);
        drdKM[i] = P.residual == ResidualType::Absolute   ? sw
                   : P.residual == ResidualType::Relative ? sw / P.data[i]
                                                          : sw / (K * M[i]);
    }
    auto f = [&e](const double* uu, std::vector<double>& out) { return e.model(uu, out); };
    std::vector<double> dM;
    for (int j = 0; j < n; ++j) {
        if (!bounded_difference(f, u, static_cast<std::size_t>(j), e.lower(j), e.upper(j), M, dM))
            return false;
        for (Eigen::Index i = 0; i < N; ++i)
            J(i, j) = drdKM[static_cast<std::size_t>(i)] * K * dM[static_cast<std::size_t>(i)];
    }
    if (has_gain)
        for (Eigen::Index i = 0; i < N; ++i)
            J(i, n) = drdKM[static_cast<std::size_t>(i)] * M[static_cast<std::size_t>(i)];
    if (const ceres::LossFunction* loss = e.loss())
        for (Eigen::Index i = 0; i < N; ++i) {
            double rho[3];
            const double ri = r[static_cast<std::size_t>(i)];
            loss->Evaluate(ri * ri, rho);
            J.row(i) *= std::sqrt(std::max(rho[1], 0.0));
        }
    return J.allFinite();
}

std::string join_names(const std::vector<FitParameter>& ps, const std::vector<int>& idx) {
    std::string s;
    for (int j : idx) s += (s.empty() ? "" : ", ") + ps[static_cast<std::size_t>(j)].name;
    return s;
}

}  // namespace

// ---------------------------------------------------------------------------------------------

double optimal_gain(std::span<const double> model, std::span<const double> data,
                    std::span<const double> weights, ResidualType residual) {
    double num = 0.0, den = 0.0;
    for (std::size_t i = 0; i < model.size(); ++i) {
        const double w = weights.empty() ? 1.0 : weights[i];
        if (w == 0.0) continue;
        const double M = model[i], y = data[i];
        switch (residual) {
            case ResidualType::Relative:
                num += w * M / y;
                den += w * M * M / (y * y);
                break;
            case ResidualType::Absolute:
                num += w * M * y;
                den += w * M * M;
                break;
            case ResidualType::Log:
                if (!(M > 0.0 && y > 0.0)) return kNaN;
                num += w * (std::log(y) - std::log(M));
                den += w;
                break;
        }
    }
    if (!(den > 0.0) || !std::isfinite(den)) return kNaN;
    return residual == ResidualType::Log ? std::exp(num / den) : num / den;
}

double profiled_sse(const LeastSquaresProblem& problem, std::span<const double> theta,
                    double* gain) {
    validate(problem, LeastSquaresOptions{});
    if (theta.size() != problem.parameters.size())
        throw InvalidArgument("theta: " + std::to_string(theta.size()) + " values for " +
                              std::to_string(problem.parameters.size()) + " parameters");
    const GainMode mode = problem.gain == GainMode::None ? GainMode::None : GainMode::Profiled;
    const Evaluator e(problem, LeastSquaresOptions{}, mode);
    std::vector<double> u(theta.size()), r(problem.data.size());
    for (std::size_t j = 0; j < theta.size(); ++j)
        u[j] = to_u(problem.parameters[j].transform, theta[j]);
    if (!e.residuals(u.data(), mode, false, r.data(), gain)) return kInf;
    double sse = 0.0;
    for (double v : r) sse += v * v;
    if (!std::isfinite(sse)) return kInf;
    return sse;
}

const FitParameter& find_parameter(const std::vector<FitParameter>& parameters,
                                   std::string_view name) {
    for (const auto& p : parameters)
        if (p.name == name) return p;
    std::string names;
    for (const auto& p : parameters) names += (names.empty() ? "" : ", ") + p.name;
    throw InvalidArgument("fit parameter '" + std::string(name) +
                          "' does not exist; have: " + names);
}

const FitParameter& LeastSquaresResult::parameter(std::string_view name) const {
    return find_parameter(parameters, name);
}

std::string brief_report_tail(const std::vector<FitParameter>& parameters,
                              bool covariance_available, double sse, double aic,
                              const std::string& message) {
    std::string s;
    for (const auto& p : parameters) {
        if (!p.identified) {
            s += " " + p.name + " not identifiable" + (p.at_bound ? " (at bound);" : ";");
            continue;
        }
        s += " " + p.name + " = " + format_message(p.value, 6);
        if (covariance_available && !p.at_bound) s += " +/- " + format_message(p.std_error, 3);
        if (p.at_bound) s += " (at bound)";
        s += ";";
    }
    return s + " SSE = " + format_message(sse, 6) + ", AIC = " + format_message(aic, 6) + ". " +
           message;
}

std::string LeastSquaresResult::brief_report() const {
    std::string s = "roughscope least squares: " + std::string(to_string(status)) + " after " +
                    std::to_string(iterations) + " iterations (" + std::to_string(evaluations) +
                    " model evaluations); N = " + std::to_string(num_data) +
                    ", p = " + std::to_string(num_parameters) + ";";
    return s + brief_report_tail(parameters, covariance_available, sse, aic, message);
}

namespace {

// One Ceres run per start (with a free gain, the profiled one as its start); the run with the
// lowest final cost among the usable ones (not failed) wins. `iterations` adds up every run's.
Run best_run(const Evaluator& e, const LeastSquaresProblem& P, const LeastSquaresOptions& O,
             GainMode mode, int& iterations) {
    const std::vector<std::vector<double>> starts = grid_starts(e, P, O, O.num_starts);
    bool have_run = false;
    Run best;
    for (std::vector<double> x : starts) {
        if (mode == GainMode::Free) {
            double K = 1.0;
            std::vector<double> r_start(e.size());
            if (!e.residuals(x.data(), GainMode::Profiled, false, r_start.data(), &K)) K = 1.0;
            x.push_back(K);
        }
        Run run = solve_from(e, O, std::move(x));
        iterations += run.iterations;
        const bool usable = run.summary.termination_type != ceres::FAILURE &&
                            run.summary.termination_type != ceres::USER_FAILURE;
        const bool best_usable = have_run && best.summary.termination_type != ceres::FAILURE &&
                                 best.summary.termination_type != ceres::USER_FAILURE;
        if (!have_run ||
            (usable && (!best_usable || run.summary.final_cost < best.summary.final_cost))) {
            best = std::move(run);
            have_run = true;
        }
    }
    return best;
}

SolverStatus status_of(ceres::TerminationType termination) {
    switch (termination) {
        case ceres::CONVERGENCE:
            return SolverStatus::Converged;
        case ceres::NO_CONVERGENCE:
            return SolverStatus::NoConvergence;
        default:
            return SolverStatus::Failed;
    }
}

// The solution x: the model M, the gain K and the unrobustified residuals r (resized to N);
// false when the model or the residuals cannot be evaluated there.
bool evaluate_solution(const Evaluator& e, const LeastSquaresProblem& P, GainMode mode,
                       const std::vector<double>& x, std::vector<double>& M, double& K,
                       std::vector<double>& r) {
    const int n = e.n();
    const bool has_gain = P.gain != GainMode::None;
    r.resize(e.size());
    K = 1.0;
    bool finite = e.model(x.data(), M);
    if (finite) {
        if (mode == GainMode::Profiled)
            K = optimal_gain(M, P.data, e.weights(), P.residual);
        else if (mode == GainMode::Free)
            K = x[static_cast<std::size_t>(n)];
        std::vector<double> xk(x.begin(), x.begin() + n);
        if (has_gain) xk.push_back(K);
        finite =
            std::isfinite(K) &&
            e.residuals(xk.data(), has_gain ? GainMode::Free : GainMode::None, false, r.data());
    }
    return finite;
}

// The Jacobian at the solution and what the rank test and the covariance need of it.
struct SolutionJacobian {
    bool available = false;
    Eigen::MatrixXd R;       // triangular factor of J (RᵀR = JᵀJ)
    Eigen::MatrixXd R_rank;  // R with the gain's column as ∂r/∂ln K
    std::vector<int> free_cols;
};

// Whether parameter j, on a bound, is held there: the gradient of the cost pushes it out of the
// box (|cos(J_j, r)| > 1e-4 with the outward sign).
bool held_on_bound(const Evaluator& e, const Eigen::MatrixXd& J, const Eigen::VectorXd& rv, int j,
                   double uj) {
    const double g = J.col(j).dot(rv);
    const double scale = J.col(j).norm() * rv.norm();
    const bool at_lower = std::abs(uj - e.lower(j)) <= 1e-9 * std::max(1.0, std::abs(uj));
    return scale > 0.0 && (at_lower ? g : -g) > 1e-4 * scale;
}

// Identifiability. A parameter on a bound is "held" there (held_on_bound) when fixed by the bound
// and left out of the rank test. One on a bound with no such pull (a flat direction that drifted
// to the bound) is tested like a free one. Returns the indices of the parameters the data do not
// determine, noting why in res.message.
std::vector<int> identifiability(const Evaluator& e, const LeastSquaresProblem& P,
                                 const LeastSquaresOptions& O, const std::vector<double>& x,
                                 double K, const std::vector<double>& M,
                                 const std::vector<double>& r, LeastSquaresResult& res,
                                 SolutionJacobian& jac) {
    const int n = e.n();
    const int N = res.num_data, p = res.num_parameters;
    const bool has_gain = P.gain != GainMode::None;
    std::vector<int> bad;
    if (N < p) {
        bad.resize(static_cast<std::size_t>(p));
        std::iota(bad.begin(), bad.end(), 0);
        res.message += "; " + std::to_string(N) + " data points (with weight > 0) for " +
                       std::to_string(p) + " parameters: at least " + std::to_string(p) +
                       " are needed";
        return bad;
    }
    Eigen::MatrixXd J;
    jac.available = jacobian(e, P, std::vector<double>(x.begin(), x.begin() + n), K, M, r, J);
    if (jac.available) {
        const Eigen::Map<const Eigen::VectorXd> rv(r.data(), static_cast<Eigen::Index>(r.size()));
        for (int j = 0; j < p; ++j)
            if (!res.parameters[static_cast<std::size_t>(j)].at_bound ||
                !held_on_bound(e, J, rv, j, x[static_cast<std::size_t>(j)]))
                jac.free_cols.push_back(j);
        // Everything below depends on J only through JᵀJ: J = QR (thin, Householder, in
        // place) gives the p×p factor R with RᵀR = JᵀJ, the same column norms and singular
        // values, so that no further copy of the N×p Jacobian is needed (N can be 1e6).
        jac.R = triangular_factor(J);
        // The rank test compares relative effects: the gain's column as ∂r/∂ln K = K ∂r/∂K,
        // like a Log parameter's (∂r/∂ln θ); in natural units a large K would make its column
        // look like one "without effect" and hide the parameter it trades off with.
        jac.R_rank = jac.R;
        if (has_gain) jac.R_rank.col(n) *= std::abs(K);
        bad = unidentified(jac.R_rank, jac.free_cols, O.rank_tolerance);
    }
    if (!bad.empty())
        res.message += "; the Jacobian is rank deficient: the data do not determine " +
                       join_names(res.parameters, bad) +
                       " (a parameter without effect, repeated geometries or constant "
                       "data, or parameters that trade off exactly)";
    return bad;
}

// The covariance of the parameters in natural units (scaled by the residual variance when
// O.scale_covariance) and their standard errors, or a note in res.message on why not.
void set_covariance(const LeastSquaresProblem& P, const LeastSquaresOptions& O,
                    const SolutionJacobian& jac, bool identified, LeastSquaresResult& res) {
    const int n = static_cast<int>(P.parameters.size());
    const int N = res.num_data, p = res.num_parameters;
    res.covariance = Eigen::MatrixXd::Zero(p, p);
    if (jac.available && identified) {
        std::vector<int> all(static_cast<std::size_t>(p));
        std::iota(all.begin(), all.end(), 0);
        Eigen::MatrixXd C;
        const bool full = unidentified(jac.R_rank, all, O.rank_tolerance).empty() &&
                          inverse_normal_matrix(jac.R, all, C);
        const bool ok = full || inverse_normal_matrix(jac.R, jac.free_cols, C);
        if (ok && (N > p || !O.scale_covariance)) {
            const double scale = O.scale_covariance ? res.sse / (N - p) : 1.0;
            std::vector<double> d(static_cast<std::size_t>(p), 1.0);  // dθ/du
            for (int j = 0; j < n; ++j)
                if (P.parameters[static_cast<std::size_t>(j)].transform == Transform::Log)
                    d[static_cast<std::size_t>(j)] =
                        res.parameters[static_cast<std::size_t>(j)].value;
            for (int a = 0; a < p; ++a)
                for (int b = 0; b < p; ++b)
                    res.covariance(a, b) = scale * C(a, b) * d[static_cast<std::size_t>(a)] *
                                           d[static_cast<std::size_t>(b)];
            res.covariance_available = res.covariance.allFinite();
        }
        if (!res.covariance_available)
            res.message += N > p ? "; covariance unavailable (singular Jacobian)"
                                 : "; covariance unavailable (N = p: no degrees of freedom)";
    } else if (!jac.available && N >= p) {
        res.message += "; covariance unavailable (the Jacobian cannot be evaluated)";
    }
    if (res.covariance_available)
        for (int j = 0; j < p; ++j)
            res.parameters[static_cast<std::size_t>(j)].std_error =
                std::sqrt(std::max(0.0, res.covariance(j, j)));
}

// Notes the parameters (not the gain) that end on a bound; a converged fit becomes AtBound.
void note_bounds(int n, LeastSquaresResult& res) {
    std::string list;
    for (int j = 0; j < n; ++j) {
        const FitParameter& fp = res.parameters[static_cast<std::size_t>(j)];
        if (!fp.at_bound) continue;
        list += (list.empty() ? "" : ", ") + fp.name + " = " + format_message(fp.value, 6) +
                " in [" + format_message(fp.lower, 6) + ", " + format_message(fp.upper, 6) + "]";
    }
    if (list.empty()) return;
    res.message += "; on a bound: " + list;
    if (res.status == SolverStatus::Converged) res.status = SolverStatus::AtBound;
}

}  // namespace

LeastSquaresResult solve_least_squares(const LeastSquaresProblem& P, const LeastSquaresOptions& O) {
    validate(P, O);
    const GainMode mode =
        P.gain == GainMode::Profiled && O.loss != LossType::None ? GainMode::Free : P.gain;
    const Evaluator e(P, O, mode);
    const int n = e.n();
    const bool has_gain = P.gain != GainMode::None;
    const int p = n + (has_gain ? 1 : 0);
    const std::vector<double>& w = e.weights();  // empty: all 1
    const int N =
        w.empty()
            ? static_cast<int>(e.size())
            : static_cast<int>(std::count_if(w.begin(), w.end(), [](double v) { return v > 0; }));

    LeastSquaresResult res;
    res.num_data = N;
    res.num_parameters = p;
    for (const ParameterSpec& s : P.parameters)
        res.parameters.push_back({s.name, kNaN, 0.0, s.lower, s.upper, false, true});
    if (has_gain) res.parameters.push_back({"gain", kNaN, 0.0, -kInf, kInf, false, true});

    // Starts, then one Ceres run per start; the lowest final cost wins.
    SolverLogCapture solver_log;
    const Run best = best_run(e, P, O, mode, res.iterations);
    res.initial_cost = best.summary.initial_cost;
    res.final_cost = best.summary.final_cost;
    res.message = best.summary.message + solver_log.summary();
    res.status = status_of(best.summary.termination_type);

    // The solution: model, gain, residuals (unrobustified). The residuals are allocated after the
    // solves (N can be 1e6: not beside Ceres' working set).
    const std::vector<double>& x = best.x;
    std::vector<double> M, r;
    double K = 1.0;
    const bool finite = evaluate_solution(e, P, mode, x, M, K, r);
    res.evaluations = e.evaluations();
    for (int j = 0; j < n; ++j) {
        const ParameterSpec& s = P.parameters[static_cast<std::size_t>(j)];
        FitParameter& fp = res.parameters[static_cast<std::size_t>(j)];
        const double u = x[static_cast<std::size_t>(j)];
        fp.value = to_theta(s.transform, u);
        fp.at_bound = on_bound(e, j, u);
    }
    if (has_gain) res.parameters.back().value = K;
    res.gain = K;
    if (!finite) {
        res.status = SolverStatus::Failed;
        res.message += "; the model cannot be evaluated at the solution";
        res.evaluations = e.evaluations();
        return res;
    }
    double sse = 0.0;
    for (double v : r) sse += v * v;
    res.sse = sse;
    const double sse_floor = std::max(sse / N, std::numeric_limits<double>::min());
    res.aic = N * std::log(sse_floor) + 2.0 * p;
    res.aicc = N - p - 1 > 0 ? res.aic + 2.0 * p * (p + 1) / double(N - p - 1) : kInf;

    SolutionJacobian jac;
    const std::vector<int> bad = identifiability(e, P, O, x, K, M, r, res, jac);
    for (int j : bad) {
        res.not_identifiable.push_back(res.parameters[static_cast<std::size_t>(j)].name);
        res.parameters[static_cast<std::size_t>(j)].identified = false;
    }
    if (!bad.empty() && res.status != SolverStatus::Failed)
        res.status = SolverStatus::NotIdentifiable;
    res.evaluations = e.evaluations();
    set_covariance(P, O, jac, bad.empty(), res);
    note_bounds(n, res);
    // The N-sized outputs last: the Jacobian and its factor are gone by now (N can be 1e6).
    res.predicted.resize(M.size());
    for (std::size_t i = 0; i < M.size(); ++i) res.predicted[i] = K * M[i];
    res.model = std::move(M);
    res.residuals = std::move(r);
    return res;
}

}  // namespace roughscope
