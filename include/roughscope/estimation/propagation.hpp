// Propagation of uncertainty through a measurement model Y = f(X) (docs/uncertainty.md): the law
// of propagation of uncertainty of the GUM (JCGM 100:2008, §5.1, first order, uncorrelated
// inputs) and its Monte Carlo supplement (JCGM 101:2008, §7, with the adaptive procedure of §7.9).
//
// Inputs are independent by construction: an effect shared by several quantities (one protractor
// read for two lights, one black level for every photograph) is ONE input whose change the model
// applies to each of them, so the correlation it causes between them is carried by the model
// (JCGM 100 §F.1.2.4, "common effects") rather than by a correlation matrix.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace roughscope {

// The probability density of an input (JCGM 101 §6.4): a normal of standard deviation u, or a
// rectangular of half-width u√3 (standard deviation u), both centred on the input's value.
enum class InputDistribution { Normal, Rectangular };

struct UncertainInput {
    std::string source;  // what it is, for the budget: "theta_i of capture 2"
    double value = 0.0;  // the best estimate x_i
    double u = 0.0;      // its standard uncertainty u(x_i), finite and ≥ 0 (0: a constant)
    InputDistribution distribution = InputDistribution::Normal;
};

enum class PropagationMethod { Auto, FirstOrder, MonteCarlo };
std::string_view to_string(PropagationMethod method);  // "auto", "first_order", "monte_carlo"
PropagationMethod parse_propagation_method(std::string_view name);

struct PropagationOptions {
    // Auto: first order unless the model is not near-linear over ± u of an input (a second-order
    // term above nonlinearity_limit · u_c, or no value at x ± u), then Monte Carlo.
    PropagationMethod method = PropagationMethod::Auto;
    double nonlinearity_limit = 0.1;
    std::uint64_t seed = 20080901;  // the Monte Carlo draws are a function of the seed alone
    // Monte Carlo: trials per batch, M = max(100/(1 − p), 10⁴) for p = 95 % (JCGM 101 §7.2.2);
    // batches are added until the estimate, u and both interval ends are stable to half a unit
    // of the 2nd significant digit of u (JCGM 101 §7.9.2, n_dig = significant_digits), or until
    // max_trials (then a warning).
    std::size_t batch_trials = 10'000;
    std::size_t max_trials = 200'000;
    int significant_digits = 2;
    std::size_t threads = 0;  // 0: every core; the result does not depend on it
};

// The model: writes y = f(x), one value per output; std::nullopt (or a non-finite value) where
// it has none at x (e.g. a brightness ratio outside a model's range). Called from several
// threads at once in the Monte Carlo method: it must not change shared state.
using PropagationModel =
    std::function<void(std::span<const double> x, std::span<std::optional<double>> y)>;

// One input's share of an output's uncertainty (JCGM 100 §5.1.3): sensitivity c_i = ∂f/∂x_i (by
// the central difference over x_i ± u(x_i), JCGM 100 §5.1.3 note 2), contribution u_i(y) =
// |c_i| u(x_i), fraction u_i(y)² / Σ u_j(y)².
struct BudgetLine {
    std::string source;
    double u_input = 0.0;
    double sensitivity = 0.0;
    double contribution = 0.0;
    double fraction = 0.0;
};

struct OutputUncertainty {
    double value = 0.0;              // y = f(x)
    double uncertainty = 0.0;        // u(y), k = 1
    double interval95_low = 0.0;     // the 95 % coverage interval: y ± 1.96 u(y) (first order) or
    double interval95_high = 0.0;    // the probabilistically symmetric one (Monte Carlo)
    std::vector<BudgetLine> budget;  // inputs with u > 0, largest contribution first
    // Monte Carlo only: trials run, and the fraction of them without a value (left out).
    std::size_t trials = 0;
    double failed_fraction = 0.0;
};

struct Propagation {
    PropagationMethod method = PropagationMethod::FirstOrder;  // as used: first order or MC
    std::string reason;  // why Monte Carlo was used (Auto), else empty
    std::vector<std::optional<OutputUncertainty>> outputs;  // nullopt: f(x) has no value
    std::vector<std::string> warnings;
};

// Propagates the inputs' uncertainties to the model's outputs, one per name (the names are for
// the warnings). Throws
// InvalidArgument for an input with a non-finite value or a negative or non-finite u, an empty
// source, or options out of range (batch_trials < 100, max_trials < batch_trials, digits not 1–3).
Propagation propagate_uncertainty(std::span<const UncertainInput> inputs,
                                  std::span<const std::string> output_names,
                                  const PropagationModel& model,
                                  const PropagationOptions& options = {});

}  // namespace roughscope
