// Tests of the least-squares engine (include/roughscope/fit/engine.hpp) on problems whose answer
// is known independently: linear least squares in closed form (solution and covariance), noise-
// free exponential decay, variable projection against a free gain, identifiability failures,
// bounds, grid starts on a multi-modal problem, and bad input (each success paired with a
// failure on the error type).
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/fit/engine.hpp"

namespace rs = roughscope;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

rs::ParameterSpec param(const std::string& name, double lower, double upper,
                        rs::Transform t = rs::Transform::Linear,
                        std::optional<double> initial = std::nullopt) {
    rs::ParameterSpec s;
    s.name = name;
    s.lower = lower;
    s.upper = upper;
    s.transform = t;
    s.initial = initial;
    return s;
}

// A deterministic "noise" in [-1, 1].
double pseudo_noise(int i) { return std::sin(12.9898 * i + 78.233 * std::cos(0.7 * i)); }

std::vector<double> xs(int n, double step = 0.25) {
    std::vector<double> x;
    for (int i = 0; i < n; ++i) x.push_back(step * i);
    return x;
}

// y = a + b x with weights: the problem and its closed-form answer.
rs::LeastSquaresProblem line_problem(const std::vector<double>& x, const std::vector<double>& y,
                                     const std::vector<double>& w) {
    rs::LeastSquaresProblem P;
    P.parameters = {param("a", -kInf, kInf, rs::Transform::Linear, 0.0),
                    param("b", -kInf, kInf, rs::Transform::Linear, 0.0)};
    P.model = [x](std::span<const double> t, std::span<double> out) {
        for (std::size_t i = 0; i < x.size(); ++i) out[i] = t[0] + t[1] * x[i];
        return true;
    };
    P.data = y;
    P.weights = w;
    return P;
}

// y = A exp(−k x): k is the model parameter, A the gain.
rs::LeastSquaresProblem decay_problem(const std::vector<double>& x, const std::vector<double>& y,
                                      rs::GainMode gain = rs::GainMode::Profiled) {
    rs::LeastSquaresProblem P;
    rs::ParameterSpec k = param("k", 1e-3, 1e3, rs::Transform::Log);
    P.parameters = {k};
    P.model = [x](std::span<const double> t, std::span<double> out) {
        for (std::size_t i = 0; i < x.size(); ++i) out[i] = std::exp(-t[0] * x[i]);
        return true;
    };
    P.data = y;
    P.gain = gain;
    return P;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Known answers

TEST(FitEngine, LinearModelMatchesClosedFormSolutionAndCovariance) {
    const std::vector<double> x = xs(20);
    std::vector<double> y, w;
    for (std::size_t i = 0; i < x.size(); ++i) {
        y.push_back(1.5 - 0.7 * x[i] + 0.1 * pseudo_noise(static_cast<int>(i)));
        w.push_back(1.0 + 0.5 * (i % 3));
    }
    const rs::LeastSquaresResult r = rs::solve_least_squares(line_problem(x, y, w));
    // Weighted normal equations: β = (XᵀWX)⁻¹ XᵀWy, cov = s² (XᵀWX)⁻¹, s² = SSE/(N − 2).
    Eigen::MatrixXd X(x.size(), 2);
    Eigen::VectorXd Y(x.size()), W(x.size());
    for (std::size_t i = 0; i < x.size(); ++i) {
        X(i, 0) = 1.0;
        X(i, 1) = x[i];
        Y(i) = y[i];
        W(i) = w[i];
    }
    const Eigen::MatrixXd A = X.transpose() * W.asDiagonal() * X;
    const Eigen::VectorXd beta = A.ldlt().solve(X.transpose() * W.asDiagonal() * Y);
    const Eigen::VectorXd res = Y - X * beta;
    const double sse = res.dot(W.asDiagonal() * res);
    const Eigen::MatrixXd cov = sse / (x.size() - 2.0) * A.inverse();

    EXPECT_EQ(r.status, rs::SolverStatus::Converged) << r.brief_report();
    EXPECT_NEAR(r.value("a"), beta(0), 1e-9);
    EXPECT_NEAR(r.value("b"), beta(1), 1e-9);
    EXPECT_NEAR(r.sse, sse, 1e-12);
    ASSERT_TRUE(r.covariance_available);
    for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b) EXPECT_NEAR(r.covariance(a, b), cov(a, b), 1e-6 * cov(a, a));
    EXPECT_NEAR(r.parameter("b").std_error, std::sqrt(cov(1, 1)), 1e-6 * std::sqrt(cov(1, 1)));
    EXPECT_EQ(r.num_parameters, 2);
    EXPECT_EQ(r.num_data, 20);
    EXPECT_NEAR(r.aic, 20 * std::log(sse / 20) + 4.0, 1e-9);
    EXPECT_NEAR(r.aicc, r.aic + 2.0 * 2 * 3 / (20 - 3.0), 1e-9);
    EXPECT_NE(r.brief_report().find("converged"), std::string::npos);
}

