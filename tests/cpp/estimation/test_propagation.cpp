// Tests of the uncertainty propagation (include/roughscope/estimation/propagation.hpp) against
// facts that do not come from it: the variance of a linear combination, the moments and quantiles
// of known distributions (a non-central χ², a rectangular, a normal with a cut), reproducibility
// from the seed, and the errors of bad input.
#include <cmath>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/estimation/propagation.hpp"

namespace rs = roughscope;

namespace {

rs::PropagationModel linear_model(std::vector<double> a) {
    return [a](std::span<const double> x, std::span<std::optional<double>> y) {
        double s = 0.0;
        for (std::size_t i = 0; i < a.size(); ++i) s += a[i] * x[i];
        y[0] = s;
    };
}

const std::vector<std::string> kOne{"y"};

}  // namespace

// Y = 3 X1 − 2 X2 + X3: u² = 9 u1² + 4 u2² + u3² exactly, the budget sorted by contribution.
TEST(Propagation, FirstOrderOfALinearModelIsExact) {
    const std::vector<rs::UncertainInput> in{{"x1", 1.0, 0.1}, {"x2", 2.0, 0.3}, {"x3", 5.0, 0.0}};
    const rs::Propagation p = rs::propagate_uncertainty(in, kOne, linear_model({3, -2, 1}));
    EXPECT_EQ(p.method, rs::PropagationMethod::FirstOrder);
    ASSERT_TRUE(p.outputs[0]);
    const auto& y = *p.outputs[0];
    EXPECT_DOUBLE_EQ(y.value, 3.0 - 4.0 + 5.0);
    EXPECT_NEAR(y.uncertainty, std::sqrt(9 * 0.01 + 4 * 0.09), 1e-12);
    EXPECT_NEAR(y.interval95_high - y.value, 1.959963984540054 * y.uncertainty, 1e-12);
    ASSERT_EQ(y.budget.size(), 2U);  // x3 is a constant (u = 0): not a source
    EXPECT_EQ(y.budget[0].source, "x2");
    EXPECT_NEAR(y.budget[0].sensitivity, -2.0, 1e-12);
    EXPECT_NEAR(y.budget[0].contribution, 0.6, 1e-12);
    EXPECT_NEAR(y.budget[0].fraction + y.budget[1].fraction, 1.0, 1e-12);
    EXPECT_NEAR(y.budget[1].fraction, 0.09 / 0.45, 1e-12);
}

// Monte Carlo on the same linear model: u and the interval of the normal within 2 %.
TEST(Propagation, MonteCarloOfALinearModelMatchesTheNormal) {
    const std::vector<rs::UncertainInput> in{{"x1", 1.0, 0.1}, {"x2", 2.0, 0.3}};
    rs::PropagationOptions options;
    options.method = rs::PropagationMethod::MonteCarlo;
    const rs::Propagation p = rs::propagate_uncertainty(in, kOne, linear_model({3, -2}), options);
    EXPECT_EQ(p.method, rs::PropagationMethod::MonteCarlo);
    const auto& y = *p.outputs[0];
    const double u = std::sqrt(0.45);
    EXPECT_NEAR(y.uncertainty, u, 0.02 * u);
    EXPECT_NEAR(y.interval95_low, -1.0 - 1.96 * u, 0.03 * u);
    EXPECT_NEAR(y.interval95_high, -1.0 + 1.96 * u, 0.03 * u);
    EXPECT_GE(y.trials, options.batch_trials * 2);
    EXPECT_EQ(y.trials % options.batch_trials, 0U);
    EXPECT_EQ(y.failed_fraction, 0.0);
}

// Y = X², X ~ N(0.1, 1): first order sees a slope of 0.2 (u = 0.2) but the second-order term is
// large, so Auto takes Monte Carlo, whose u is that of a non-central χ²(1, λ = 0.01):
// Var = 2 (1 + 2λ) = 2.04.
TEST(Propagation, AutoChoosesMonteCarloForANonlinearModel) {
    const std::vector<rs::UncertainInput> in{{"x", 0.1, 1.0}};
    const auto square = [](std::span<const double> x, std::span<std::optional<double>> y) {
        y[0] = x[0] * x[0];
    };
    rs::PropagationOptions first;
    first.method = rs::PropagationMethod::FirstOrder;
    const rs::Propagation fo = rs::propagate_uncertainty(in, kOne, square, first);
    EXPECT_NEAR(fo.outputs[0]->uncertainty, 0.2, 1e-12);
    ASSERT_FALSE(fo.warnings.empty());  // first order requested on a nonlinear model: said

    const rs::Propagation p = rs::propagate_uncertainty(in, kOne, square);
    EXPECT_EQ(p.method, rs::PropagationMethod::MonteCarlo);
    EXPECT_NE(p.reason.find("second-order"), std::string::npos) << p.reason;
    EXPECT_NEAR(p.outputs[0]->uncertainty, std::sqrt(2.04), 0.03 * std::sqrt(2.04));
    // χ²(1) 95 % central quantiles ≈ 0.00098 and 5.02 (λ small): the interval is one-sided.
    EXPECT_GT(p.outputs[0]->interval95_low, -1e-9);
    EXPECT_NEAR(p.outputs[0]->interval95_high, 5.1, 0.3);
}

