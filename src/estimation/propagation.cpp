// Propagation of uncertainty: JCGM 100 §5.1 (first order) and JCGM 101 §7 (Monte Carlo), see
// propagation.hpp and docs/uncertainty.md.
#include "roughscope/estimation/propagation.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <utility>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/names.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/core/parallel.hpp"
#include "roughscope/core/text.hpp"

namespace roughscope {
namespace {

constexpr std::array<NameEntry<PropagationMethod>, 3> kMethodNames{{
    {"auto", PropagationMethod::Auto},
    {"first_order", PropagationMethod::FirstOrder},
    {"monte_carlo", PropagationMethod::MonteCarlo},
}};

// The coverage factor of a 95 % interval of a normal distribution (JCGM 100 §G.1.3).
constexpr double kCoverage95 = 1.959963984540054;
// Trials per random stream: a batch is cut into chunks of this many trials, each drawn from its
// own generator seeded by (seed, batch, chunk), so that the draws do not depend on the threads.
constexpr std::size_t kChunkTrials = 1000;

using Outputs = std::vector<std::optional<double>>;

Outputs evaluate(const PropagationModel& model, std::span<const double> x, std::size_t count) {
    Outputs y(count);
    model(x, y);
    for (auto& v : y)
        if (v && !std::isfinite(*v)) v.reset();
    return y;
}

void check_inputs(std::span<const UncertainInput> inputs, const PropagationOptions& options) {
    for (std::size_t i = 0; i < inputs.size(); ++i) {
        const UncertainInput& in = inputs[i];
        const std::string name =
            concat("uncertainty input ", std::to_string(i), " (", in.source, ")");
        if (in.source.empty())
            throw InvalidArgument(
                concat("uncertainty input ", std::to_string(i), ": no source named"));
        check::finite(concat(name, ": value"), in.value);
        check::non_negative(concat(name, ": u"), in.u);
    }
    if (options.batch_trials < 100)
        throw InvalidArgument(concat("propagation: batch_trials = ",
                                     std::to_string(options.batch_trials), " must be ≥ 100"));
    if (options.max_trials < options.batch_trials)
        throw InvalidArgument(
            concat("propagation: max_trials = ", std::to_string(options.max_trials),
                   " must be ≥ batch_trials = ", std::to_string(options.batch_trials)));
    if (options.significant_digits < 1 || options.significant_digits > 3)
        throw InvalidArgument(
            concat("propagation: significant_digits = ", std::to_string(options.significant_digits),
                   " must be 1, 2 or 3"));
    check::positive("propagation: nonlinearity_limit", options.nonlinearity_limit);
}

// First order (JCGM 100 §5.1.2): sensitivities by central differences over ± u(x_i), the
// combined u, and whether the model is near-linear: its second differences
// d_i = f(x + u e_i) + f(x − u e_i) − 2 f(x) ≈ f''u² give the second-order term
// Σ ½ d_i² of the variance (JCGM 100 §5.1.2 note, without the cross terms), which must stay
// below (limit · u_c)²; an input at whose x ± u the model has no value is nonlinear as well.
struct FirstOrder {
    std::vector<std::vector<BudgetLine>> budgets;  // per output
    std::vector<double> u;                         // per output (NaN: some sensitivity unknown)
    std::vector<std::string> nonlinear;            // per output: the reason, or empty
};

FirstOrder first_order(std::span<const UncertainInput> inputs, const PropagationModel& model,
                       const Outputs& y0, double limit) {
    const std::size_t n = y0.size();
    FirstOrder out;
    out.budgets.resize(n);
    out.u.assign(n, 0.0);
    out.nonlinear.resize(n);
    std::vector<double> second(n, 0.0);
    std::vector<double> x(inputs.size());
    for (std::size_t i = 0; i < inputs.size(); ++i) x[i] = inputs[i].value;
    for (std::size_t i = 0; i < inputs.size(); ++i) {
        const double u = inputs[i].u;
        if (!(u > 0.0)) continue;
        x[i] = inputs[i].value + u;
        const Outputs plus = evaluate(model, x, n);
        x[i] = inputs[i].value - u;
        const Outputs minus = evaluate(model, x, n);
        x[i] = inputs[i].value;
        for (std::size_t o = 0; o < n; ++o) {
            if (!y0[o]) continue;
            double c = std::numeric_limits<double>::quiet_NaN();
            if (plus[o] && minus[o]) {
                c = (*plus[o] - *minus[o]) / (2.0 * u);
                const double d = *plus[o] + *minus[o] - 2.0 * *y0[o];
                second[o] += 0.5 * d * d;
            } else if (plus[o] || minus[o]) {
                c = plus[o] ? (*plus[o] - *y0[o]) / u : (*y0[o] - *minus[o]) / u;
                out.nonlinear[o] = concat("no value at ", inputs[i].source, " ",
                                          plus[o] ? "−" : "+", " its uncertainty");
            } else {
                out.nonlinear[o] = concat("no value at ", inputs[i].source, " ± its uncertainty");
            }
            out.budgets[o].push_back(BudgetLine{inputs[i].source, u, c, std::abs(c) * u, 0.0});
        }
    }
    for (std::size_t o = 0; o < n; ++o) {
        double var = 0.0;
        for (const BudgetLine& line : out.budgets[o]) var += line.contribution * line.contribution;
        out.u[o] = std::sqrt(var);
        for (BudgetLine& line : out.budgets[o])
            line.fraction =
                var > 0.0 && std::isfinite(var) ? line.contribution * line.contribution / var : 0.0;
        std::stable_sort(out.budgets[o].begin(), out.budgets[o].end(),
                         [](const BudgetLine& a, const BudgetLine& b) {
                             return a.contribution > b.contribution;
                         });
        if (out.nonlinear[o].empty() && std::isfinite(var) && second[o] > limit * limit * var)
            out.nonlinear[o] = concat(
                "the second-order term is ", format_significant(std::sqrt(second[o] / var), 2),
                " of the first-order uncertainty (limit ", format_significant(limit, 2), ")");
    }
    return out;
}

// One batch of Monte Carlo trials: per output, the values of the trials that have one.
std::vector<std::vector<double>> monte_carlo_batch(std::span<const UncertainInput> inputs,
                                                   const PropagationModel& model,
                                                   std::size_t outputs,
                                                   const PropagationOptions& options,
                                                   std::size_t batch) {
    const std::size_t chunks = (options.batch_trials + kChunkTrials - 1) / kChunkTrials;
    std::vector<std::vector<std::vector<double>>> per_chunk(chunks);
    run_bands(chunks, options.threads, [&](std::size_t chunk) {
        std::seed_seq seq{static_cast<std::uint32_t>(options.seed),
                          static_cast<std::uint32_t>(options.seed >> 32U),
                          static_cast<std::uint32_t>(batch), static_cast<std::uint32_t>(chunk)};
        std::mt19937_64 rng(seq);
        std::normal_distribution<double> normal(0.0, 1.0);
        std::uniform_real_distribution<double> uniform(-1.0, 1.0);
        const std::size_t first = chunk * kChunkTrials;
        const std::size_t count = std::min(kChunkTrials, options.batch_trials - first);
        auto& values = per_chunk[chunk];
        values.resize(outputs);
        std::vector<double> x(inputs.size());
        Outputs y(outputs);
        for (std::size_t t = 0; t < count; ++t) {
            for (std::size_t i = 0; i < inputs.size(); ++i) {
                const UncertainInput& in = inputs[i];
                const double z = in.distribution == InputDistribution::Normal
                                     ? normal(rng)
                                     : std::sqrt(3.0) * uniform(rng);
                x[i] = in.value + in.u * z;
            }
            std::fill(y.begin(), y.end(), std::nullopt);
            model(x, y);
            for (std::size_t o = 0; o < outputs; ++o)
                if (y[o] && std::isfinite(*y[o])) values[o].push_back(*y[o]);
        }
    });
    std::vector<std::vector<double>> out(outputs);
    for (auto& chunk : per_chunk)
        for (std::size_t o = 0; o < outputs; ++o)
            out[o].insert(out[o].end(), chunk[o].begin(), chunk[o].end());
    return out;
}

// The estimate (mean), standard deviation and probabilistically symmetric 95 % interval of a set
// of values (JCGM 101 §7.6, §7.7); `values` is sorted on return.
struct Summary {
    double mean = 0.0;
    double sd = 0.0;
    double low = 0.0;
    double high = 0.0;
};

Summary summarise(std::vector<double>& values) {
    Summary s;
    const auto m = static_cast<double>(values.size());
    if (values.empty()) return s;
    double sum = 0.0;
    for (double v : values) sum += v;
    s.mean = sum / m;
    double ss = 0.0;
    for (double v : values) ss += (v - s.mean) * (v - s.mean);
    s.sd = values.size() > 1 ? std::sqrt(ss / (m - 1.0)) : 0.0;
    std::sort(values.begin(), values.end());
    // y_low = y_(r), y_high = y_(r + q) with q = pM and r = (M − q)/2 (JCGM 101 §7.7.2), 1-based.
    const auto q = static_cast<std::size_t>(std::llround(0.95 * m));
    const std::size_t r = std::max<std::size_t>(1, (values.size() - q) / 2);
    s.low = values[r - 1];
    s.high = values[std::min(values.size(), r + q) - 1];
    return s;
}

// Half a unit of the last of n_dig significant digits of u (JCGM 101 §7.9.2): the numerical
// tolerance δ of the adaptive procedure.
double numerical_tolerance(double u, int digits) {
    if (!(u > 0.0)) return 0.0;
    const double l = std::floor(std::log10(u)) - (digits - 1);
    return 0.5 * std::pow(10.0, l);
}

// The batch standard deviation of a sequence of per-batch results, as the standard deviation of
// their mean (JCGM 101 §7.9.4 c): s² = Σ (x_r − x̄)² / (h (h − 1)).
double batch_sd(const std::vector<double>& xs) {
    const auto h = static_cast<double>(xs.size());
    double mean = 0.0;
    for (double x : xs) mean += x;
    mean /= h;
    double ss = 0.0;
    for (double x : xs) ss += (x - mean) * (x - mean);
    return std::sqrt(ss / (h * (h - 1.0)));
}

struct MonteCarlo {
    std::vector<Summary> summaries;
    std::vector<std::size_t> valid;
    std::size_t trials = 0;
    bool stable = false;
};

MonteCarlo monte_carlo(std::span<const UncertainInput> inputs, const PropagationModel& model,
                       std::size_t outputs, const PropagationOptions& options) {
    MonteCarlo out;
    std::vector<std::vector<double>> all(outputs);
    // Per output, the per-batch estimate, u, low and high.
    std::vector<std::array<std::vector<double>, 4>> history(outputs);
    for (std::size_t batch = 0; out.trials + options.batch_trials <= options.max_trials; ++batch) {
        auto values = monte_carlo_batch(inputs, model, outputs, options, batch);
        out.trials += options.batch_trials;
        for (std::size_t o = 0; o < outputs; ++o) {
            all[o].insert(all[o].end(), values[o].begin(), values[o].end());
            const Summary s = summarise(values[o]);
            if (!values[o].empty())
                for (std::size_t k = 0; k < 4; ++k)
                    history[o][k].push_back(std::array{s.mean, s.sd, s.low, s.high}[k]);
        }
        if (batch == 0) continue;
        bool stable = true;
        for (std::size_t o = 0; o < outputs && stable; ++o) {
            if (history[o][0].size() < 2) continue;  // no value in any trial or batch
            const Summary s = summarise(all[o]);
            const double delta = numerical_tolerance(s.sd, options.significant_digits);
            for (std::size_t k = 0; k < 4 && stable; ++k)
                stable = 2.0 * batch_sd(history[o][k]) <= delta;
        }
        if (stable) {
            out.stable = true;
            break;
        }
    }
    for (std::size_t o = 0; o < outputs; ++o) {
        out.valid.push_back(all[o].size());
        out.summaries.push_back(summarise(all[o]));
    }
    return out;
}

}  // namespace

std::string_view to_string(PropagationMethod method) { return name_of(kMethodNames, method); }

PropagationMethod parse_propagation_method(std::string_view name) {
    return parse_name(kMethodNames, "uncertainty method", name);
}

Propagation propagate_uncertainty(std::span<const UncertainInput> inputs,
                                  std::span<const std::string> output_names,
                                  const PropagationModel& model,
                                  const PropagationOptions& options) {
    check_inputs(inputs, options);
    const std::size_t n = output_names.size();
    std::vector<double> x(inputs.size());
    for (std::size_t i = 0; i < inputs.size(); ++i) x[i] = inputs[i].value;
    const Outputs y0 = evaluate(model, x, n);
    const FirstOrder fo = first_order(inputs, model, y0, options.nonlinearity_limit);

    Propagation result;
    result.method = options.method == PropagationMethod::MonteCarlo ? PropagationMethod::MonteCarlo
                                                                    : PropagationMethod::FirstOrder;
    if (options.method == PropagationMethod::Auto) {
        for (std::size_t o = 0; o < n; ++o)
            if (y0[o] && !fo.nonlinear[o].empty()) {
                result.method = PropagationMethod::MonteCarlo;
                result.reason = concat(output_names[o], ": ", fo.nonlinear[o]);
                break;
            }
    }
    MonteCarlo mc;
    if (result.method == PropagationMethod::MonteCarlo) {
        mc = monte_carlo(inputs, model, n, options);
        if (!mc.stable)
            result.warnings.push_back(concat(
                "uncertainty: the Monte Carlo results did not stabilise to ",
                std::to_string(options.significant_digits), " significant digits of u within ",
                std::to_string(mc.trials), " trials (max_trials)"));
    }
    result.outputs.resize(n);
    for (std::size_t o = 0; o < n; ++o) {
        if (!y0[o]) continue;
        OutputUncertainty out;
        out.value = *y0[o];
        out.budget = fo.budgets[o];
        if (result.method == PropagationMethod::FirstOrder) {
            if (!fo.nonlinear[o].empty())
                result.warnings.push_back(concat("uncertainty of ", output_names[o], ": ",
                                                 fo.nonlinear[o],
                                                 "; first order was requested, the Monte Carlo "
                                                 "method would be more reliable"));
            if (!std::isfinite(fo.u[o])) {
                result.warnings.push_back(concat("uncertainty of ", output_names[o],
                                                 ": no first-order uncertainty (", fo.nonlinear[o],
                                                 ")"));
                continue;
            }
            out.uncertainty = fo.u[o];
            out.interval95_low = out.value - kCoverage95 * fo.u[o];
            out.interval95_high = out.value + kCoverage95 * fo.u[o];
        } else {
            const Summary& s = mc.summaries[o];
            out.trials = mc.trials;
            out.failed_fraction =
                1.0 - static_cast<double>(mc.valid[o]) / static_cast<double>(mc.trials);
            if (mc.valid[o] < 2) {
                result.warnings.push_back(concat("uncertainty of ", output_names[o],
                                                 ": no Monte Carlo trial gave a value"));
                continue;
            }
            out.uncertainty = s.sd;
            out.interval95_low = s.low;
            out.interval95_high = s.high;
            if (out.failed_fraction > 0.0)
                result.warnings.push_back(concat(
                    "uncertainty of ", output_names[o], ": ",
                    format_significant(100.0 * out.failed_fraction, 2),
                    " % of the Monte Carlo trials gave no value (outside the model's range) and "
                    "are left out: the interval is that of the trials with a value"));
        }
        result.outputs[o] = std::move(out);
    }
    return result;
}

}  // namespace roughscope