TEST(FitEngine, LinearModelRejectsWeightsOfTheWrongLength) {
    const std::vector<double> x = xs(5);
    EXPECT_THROW(rs::solve_least_squares(line_problem(x, {1, 2, 3, 4, 5}, {1, 1})),
                 rs::InvalidArgument);
}

TEST(FitEngine, NoiseFreeExponentialDecayIsRecoveredExactly) {
    const std::vector<double> x = xs(15);
    for (double k : {0.05, 0.8, 6.0}) {
        std::vector<double> y;
        for (double xi : x) y.push_back(4.2 * std::exp(-k * xi));
        for (auto rt :
             {rs::ResidualType::Absolute, rs::ResidualType::Relative, rs::ResidualType::Log}) {
            rs::LeastSquaresProblem P = decay_problem(x, y);
            P.residual = rt;
            const rs::LeastSquaresResult r = rs::solve_least_squares(P);
            EXPECT_EQ(r.status, rs::SolverStatus::Converged) << r.brief_report();
            EXPECT_NEAR(r.value("k"), k, 1e-8 * k) << r.brief_report();
            EXPECT_NEAR(r.value("gain"), 4.2, 1e-8 * 4.2);
            EXPECT_NEAR(r.gain, 4.2, 1e-8 * 4.2);
            EXPECT_LT(r.sse, 1e-18);
            EXPECT_EQ(r.num_parameters, 2);
        }
    }
}

TEST(FitEngine, DecayRejectsNonPositiveDataUnderRelativeResiduals) {
    const std::vector<double> x = xs(4);
    rs::LeastSquaresProblem P = decay_problem(x, {1.0, 0.5, 0.0, 0.1});
    P.residual = rs::ResidualType::Relative;
    try {
        rs::solve_least_squares(P);
        FAIL() << "expected InvalidArgument";
    } catch (const rs::InvalidArgument& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("data[2]"), std::string::npos) << m;
        EXPECT_NE(m.find("(0, inf)"), std::string::npos) << m;
    }
    P.residual = rs::ResidualType::Absolute;  // fine with absolute residuals
    EXPECT_NO_THROW(rs::solve_least_squares(P));
}

TEST(FitEngine, VariableProjectionEqualsAFreeGain) {
    // Noisy decay: eliminating the gain in closed form and fitting it jointly give one minimum,
    // one covariance.
    const std::vector<double> x = xs(25, 0.2);
    std::vector<double> y;
    for (std::size_t i = 0; i < x.size(); ++i)
        y.push_back(3.0 * std::exp(-1.3 * x[i]) + 0.02 * pseudo_noise(static_cast<int>(i)));
    const auto vp = rs::solve_least_squares(decay_problem(x, y, rs::GainMode::Profiled));
    const auto free = rs::solve_least_squares(decay_problem(x, y, rs::GainMode::Free));
    EXPECT_EQ(vp.status, rs::SolverStatus::Converged) << vp.brief_report();
    EXPECT_EQ(free.status, rs::SolverStatus::Converged) << free.brief_report();
    EXPECT_NEAR(vp.value("k"), free.value("k"), 1e-7 * vp.value("k"));
    EXPECT_NEAR(vp.value("gain"), free.value("gain"), 1e-7 * vp.value("gain"));
    EXPECT_NEAR(vp.sse, free.sse, 1e-10 * vp.sse);
    ASSERT_TRUE(vp.covariance_available && free.covariance_available);
    for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b)
            EXPECT_NEAR(vp.covariance(a, b), free.covariance(a, b),
                        1e-5 * std::sqrt(vp.covariance(a, a) * vp.covariance(b, b)));
    // The closed-form gain of the solution is the reported one.
    EXPECT_NEAR(rs::optimal_gain(vp.model, y, {}, rs::ResidualType::Absolute), vp.gain,
                1e-12 * vp.gain);
}