// A rectangular input of standard deviation u has half-width u√3: the 95 % interval of Y = X is
// ± 0.95 u√3.
TEST(Propagation, RectangularInputGivesItsQuantiles) {
    std::vector<rs::UncertainInput> in{{"x", 0.0, 1.0, rs::InputDistribution::Rectangular}};
    rs::PropagationOptions options;
    options.method = rs::PropagationMethod::MonteCarlo;
    const rs::Propagation p = rs::propagate_uncertainty(in, kOne, linear_model({1}), options);
    EXPECT_NEAR(p.outputs[0]->uncertainty, 1.0, 0.01);
    EXPECT_NEAR(p.outputs[0]->interval95_high, 0.95 * std::sqrt(3.0), 0.02);
    EXPECT_NEAR(p.outputs[0]->interval95_low, -0.95 * std::sqrt(3.0), 0.02);
}

// Trials without a value (Y = √X for X < 0) are counted and left out: P(X < 0) = Φ(−0.5) for
// X ~ N(0.5, 1); Auto switches to Monte Carlo because x − u has no value, and says so.
TEST(Propagation, TrialsWithoutAValueAreCountedAndSaid) {
    const std::vector<rs::UncertainInput> in{{"x", 0.5, 1.0}};
    const auto root = [](std::span<const double> x, std::span<std::optional<double>> y) {
        if (x[0] >= 0.0) y[0] = std::sqrt(x[0]);
    };
    const rs::Propagation p = rs::propagate_uncertainty(in, kOne, root);
    EXPECT_EQ(p.method, rs::PropagationMethod::MonteCarlo);
    EXPECT_NE(p.reason.find("no value"), std::string::npos) << p.reason;
    EXPECT_NEAR(p.outputs[0]->failed_fraction, 0.5 * std::erfc(0.5 / std::sqrt(2.0)), 0.01);
    bool said = false;
    for (const auto& w : p.warnings) said = said || w.find("no value") != std::string::npos;
    EXPECT_TRUE(said);
}

// The draws are a function of the seed alone: the same on 1 and 2 threads, another with another
// seed.
TEST(Propagation, MonteCarloIsReproducibleFromItsSeed) {
    const std::vector<rs::UncertainInput> in{{"x1", 1.0, 0.1}, {"x2", 2.0, 0.3}};
    rs::PropagationOptions options;
    options.method = rs::PropagationMethod::MonteCarlo;
    options.threads = 1;
    const auto a = rs::propagate_uncertainty(in, kOne, linear_model({3, -2}), options);
    options.threads = 2;
    const auto b = rs::propagate_uncertainty(in, kOne, linear_model({3, -2}), options);
    EXPECT_EQ(a.outputs[0]->uncertainty, b.outputs[0]->uncertainty);
    EXPECT_EQ(a.outputs[0]->interval95_low, b.outputs[0]->interval95_low);
    options.seed += 1;
    const auto c = rs::propagate_uncertainty(in, kOne, linear_model({3, -2}), options);
    EXPECT_NE(a.outputs[0]->uncertainty, c.outputs[0]->uncertainty);
}

// An output the model has no value for at x is absent; the others are there.
TEST(Propagation, AnOutputWithoutValueIsAbsent) {
    const std::vector<rs::UncertainInput> in{{"x", 1.0, 0.1}};
    const std::vector<std::string> names{"y", "none"};
    const auto model = [](std::span<const double> x, std::span<std::optional<double>> y) {
        y[0] = 2.0 * x[0];
        y[1] = std::nan("");
    };
    const auto p = rs::propagate_uncertainty(in, names, model);
    ASSERT_TRUE(p.outputs[0]);
    EXPECT_FALSE(p.outputs[1]);
    EXPECT_NEAR(p.outputs[0]->uncertainty, 0.2, 1e-12);
}

TEST(Propagation, BadInputIsRefusedWithItsName) {
    const auto model = linear_model({1});
    const std::vector<rs::UncertainInput> negative{{"black level", 1.0, -0.5}};
    try {
        rs::propagate_uncertainty(negative, kOne, model);
        FAIL();
    } catch (const rs::InvalidArgument& e) {
        EXPECT_NE(std::string(e.what()).find("black level"), std::string::npos) << e.what();
    }
    const std::vector<rs::UncertainInput> nan{{"x", std::nan(""), 0.5}};
    EXPECT_THROW(rs::propagate_uncertainty(nan, kOne, model), rs::InvalidArgument);
    const std::vector<rs::UncertainInput> ok{{"x", 1.0, 0.5}};
    rs::PropagationOptions options;
    options.batch_trials = 10;
    EXPECT_THROW(rs::propagate_uncertainty(ok, kOne, model, options), rs::InvalidArgument);
    EXPECT_EQ(rs::parse_propagation_method("Monte-Carlo"), rs::PropagationMethod::MonteCarlo);
    EXPECT_THROW(rs::parse_propagation_method("bootstrap"), rs::InvalidArgument);
}
