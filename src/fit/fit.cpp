// Least-squares roughness fits with Ceres (paper §4, "least-square fitting techniques").
#include "roughscope/fit/fit.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>

#include <Eigen/Dense>
#include <ceres/ceres.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/names.hpp"
#include "roughscope/scattering/validity.hpp"

namespace roughscope {

// ---------------------------------------------------------------------------------------------
// Names

namespace {
constexpr std::array<NameEntry<FitModel>, 2> kFitModelNames{{
    {"very_rough", FitModel::VeryRough},
    {"slightly_rough", FitModel::SlightlyRough},
}};
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
constexpr std::array<NameEntry<SolverStatus>, 3> kSolverStatusNames{{
    {"converged", SolverStatus::Converged},
    {"no_convergence", SolverStatus::NoConvergence},
    {"failed", SolverStatus::Failed},
}};
}  // namespace

std::string_view to_string(FitModel m) { return name_of(kFitModelNames, m); }
std::string_view to_string(ResidualType r) { return name_of(kResidualNames, r); }
std::string_view to_string(LossType l) { return name_of(kLossNames, l); }
std::string_view to_string(SolverStatus s) { return name_of(kSolverStatusNames, s); }

FitModel parse_fit_model(std::string_view name) {
    return parse_name(kFitModelNames, "fit model", name);
}
ResidualType parse_residual_type(std::string_view name) {
    return parse_name(kResidualNames, "residual type", name);
}
LossType parse_loss_type(std::string_view name) { return parse_name(kLossNames, "loss", name); }

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

std::string fmt(double x, int digits = 6) {
    if (std::isnan(x)) return "nan";
    if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*g", digits, x);
    return buf;
}

int model_parameter_count(const FitOptions& o) { return o.model == FitModel::VeryRough ? 1 : 2; }

void check_bounds(std::string_view name, double lo, double hi) {
    check::positive(std::string(name) + " lower bound", lo);
    check::positive(std::string(name) + " upper bound", hi);
    if (!(lo < hi))
        throw InvalidArgument(std::string(name) + " bounds [" + fmt(lo) + ", " + fmt(hi) +
                              "] are empty: the lower bound must be below the upper bound");
}

void check_initial(std::string_view name, const std::optional<double>& v, double lo, double hi) {
    if (!v) return;
    check::positive(std::string("initial ") + std::string(name), *v);
    if (*v < lo || *v > hi)
        throw InvalidArgument("initial " + std::string(name) + " = " + fmt(*v) +
                              " is outside its bounds [" + fmt(lo) + ", " + fmt(hi) + "]");
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

void check_measurements(const std::vector<Measurement>& ms, int p) {
    if (static_cast<int>(ms.size()) < p + 1)
        throw InvalidArgument("measurements: " + std::to_string(ms.size()) +
                              " given, but this fit has " + std::to_string(p) +
                              " parameters (including the gain K) and needs at least " +
                              std::to_string(p + 1));
    for (std::size_t i = 0; i < ms.size(); ++i) {
        const std::string at = "measurement " + std::to_string(i + 1) + " ";
        check::polar_angle(at + "theta_i", ms[i].geometry.theta_i_rad);
        check::polar_angle(at + "theta_s", ms[i].geometry.theta_s_rad);
        check::azimuth(at + "phi_s", ms[i].geometry.phi_s_rad);
        check::positive(at + "brightness", ms[i].brightness);
        check::positive(at + "weight", ms[i].weight);
    }
}

// Model brightness B and d ln B / d ln p_j at one geometry, from the log-parameters.
class Model {
  public:
    explicit Model(const FitOptions& o) : o_(o) {
        mo_.factor = o.factor;
        mo_.radiometry = o.radiometry;
        mo_.regime = o.regime;
        mo_.wavelength_um = o.wavelength_um;
    }
    int size() const { return model_parameter_count(o_); }

    // Returns false when B is not a positive finite number (underflow far outside the lobe).
    bool eval(const Geometry& g, const double* log_p, double& B, double* dlnB) const {
        if (o_.model == FitModel::VeryRough) {
            const double s = std::exp(log_p[0]);
            B = very_rough(g, s);
            if (dlnB) {
                // Eq. 4: d ln B/d ln(σ/T) = b/(2 s²); Eq. 5: 3 (b/s²)/(1 + b/s²), b = q_xy²/q_z².
                const ScatteringDirection q = scattering_direction(g);
                const double x = q.qxy2() / (q.qz2() * s * s);
                dlnB[0] = o_.correlation == Correlation::Gaussian ? 0.5 * x : 3.0 * x / (1.0 + x);
            }
        } else {
            B = slightly_rough(g, std::exp(log_p[0]), std::exp(log_p[1]));
            if (dlnB) {
                const double h = 1e-6;
                for (int j = 0; j < 2; ++j) {
                    double lp[2] = {log_p[0], log_p[1]};
                    lp[j] += h;
                    const double up = slightly_rough(g, std::exp(lp[0]), std::exp(lp[1]));
                    lp[j] -= 2.0 * h;
                    const double dn = slightly_rough(g, std::exp(lp[0]), std::exp(lp[1]));
                    dlnB[j] = (std::log(up) - std::log(dn)) / (2.0 * h);
                    if (!std::isfinite(dlnB[j])) return false;
                }
            }
        }
        return std::isfinite(B) && B > 0.0;
    }

    double very_rough(const Geometry& g, double s) const {
        const double F2 = geometric_factor_squared(o_.factor, g);
        const ScatteringDirection q = scattering_direction(g);
        const double shape = o_.correlation == Correlation::Gaussian
                                 ? very_rough_shape_gaussian(F2, q, s)
                                 : very_rough_shape_exponential(F2, q, s);
        return shape * radiometric_factor(o_.radiometry, g);
    }
    double slightly_rough(const Geometry& g, double sigma_um, double T_um) const {
        const ScatteredPower p =
            mean_scattered_power(g, Surface{sigma_um, T_um, o_.correlation}, mo_);
        return p.diffuse * radiometric_factor(o_.radiometry, g);
    }

  private:
    const FitOptions& o_;
    ModelOptions mo_;
};

double residual_of(ResidualType rt, double sw, double KB, double E) {
    switch (rt) {
        case ResidualType::Relative:
            return sw * (KB - E) / E;
        case ResidualType::Absolute:
            return sw * (KB - E);
        case ResidualType::Log:
            return sw * (std::log(KB) - std::log(E));
    }
    return 0.0;
}

// One residual per measurement; one parameter block [ln p..., ln K].
class MeasurementCost final : public ceres::CostFunction {
  public:
    MeasurementCost(const Measurement& m, const Model& model, ResidualType rt)
        : m_(m), model_(model), rt_(rt) {
        set_num_residuals(1);
        mutable_parameter_block_sizes()->push_back(model.size() + 1);
    }
    bool Evaluate(double const* const* parameters, double* residuals,
                  double** jacobians) const override {
        const double* p = parameters[0];
        const int n = model_.size();
        double B = 0.0, dlnB[2] = {0.0, 0.0};
        if (!model_.eval(m_.geometry, p, B, jacobians && jacobians[0] ? dlnB : nullptr))
            return false;
        const double KB = std::exp(p[n]) * B;
        if (!(std::isfinite(KB) && KB > 0.0)) return false;
        const double sw = std::sqrt(m_.weight), E = m_.brightness;
        residuals[0] = residual_of(rt_, sw, KB, E);
        if (jacobians && jacobians[0]) {
            // d(K B)/d ln p_j = K B d ln B/d ln p_j, d(K B)/d ln K = K B.
            double scale = 0.0;
            switch (rt_) {
                case ResidualType::Relative:
                    scale = sw * KB / E;
                    break;
                case ResidualType::Absolute:
                    scale = sw * KB;
                    break;
                case ResidualType::Log:
                    scale = sw;
                    break;
            }
            for (int j = 0; j < n; ++j) jacobians[0][j] = scale * dlnB[j];
            jacobians[0][n] = scale;
        }
        return std::isfinite(residuals[0]);
    }

  private:
    const Measurement& m_;
    const Model& model_;
    ResidualType rt_;
};

// The gain minimising the (unrobustified) sum of squares for fixed model brightness B_i.
double optimal_log_gain(const std::vector<Measurement>& ms, const std::vector<double>& B,
                        ResidualType rt) {
    double num = 0.0, den = 0.0;
    for (std::size_t i = 0; i < ms.size(); ++i) {
        const double w = ms[i].weight, E = ms[i].brightness;
        switch (rt) {
            case ResidualType::Relative:
                num += w * B[i] / E;
                den += w * B[i] * B[i] / (E * E);
                break;
            case ResidualType::Absolute:
                num += w * B[i] * E;
                den += w * B[i] * B[i];
                break;
            case ResidualType::Log:
                num += w * (std::log(E) - std::log(B[i]));
                den += w;
                break;
        }
    }
    return rt == ResidualType::Log ? num / den : std::log(num / den);
}

// Sum of squares with the gain profiled out; inf when the model underflows somewhere.
double profile_sse(const std::vector<Measurement>& ms, const Model& model, const double* log_p,
                   double* log_K_out = nullptr, ResidualType rt = ResidualType::Relative) {
    std::vector<double> B(ms.size());
    for (std::size_t i = 0; i < ms.size(); ++i)
        if (!model.eval(ms[i].geometry, log_p, B[i], nullptr)) return kInf;
    const double lK = optimal_log_gain(ms, B, rt);
    if (!std::isfinite(lK)) return kInf;
    double sse = 0.0;
    for (std::size_t i = 0; i < ms.size(); ++i) {
        const double r =
            residual_of(rt, std::sqrt(ms[i].weight), std::exp(lK) * B[i], ms[i].brightness);
        sse += r * r;
    }
    if (log_K_out) *log_K_out = lK;
    return std::isfinite(sse) ? sse : kInf;
}

// Starting point [ln p..., ln K] (see docs/estimation.md).
std::vector<double> initial_point(const std::vector<Measurement>& ms, const Model& model,
                                  const FitOptions& o) {
    const int n = model.size();
    std::vector<double> x(n + 1, 0.0);
    if (o.model == FitModel::VeryRough) {
        if (o.initial_sigma_over_T) {
            x[0] = std::log(*o.initial_sigma_over_T);
        } else {
            // Coarse profile scan (gain profiled out) over the bounds, capped to [1e-3, 1e3].
            const double lo = std::log(std::max(o.sigma_over_T_min, 1e-3));
            const double hi = std::log(std::min(o.sigma_over_T_max, 1e3));
            double best = kInf;
            x[0] = 0.5 * (lo + hi);
            const int steps = 24;
            for (int k = 0; k <= steps; ++k) {
                const double ls = lo + (hi - lo) * k / steps;
                const double sse = profile_sse(ms, model, &ls, nullptr, o.residual);
                if (sse < best) {
                    best = sse;
                    x[0] = ls;
                }
            }
        }
    } else {
        double sigma0 = 0.0, T0 = 0.0;
        if (!(o.initial_sigma_um && o.initial_T_um)) {
            // Eq. 3 in logs is linear: ln E − ln(v_z² F² rad) = c − σ² v_z² − (T²/4) v_xy².
            Eigen::MatrixXd A(ms.size(), 3);
            Eigen::VectorXd y(ms.size());
            for (std::size_t i = 0; i < ms.size(); ++i) {
                const Geometry& g = ms[i].geometry;
                const ScatteringVector v = scattering_vector(g, o.wavelength_um);
                const double sw = std::sqrt(ms[i].weight);
                const double F2 = geometric_factor_squared(o.factor, g);
                A(i, 0) = sw;
                A(i, 1) = -sw * v.vz * v.vz;
                A(i, 2) = -sw * v.vxy2() / 4.0;
                y(i) = sw * (std::log(ms[i].brightness) -
                             std::log(v.vz * v.vz * F2 * radiometric_factor(o.radiometry, g)));
            }
            const Eigen::VectorXd c = A.colPivHouseholderQr().solve(y);
            if (c.allFinite() && c(1) > 0.0) sigma0 = std::sqrt(c(1));
            if (c.allFinite() && c(2) > 0.0) T0 = std::sqrt(c(2));
        }
        if (o.initial_sigma_um) sigma0 = *o.initial_sigma_um;
        if (o.initial_T_um) T0 = *o.initial_T_um;
        if (!(sigma0 > 0.0 && T0 > 0.0)) {
            // Coarse profile scan around λ-scaled values (the log-linear start failed).
            double best = kInf;
            const double k = wavenumber_per_um(o.wavelength_um);
            for (int a = 0; a <= 12; ++a)
                for (int b = 0; b <= 12; ++b) {
                    const double s = sigma0 > 0.0 ? sigma0 : std::pow(10.0, -2.5 + 0.25 * a) / k;
                    const double t = T0 > 0.0 ? T0 : std::pow(10.0, -1.0 + 0.25 * b) / k;
                    const double lp[2] = {std::log(s), std::log(t)};
                    const double sse = profile_sse(ms, model, lp, nullptr, o.residual);
                    if (sse < best) {
                        best = sse;
                        x[0] = lp[0];
                        x[1] = lp[1];
                    }
                }
            if (!std::isfinite(best)) {
                x[0] = std::log(sigma0 > 0.0 ? sigma0 : 0.05 / k);
                x[1] = std::log(T0 > 0.0 ? T0 : 1.0 / k);
            }
        } else {
            x[0] = std::log(sigma0);
            x[1] = std::log(T0);
        }
        x[0] = std::clamp(x[0], std::log(o.sigma_min_um), std::log(o.sigma_max_um));
        x[1] = std::clamp(x[1], std::log(o.T_min_um), std::log(o.T_max_um));
    }
    if (o.model == FitModel::VeryRough)
        x[0] = std::clamp(x[0], std::log(o.sigma_over_T_min), std::log(o.sigma_over_T_max));
    double lK = 0.0;
    if (std::isfinite(profile_sse(ms, model, x.data(), &lK, o.residual))) x[n] = lK;
    return x;
}

ceres::LossFunction* make_loss(const FitOptions& o) {
    switch (o.loss) {
        case LossType::None:
            return nullptr;
        case LossType::Huber:
            return new ceres::HuberLoss(o.loss_scale);
        case LossType::Cauchy:
            return new ceres::CauchyLoss(o.loss_scale);
        case LossType::SoftLOne:
            return new ceres::SoftLOneLoss(o.loss_scale);
    }
    return nullptr;
}

std::string correlation_label(Correlation c) {
    return c == Correlation::Gaussian ? "Gaussian" : "exponential";
}

}  // namespace

double fit_model_brightness(const Geometry& geom, const std::vector<double>& parameters,
                            const FitOptions& options) {
    check_options(options);
    check::polar_angle("theta_i", geom.theta_i_rad);
    check::polar_angle("theta_s", geom.theta_s_rad);
    check::azimuth("phi_s", geom.phi_s_rad);
    const int n = model_parameter_count(options);
    if (static_cast<int>(parameters.size()) != n)
        throw InvalidArgument("parameters: " + std::to_string(parameters.size()) + " given, the " +
                              std::string(to_string(options.model)) + " model has " +
                              std::to_string(n));
    Model model(options);
    if (n == 1) {
        check::positive("sigma/T", parameters[0]);
        return model.very_rough(geom, parameters[0]);
    }
    check::positive("sigma", parameters[0], "um");
    check::positive("T", parameters[1], "um");
    return model.slightly_rough(geom, parameters[0], parameters[1]);
}

const FitParameter& FitResult::parameter(std::string_view name) const {
    for (const auto& p : parameters)
        if (p.name == name) return p;
    std::string names;
    for (const auto& p : parameters) names += (names.empty() ? "" : ", ") + p.name;
    throw InvalidArgument("fit parameter '" + std::string(name) +
                          "' does not exist; have: " + names);
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
    for (const auto& p : parameters) {
        s += " " + p.name + " = " + fmt(p.value);
        if (covariance_available && !p.at_bound) s += " +/- " + fmt(p.std_error, 3);
        if (p.at_bound) s += " (at bound)";
        s += ";";
    }
    s += " SSE = " + fmt(sse) + ", AIC = " + fmt(aic) + ". " + message;
    return s;
}

FitResult fit_roughness(const std::vector<Measurement>& measurements, const FitOptions& options) {
    check_options(options);
    const int n = model_parameter_count(options);
    const int p = n + 1;
    check_measurements(measurements, p);
    const int N = static_cast<int>(measurements.size());

    FitResult result;
    result.options = options;
    result.num_measurements = N;
    result.num_parameters = p;

    Model model(options);
    std::vector<double> x = initial_point(measurements, model, options);

    ceres::Problem::Options problem_options;
    problem_options.loss_function_ownership = ceres::TAKE_OWNERSHIP;
    problem_options.cost_function_ownership = ceres::TAKE_OWNERSHIP;
    ceres::Problem problem(problem_options);
    std::vector<const MeasurementCost*> costs;
    for (const auto& m : measurements) {
        auto* cost = new MeasurementCost(m, model, options.residual);
        costs.push_back(cost);
        problem.AddResidualBlock(cost, make_loss(options), x.data());
    }
    std::vector<std::array<double, 2>> bounds;
    std::vector<std::string> names;
    if (options.model == FitModel::VeryRough) {
        bounds.push_back({options.sigma_over_T_min, options.sigma_over_T_max});
        names.push_back("sigma_over_T");
    } else {
        bounds.push_back({options.sigma_min_um, options.sigma_max_um});
        bounds.push_back({options.T_min_um, options.T_max_um});
        names.push_back("sigma_um");
        names.push_back("T_um");
    }
    for (int j = 0; j < n; ++j) {
        problem.SetParameterLowerBound(x.data(), j, std::log(bounds[j][0]));
        problem.SetParameterUpperBound(x.data(), j, std::log(bounds[j][1]));
    }

    ceres::Solver::Options so;
    so.linear_solver_type = ceres::DENSE_QR;
    so.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
    so.max_num_iterations = options.max_iterations;
    so.function_tolerance = options.function_tolerance;
    so.gradient_tolerance = options.gradient_tolerance;
    so.parameter_tolerance = options.parameter_tolerance;
    so.logging_type = ceres::SILENT;
    so.minimizer_progress_to_stdout = false;
    so.num_threads = 1;
    ceres::Solver::Summary summary;
    ceres::Solve(so, &problem, &summary);

    result.iterations = static_cast<int>(summary.iterations.size()) - 1;
    result.initial_cost = summary.initial_cost;
    result.final_cost = summary.final_cost;
    switch (summary.termination_type) {
        case ceres::CONVERGENCE:
            result.status = SolverStatus::Converged;
            break;
        case ceres::NO_CONVERGENCE:
            result.status = SolverStatus::NoConvergence;
            break;
        default:
            result.status = SolverStatus::Failed;
            break;
    }
    result.message = summary.message;

    // Residuals and predictions at the solution (unrobustified).
    result.residuals.resize(N);
    result.predicted.resize(N);
    double sse = 0.0;
    bool finite = true;
    for (int i = 0; i < N; ++i) {
        double B = 0.0;
        finite = finite && model.eval(measurements[i].geometry, x.data(), B, nullptr);
        const double KB = std::exp(x[n]) * B;
        result.predicted[i] = KB;
        result.residuals[i] = residual_of(options.residual, std::sqrt(measurements[i].weight), KB,
                                          measurements[i].brightness);
        sse += result.residuals[i] * result.residuals[i];
    }
    if (!finite || !std::isfinite(sse)) {
        result.status = SolverStatus::Failed;
        result.message += "; the model brightness is not finite at the solution";
    }
    result.sse = sse;
    const double sse_floor = std::max(sse / N, std::numeric_limits<double>::min());
    result.aic = N * std::log(sse_floor) + 2.0 * p;
    result.aicc = N - p - 1 > 0 ? result.aic + 2.0 * p * (p + 1) / double(N - p - 1) : kInf;

    // Parameters and covariance (log space → natural units by the delta method).
    std::vector<double> natural(p);
    for (int j = 0; j < p; ++j) natural[j] = std::exp(x[j]);
    result.covariance = Eigen::MatrixXd::Zero(p, p);
    if (result.status != SolverStatus::Failed) {
        // Gauss–Newton covariance (JᵀJ)⁻¹ in log space from the Jacobian at the solution, rows
        // scaled by √ρ'(r²) for a robust loss (the first-order correction Ceres also applies).
        // Computed here with an SVD rather than ceres::Covariance so that a rank-deficient
        // problem is reported in the result instead of logged.
        const std::unique_ptr<ceres::LossFunction> loss(make_loss(options));
        Eigen::MatrixXd J(N, p);
        bool ok = true;
        for (int i = 0; i < N && ok; ++i) {
            double r = 0.0;
            std::vector<double> row(p);
            const double* params[] = {x.data()};
            double* jac[] = {row.data()};
            ok = costs[i]->Evaluate(params, &r, jac);
            double w = 1.0;
            if (loss) {
                double rho[3];
                loss->Evaluate(r * r, rho);
                w = std::sqrt(std::max(rho[1], 0.0));
            }
            for (int j = 0; j < p; ++j) J(i, j) = w * row[j];
        }
        if (ok && J.allFinite()) {
            Eigen::JacobiSVD<Eigen::MatrixXd> svd(J, Eigen::ComputeThinV);
            const Eigen::VectorXd sv = svd.singularValues();
            if (sv(sv.size() - 1) > 1e-10 * sv(0)) {
                const Eigen::VectorXd inv2 = sv.array().square().inverse();
                const Eigen::MatrixXd C =
                    svd.matrixV() * inv2.asDiagonal() * svd.matrixV().transpose();
                const double scale = options.scale_covariance ? sse / (N - p) : 1.0;
                for (int a = 0; a < p; ++a)
                    for (int b = 0; b < p; ++b)
                        result.covariance(a, b) = scale * C(a, b) * natural[a] * natural[b];
                result.covariance_available = result.covariance.allFinite();
            }
        }
        if (!result.covariance_available)
            result.message +=
                "; covariance unavailable (the Jacobian is rank deficient: the "
                "measurements do not constrain every parameter)";
    }
    for (int j = 0; j < p; ++j) {
        FitParameter fp;
        fp.name = j < n ? names[j] : "gain";
        fp.value = natural[j];
        fp.lower = j < n ? bounds[j][0] : 0.0;
        fp.upper = j < n ? bounds[j][1] : kInf;
        fp.std_error =
            result.covariance_available ? std::sqrt(std::max(0.0, result.covariance(j, j))) : 0.0;
        if (j < n)
            fp.at_bound = std::abs(x[j] - std::log(fp.lower)) < 1e-9 ||
                          std::abs(x[j] - std::log(fp.upper)) < 1e-9;
        result.parameters.push_back(fp);
    }

    // Derived quantities.
    RoughnessEstimate& est = result.estimate;
    est.correlation = options.correlation;
    std::vector<Geometry> geoms;
    for (const auto& m : measurements) geoms.push_back(m.geometry);
    auto se = [&](int j) {
        return result.covariance_available ? result.parameters[j].std_error : 0.0;
    };
    if (options.model == FitModel::VeryRough) {
        est.sigma_over_T = Estimate{natural[0], se(0)};
        est.roughness_class = RoughnessClass::VeryRough;
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
        if (fp.at_bound)
            est.warnings.push_back(fp.name + " = " + fmt(fp.value) +
                                   " is at a bound of its range [" + fmt(fp.lower) + ", " +
                                   fmt(fp.upper) +
                                   "]: the data do not constrain it there; its standard error "
                                   "is not meaningful");
    if (result.status != SolverStatus::Converged)
        est.warnings.push_back("the fit did not converge: " + result.message);
    return result;
}

CorrelationComparison compare_correlations(const std::vector<Measurement>& measurements,
                                           const FitOptions& options) {
    CorrelationComparison c;
    FitOptions o = options;
    o.correlation = Correlation::Gaussian;
    c.gaussian = fit_roughness(measurements, o);
    o.correlation = Correlation::Exponential;
    c.exponential = fit_roughness(measurements, o);
    c.preferred =
        c.gaussian.aic <= c.exponential.aic ? Correlation::Gaussian : Correlation::Exponential;
    c.delta_aic = std::abs(c.gaussian.aic - c.exponential.aic);
    return c;
}

}  // namespace roughscope