TEST(FitEngine, OptimalGainClosedForms) {
    const std::vector<double> M = {1.0, 2.0, 4.0}, y = {2.0, 3.0, 9.0}, w = {1.0, 2.0, 0.5};
    EXPECT_NEAR(rs::optimal_gain(M, y, w, rs::ResidualType::Absolute),
                (2.0 + 12.0 + 18.0) / (1.0 + 8.0 + 8.0), 1e-15);
    EXPECT_NEAR(
        rs::optimal_gain(M, y, w, rs::ResidualType::Relative),
        (0.5 + 2.0 * 2.0 / 3.0 + 0.5 * 4.0 / 9.0) / (0.25 + 2.0 * 4.0 / 9.0 + 0.5 * 16.0 / 81.0),
        1e-15);
    EXPECT_NEAR(rs::optimal_gain(M, y, w, rs::ResidualType::Log),
                std::exp((std::log(2.0) + 2.0 * std::log(1.5) + 0.5 * std::log(2.25)) / 3.5),
                1e-14);
    EXPECT_TRUE(
        std::isnan(rs::optimal_gain(std::vector<double>{0.0, 0.0}, std::vector<double>{1.0, 2.0},
                                    {}, rs::ResidualType::Absolute)));
}

TEST(FitEngine, RobustLossResistsAnOutlierWithTheGainFittedJointly) {
    const std::vector<double> x = xs(20, 0.2);
    std::vector<double> y;
    for (double xi : x) y.push_back(2.0 * std::exp(-0.9 * xi));
    y[7] *= 3.0;  // an outlier
    rs::LeastSquaresOptions o;
    const auto plain = rs::solve_least_squares(decay_problem(x, y), o);
    o.loss = rs::LossType::Cauchy;
    o.loss_scale = 0.01;
    const auto robust = rs::solve_least_squares(decay_problem(x, y), o);
    EXPECT_GT(std::abs(plain.value("k") - 0.9), 0.01);
    EXPECT_NEAR(robust.value("k"), 0.9, 2e-3) << robust.brief_report();
    EXPECT_NEAR(robust.value("gain"), 2.0, 5e-3);
    o.loss_scale = -1.0;
    EXPECT_THROW(rs::solve_least_squares(decay_problem(x, y), o), rs::InvalidArgument);
}

TEST(FitEngine, GridStartFindsTheGlobalMinimumOfAMultiModalProblem) {
    // y = sin(f x): the cost has many local minima in f; a local start at f = 1 misses f = 7.3,
    // the grid over [0.5, 12] finds it.
    const std::vector<double> x = xs(60, 0.1);
    std::vector<double> y;
    for (double xi : x) y.push_back(std::sin(7.3 * xi));
    rs::LeastSquaresProblem P;
    P.parameters = {param("f", 0.5, 12.0, rs::Transform::Linear)};
    P.parameters[0].grid_points = 200;
    P.model = [x](std::span<const double> t, std::span<double> out) {
        for (std::size_t i = 0; i < x.size(); ++i) out[i] = std::sin(t[0] * x[i]);
        return true;
    };
    P.data = y;
    const auto global = rs::solve_least_squares(P);
    EXPECT_NEAR(global.value("f"), 7.3, 1e-8) << global.brief_report();
    P.parameters[0].initial = 1.0;
    const auto local = rs::solve_least_squares(P);
    EXPECT_GT(std::abs(local.value("f") - 7.3), 0.5) << local.brief_report();
    // A grid needs a finite start range.
    P.parameters[0].initial.reset();
    P.parameters[0].upper = kInf;
    EXPECT_THROW(rs::solve_least_squares(P), rs::InvalidArgument);
}

// ---------------------------------------------------------------------------------------------
// Identifiability: never "converged"

TEST(FitEngineIdentifiability, TwoDataPointsForTwoParametersAndAGain) {
    rs::LeastSquaresProblem P;
    P.parameters = {param("a", 0.01, 10.0, rs::Transform::Log, 1.0),
                    param("b", 0.01, 10.0, rs::Transform::Log, 1.0)};
    const std::vector<double> x = {0.5, 1.5};
    P.model = [x](std::span<const double> t, std::span<double> out) {
        for (std::size_t i = 0; i < x.size(); ++i) out[i] = std::exp(-t[0] * x[i]) + t[1];
        return true;
    };
    P.data = {1.0, 0.6};
    P.gain = rs::GainMode::Profiled;
    const auto r = rs::solve_least_squares(P);
    EXPECT_EQ(r.status, rs::SolverStatus::NotIdentifiable) << r.brief_report();
    EXPECT_FALSE(r.covariance_available);
    EXPECT_NE(r.message.find("2 data points"), std::string::npos) << r.message;
    EXPECT_EQ(r.not_identifiable.size(), 3u);
    // A third distinct point makes it identifiable.
    const std::vector<double> x3 = {0.5, 1.5, 3.0};
    P.model = [x3](std::span<const double> t, std::span<double> out) {
        for (std::size_t i = 0; i < x3.size(); ++i) out[i] = std::exp(-t[0] * x3[i]) + t[1];
        return true;
    };
    P.data = {1.0, 0.6, 0.45};
    const auto r3 = rs::solve_least_squares(P);
    EXPECT_NE(r3.status, rs::SolverStatus::NotIdentifiable) << r3.brief_report();
}

TEST(FitEngineIdentifiability, RepeatedGeometryIsNotEnough) {
    // Ten measurements, all at the same x: k and the gain trade off exactly.
    const std::vector<double> x(10, 0.7);
    std::vector<double> y(10);
    for (int i = 0; i < 10; ++i) y[static_cast<std::size_t>(i)] = 1.0 + 0.01 * pseudo_noise(i);
    rs::LeastSquaresProblem P = decay_problem(x, y);
    P.parameters[0].initial = 0.5;
    const auto r = rs::solve_least_squares(P);
    EXPECT_EQ(r.status, rs::SolverStatus::NotIdentifiable) << r.brief_report();
    ASSERT_FALSE(r.not_identifiable.empty());
    EXPECT_NE(r.message.find("k"), std::string::npos);
}

TEST(FitEngineIdentifiability, RepeatedGeometryNamesTheParameterWhateverTheGainsScale) {
    // A model of order 1e-20 against data of order 1 (gain ≈ 1e20, e.g. a very rough brightness
    // far outside its lobe), all at one x: k and the gain trade off exactly, and both are named
    // — the gain's size must not make it look like a parameter without effect.
    const std::vector<double> x(3, 0.7);
    rs::LeastSquaresProblem P;
    P.parameters = {param("k", 0.01, 10.0, rs::Transform::Log, 0.5)};
    P.model = [x](std::span<const double> t, std::span<double> out) {
        for (std::size_t i = 0; i < x.size(); ++i) out[i] = 1e-20 * std::exp(-t[0] * x[i]);
        return true;
    };
    P.data = {1.0, 1.1, 0.9};
    P.residual = rs::ResidualType::Relative;
    P.gain = rs::GainMode::Profiled;
    const auto r = rs::solve_least_squares(P);
    EXPECT_EQ(r.status, rs::SolverStatus::NotIdentifiable) << r.brief_report();
    EXPECT_EQ(r.not_identifiable, (std::vector<std::string>{"k", "gain"})) << r.brief_report();
    for (const auto& p : r.parameters) EXPECT_FALSE(p.identified) << p.name;
    // No number for what the data do not determine.
    EXPECT_NE(r.brief_report().find("k not identifiable"), std::string::npos) << r.brief_report();
    EXPECT_EQ(r.brief_report().find("k = "), std::string::npos) << r.brief_report();
}

TEST(FitEngineIdentifiability, ConstantDataDoNotDetermineTheShape) {
    // A lobe exp(−(x/w)²) times a gain against constant data: the width runs off to where the
    // lobe is flat and has no effect any more.
    const std::vector<double> x = xs(12, 0.1);
    rs::LeastSquaresProblem P;
    P.parameters = {param("w", 0.0, kInf, rs::Transform::Log, 1.0)};
    P.model = [x](std::span<const double> t, std::span<double> out) {
        for (std::size_t i = 0; i < x.size(); ++i) out[i] = std::exp(-std::pow(x[i] / t[0], 2));
        return true;
    };
    P.data.assign(x.size(), 2.0);
    P.gain = rs::GainMode::Profiled;
    const auto r = rs::solve_least_squares(P);
    EXPECT_NE(r.status, rs::SolverStatus::Converged) << r.brief_report();
    EXPECT_EQ(r.status, rs::SolverStatus::NotIdentifiable) << r.brief_report();
    ASSERT_EQ(r.not_identifiable.size(), 1u);
    EXPECT_EQ(r.not_identifiable[0], "w");
    // Data from a real lobe determine it.
    for (std::size_t i = 0; i < x.size(); ++i) P.data[i] = 2.0 * std::exp(-std::pow(x[i] / 0.6, 2));
    const auto ok = rs::solve_least_squares(P);
    EXPECT_EQ(ok.status, rs::SolverStatus::Converged) << ok.brief_report();
    EXPECT_NEAR(ok.value("w"), 0.6, 1e-8);
}

TEST(FitEngineIdentifiability, ParameterWithoutEffectIsNamed) {
    const std::vector<double> x = xs(10);
    std::vector<double> y;
    for (double xi : x) y.push_back(2.0 * std::exp(-0.8 * xi));
    rs::LeastSquaresProblem P;
    P.parameters = {param("k", 0.01, 10.0, rs::Transform::Log),
                    param("unused", -1.0, 1.0, rs::Transform::Linear, 0.3)};
    P.model = [x](std::span<const double> t, std::span<double> out) {
        for (std::size_t i = 0; i < x.size(); ++i) out[i] = std::exp(-t[0] * x[i]);
        return true;
    };
    P.data = y;
    P.gain = rs::GainMode::Profiled;
    const auto r = rs::solve_least_squares(P);
    EXPECT_EQ(r.status, rs::SolverStatus::NotIdentifiable) << r.brief_report();
    ASSERT_EQ(r.not_identifiable.size(), 1u);
    EXPECT_EQ(r.not_identifiable[0], "unused");
    EXPECT_NE(r.message.find("unused"), std::string::npos);
    EXPECT_NEAR(r.value("k"), 0.8, 1e-8);  // the identifiable part is still solved
    // Without the dead parameter: converged.
    P.parameters.pop_back();
    EXPECT_EQ(rs::solve_least_squares(P).status, rs::SolverStatus::Converged);
}

// ---------------------------------------------------------------------------------------------
// Bounds and bad input

TEST(FitEngineBounds, SolutionOnABoundIsFlagged) {
    const std::vector<double> x = xs(12);
    std::vector<double> y;
    for (double xi : x) y.push_back(1.7 * std::exp(-0.3 * xi));
    rs::LeastSquaresProblem P = decay_problem(x, y);
    P.parameters[0].lower = 0.5;  // the truth, 0.3, is outside
    P.parameters[0].upper = 5.0;
    const auto r = rs::solve_least_squares(P);
    EXPECT_EQ(r.status, rs::SolverStatus::AtBound) << r.brief_report();
    EXPECT_TRUE(r.parameter("k").at_bound);
    EXPECT_FALSE(r.parameter("gain").at_bound);
    EXPECT_NEAR(r.value("k"), 0.5, 1e-12);
    EXPECT_NE(r.message.find("on a bound: k = 0.5"), std::string::npos) << r.message;
    EXPECT_NE(r.brief_report().find("(at bound)"), std::string::npos);
    // The gain is the best one for k on the bound.
    EXPECT_NEAR(r.gain, rs::optimal_gain(r.model, y, {}, rs::ResidualType::Absolute), 1e-12);
    // Inside the bounds: not flagged.
    P.parameters[0].lower = 0.1;
    const auto inside = rs::solve_least_squares(P);
    EXPECT_EQ(inside.status, rs::SolverStatus::Converged);
    EXPECT_FALSE(inside.parameter("k").at_bound);
}

TEST(FitEngineBounds, ActiveSetPolishFindsTheMinimumAlongABound) {
    // Two parameters; the best b is on its upper bound and a must still reach its own optimum.
    const std::vector<double> x = xs(30, 0.1);
    std::vector<double> y;
    for (double xi : x) y.push_back(std::exp(-1.2 * xi) + 2.0 * xi);
    rs::LeastSquaresProblem P;
    P.parameters = {param("a", 0.1, 5.0, rs::Transform::Linear),
                    param("b", 0.0, 1.0, rs::Transform::Linear)};
    P.parameters[0].grid_points = 5;
    P.parameters[1].grid_points = 5;
    P.model = [x](std::span<const double> t, std::span<double> out) {
        for (std::size_t i = 0; i < x.size(); ++i) out[i] = std::exp(-t[0] * x[i]) + t[1] * x[i];
        return true;
    };
    P.data = y;
    const auto r = rs::solve_least_squares(P);
    EXPECT_EQ(r.status, rs::SolverStatus::AtBound) << r.brief_report();
    EXPECT_NEAR(r.value("b"), 1.0, 1e-12);
    // The exact 1-D optimum of a with b = 1 (golden-section on the SSE as an independent check).
    auto sse = [&](double a) {
        double s = 0.0;
        for (std::size_t i = 0; i < x.size(); ++i) {
            const double d = std::exp(-a * x[i]) + x[i] - y[i];
            s += d * d;
        }
        return s;
    };
    double lo = 0.1, hi = 5.0;
    const double g = (std::sqrt(5.0) - 1.0) / 2.0;
    for (int it = 0; it < 200; ++it) {
        const double c = hi - g * (hi - lo), d = lo + g * (hi - lo);
        (sse(c) < sse(d) ? hi : lo) = sse(c) < sse(d) ? d : c;
    }
    EXPECT_NEAR(r.value("a"), 0.5 * (lo + hi), 1e-6);
}

TEST(FitEngineErrors, BadInputNamesTheValueAndItsRange) {
    const std::vector<double> x = xs(6);
    const std::vector<double> y = {1.0, 0.8, 0.6, 0.5, 0.4, 0.3};
    auto message = [](const rs::LeastSquaresProblem& P, const rs::LeastSquaresOptions& o = {}) {
        try {
            rs::solve_least_squares(P, o);
        } catch (const rs::InvalidArgument& e) {
            return std::string(e.what());
        }
        return std::string("no exception");
    };
    rs::LeastSquaresProblem P = decay_problem(x, y);
    P.parameters[0].initial = 2000.0;
    EXPECT_NE(message(P).find("initial k = 2000 is outside its bounds [0.001, 1000]"),
              std::string::npos)
        << message(P);
    P = decay_problem(x, y);
    P.parameters[0].lower = 5.0;
    P.parameters[0].upper = 1.0;
    EXPECT_NE(message(P).find("bounds [5, 1]"), std::string::npos) << message(P);
    P = decay_problem(x, y);
    P.parameters[0].lower = -1.0;
    EXPECT_NE(message(P).find("lower bound = -1"), std::string::npos) << message(P);
    P = decay_problem(x, y);
    P.data[3] = std::nan("");
    EXPECT_NE(message(P).find("data[3]"), std::string::npos) << message(P);
    P = decay_problem(x, y);
    P.weights.assign(6, 1.0);
    P.weights[1] = -2.0;
    EXPECT_NE(message(P).find("weights[1] = -2 is outside the valid range [0, inf)"),
              std::string::npos)
        << message(P);
    P = decay_problem(x, y);
    P.parameters.push_back(P.parameters[0]);
    EXPECT_NE(message(P).find("given twice"), std::string::npos);
    P = decay_problem(x, y);
    P.parameters[0].name = "gain";
    EXPECT_NE(message(P).find("reserved"), std::string::npos);
    P = decay_problem(x, y);
    P.parameters.clear();
    EXPECT_NE(message(P).find("at least 1"), std::string::npos);
    P = decay_problem(x, y);
    rs::LeastSquaresOptions o;
    o.max_iterations = 0;
    EXPECT_NE(message(P, o).find("max_iterations = 0"), std::string::npos);
    o = {};
    o.rank_tolerance = 2.0;
    EXPECT_NE(message(P, o).find("(0, 1)"), std::string::npos);
    // And the same problem, well posed, solves.
    EXPECT_EQ(rs::solve_least_squares(decay_problem(x, y)).status, rs::SolverStatus::Converged);
}

TEST(FitEngineErrors, ModelThatCannotBeEvaluatedFailsWithoutThrowing) {
    const std::vector<double> x = xs(6);
    rs::LeastSquaresProblem P = decay_problem(x, {1.0, 0.8, 0.6, 0.5, 0.4, 0.3});
    P.model = [](std::span<const double>, std::span<double>) -> bool {
        throw rs::InvalidArgument("model exploded");
    };
    const auto r = rs::solve_least_squares(P);
    EXPECT_EQ(r.status, rs::SolverStatus::Failed) << r.brief_report();
}

TEST(FitEngineNames, StatusResidualAndLossNamesRoundTrip) {
    EXPECT_EQ(rs::to_string(rs::SolverStatus::NotIdentifiable), "not_identifiable");
    EXPECT_EQ(rs::to_string(rs::SolverStatus::AtBound), "at_bound");
    for (auto rt : {rs::ResidualType::Relative, rs::ResidualType::Absolute, rs::ResidualType::Log})
        EXPECT_EQ(rs::parse_residual_type(rs::to_string(rt)), rt);
    for (auto l :
         {rs::LossType::None, rs::LossType::Huber, rs::LossType::Cauchy, rs::LossType::SoftLOne})
        EXPECT_EQ(rs::parse_loss_type(rs::to_string(l)), l);
    EXPECT_THROW(rs::parse_loss_type("l2"), rs::InvalidArgument);
}
