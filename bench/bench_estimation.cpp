// Estimators of §4 (estimation.hpp) and least-squares fits (fit.hpp).
//
// Per call: the closed forms Eq. 13, 15, 17, 19 against the numeric two-geometry solver (TOMS 748)
// on the same inputs — the closed forms are the baseline, so the ratio solver/closed form is the
// price of leaving the normal-view setup. The solver on a general geometry and on the exact series
// (moderately rough surfaces) is measured too.
//
// Fits: 205 measurements (the size of a CUReT sample) at pseudo-random geometries, 1 % noise.
// Baseline in the same run: an exhaustive 1-D search over σ/T (1000 log-spaced values, gain
// profiled out — the kind of search the paper uses for the Lafortune exponent, §5.3), which gives
// no uncertainty; the Ceres fit should be faster and returns the covariance.
#include <cmath>
#include <random>
#include <vector>

#include <benchmark/benchmark.h>

#include "roughscope/estimation/estimation.hpp"
#include "roughscope/fit/fit.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/geometry.hpp"

namespace {

namespace rs = roughscope;

const double kT1 = rs::deg_to_rad(30.0), kT2 = rs::deg_to_rad(45.0);

// A spread of valid ratios for both correlations at 30°/45° (inside (1.025, 3.79)).
std::vector<double> ratios() {
    std::vector<double> r;
    for (int i = 0; i < 64; ++i) r.push_back(1.03 + 0.02 * i);
    return r;
}

void BM_Eq17_GaussianClosedForm(benchmark::State& state) {
    const auto r = ratios();
    std::size_t i = 0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(
            rs::sigma_over_T_from_ratio(rs::Correlation::Gaussian, r[i++ & 63], kT1, kT2));
    }
}
BENCHMARK(BM_Eq17_GaussianClosedForm);

void BM_Eq19_ExponentialClosedForm(benchmark::State& state) {
    const auto r = ratios();
    std::size_t i = 0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(
            rs::sigma_over_T_from_ratio(rs::Correlation::Exponential, r[i++ & 63], kT1, kT2));
    }
}
BENCHMARK(BM_Eq19_ExponentialClosedForm);

// The numeric solver on exactly the inputs of Eq. 17 / 19 (normal view).
void BM_SolverNormalView(benchmark::State& state) {
    const auto c = state.range(0) == 0 ? rs::Correlation::Gaussian : rs::Correlation::Exponential;
    const auto g1 = rs::normal_view_geometry(kT1), g2 = rs::normal_view_geometry(kT2);
    const auto r = ratios();
    std::size_t i = 0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(rs::sigma_over_T_two_geometries(r[i++ & 63], g1, g2, c));
    }
    state.SetLabel(c == rs::Correlation::Gaussian ? "gaussian (vs Eq. 17)"
                                                  : "exponential (vs Eq. 19)");
}
BENCHMARK(BM_SolverNormalView)->Arg(0)->Arg(1);

// A general pair of geometries (θs ≠ 0, φs ≠ 0).
void BM_SolverGeneralGeometry(benchmark::State& state) {
    const auto c = state.range(0) == 0 ? rs::Correlation::Gaussian : rs::Correlation::Exponential;
    const auto g1 = rs::make_geometry(rs::deg_to_rad(20), rs::deg_to_rad(35), rs::deg_to_rad(120));
    const auto g2 = rs::make_geometry(rs::deg_to_rad(55), rs::deg_to_rad(10), rs::deg_to_rad(40));
    std::vector<double> r;
    for (double s = 0.1; s < 3.0; s *= 1.06)
        r.push_back(rs::very_rough_brightness(g1, s, c) / rs::very_rough_brightness(g2, s, c));
    std::size_t i = 0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(rs::sigma_over_T_two_geometries(r[i++ % r.size()], g1, g2, c));
    }
    state.SetLabel(c == rs::Correlation::Gaussian ? "gaussian" : "exponential");
}
BENCHMARK(BM_SolverGeneralGeometry)->Arg(0)->Arg(1);

void BM_Eq13_SigmaFromSpecular(benchmark::State& state) {
    double R = 0.001;
    for (auto _ : state) {
        benchmark::DoNotOptimize(rs::sigma_from_specular(R, rs::deg_to_rad(14), 0.555));
        R = R < 0.5 ? R * 1.01 : 0.001;
    }
}
BENCHMARK(BM_Eq13_SigmaFromSpecular);

void BM_Eq15_CorrelationLengthClosedForm(benchmark::State& state) {
    const auto r = ratios();
    std::size_t i = 0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(
            rs::correlation_length_from_ratio(r[i++ & 63], 0.094, kT1, kT2, 0.555));
    }
}
BENCHMARK(BM_Eq15_CorrelationLengthClosedForm);

// T by the solver: arg 0 = Eq. 3 (same as Eq. 15), 1 = the exact series (moderately rough).
void BM_SolverCorrelationLength(benchmark::State& state) {
    rs::TwoGeometryOptions o;
    o.regime = state.range(0) == 0 ? rs::Regime::SlightlyRough : rs::Regime::Series;
    const auto g1 = rs::normal_view_geometry(kT1), g2 = rs::normal_view_geometry(kT2);
    std::vector<double> r;  // ratios of T = 0.1 ... 1 µm in the same regime
    for (double T = 0.1; T < 1.0; T *= 1.04)
        r.push_back(rs::model_ratio_diffuse(g1, g2, 0.094, T, rs::Correlation::Gaussian, o));
    std::size_t i = 0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(rs::correlation_length_two_geometries(
            r[i++ % r.size()], g1, g2, 0.094, rs::Correlation::Gaussian, o));
    }
    state.SetLabel(state.range(0) == 0 ? "Eq. 3 (vs Eq. 15)" : "exact series");
}
BENCHMARK(BM_SolverCorrelationLength)->Arg(0)->Arg(1);

// ---- 205-point fits -----------------------------------------------------------------------

std::vector<rs::Measurement> data205(rs::Correlation c, double s) {
    std::mt19937_64 rng(205);
    std::uniform_real_distribution<double> th(0.0, rs::deg_to_rad(75.0)), ph(0.0, 2.0 * rs::kPi);
    std::normal_distribution<double> n01;
    std::vector<rs::Measurement> ms;
    for (int i = 0; i < 205; ++i) {
        const auto g = rs::make_geometry(th(rng), th(rng), ph(rng));
        ms.push_back({g, 50.0 * rs::very_rough_brightness(g, s, c) * (1 + 0.01 * n01(rng)), 1.0});
    }
    return ms;
}

void BM_Fit205(benchmark::State& state) {
    const auto c = state.range(0) == 0 ? rs::Correlation::Gaussian : rs::Correlation::Exponential;
    const auto ms = data205(c, 0.4);
    rs::FitOptions o;
    o.correlation = c;
    for (auto _ : state) {
        const auto r = rs::fit_roughness(ms, o);
        benchmark::DoNotOptimize(r.sse);
    }
    state.SetLabel(c == rs::Correlation::Gaussian ? "very rough, gaussian"
                                                  : "very rough, exponential");
}
BENCHMARK(BM_Fit205)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

void BM_Fit205_CompareCorrelations(benchmark::State& state) {
    const auto ms = data205(rs::Correlation::Gaussian, 0.4);
    for (auto _ : state) benchmark::DoNotOptimize(rs::compare_correlations(ms).delta_aic);
}
BENCHMARK(BM_Fit205_CompareCorrelations)->Unit(benchmark::kMicrosecond);

void BM_Fit205_SlightlyRough(benchmark::State& state) {
    std::mt19937_64 rng(206);
    std::uniform_real_distribution<double> th(0.0, rs::deg_to_rad(75.0)), ph(0.0, 2.0 * rs::kPi);
    rs::ModelOptions mo;
    mo.regime = rs::Regime::SlightlyRough;
    std::vector<rs::Measurement> ms;
    for (int i = 0; i < 205; ++i) {
        const auto g = rs::make_geometry(th(rng), th(rng), ph(rng));
        ms.push_back(
            {g, rs::mean_scattered_power(g, {0.03, 0.4, rs::Correlation::Gaussian}, mo).diffuse,
             1.0});
    }
    rs::FitOptions o;
    o.model = rs::FitModel::SlightlyRough;
    for (auto _ : state) benchmark::DoNotOptimize(rs::fit_roughness(ms, o).sse);
}
BENCHMARK(BM_Fit205_SlightlyRough)->Unit(benchmark::kMicrosecond);

// Baseline: exhaustive search over 1000 log-spaced σ/T in [1e-2, 1e2] with the gain profiled out
// (relative residuals, as the fit); no uncertainty.
void BM_Fit205_GridSearchBaseline(benchmark::State& state) {
    const auto c = state.range(0) == 0 ? rs::Correlation::Gaussian : rs::Correlation::Exponential;
    const auto ms = data205(c, 0.4);
    std::vector<double> B(ms.size());
    for (auto _ : state) {
        double best = 1e300, best_s = 0.0;
        for (int k = 0; k < 1000; ++k) {
            const double s = std::pow(10.0, -2.0 + 4.0 * k / 999.0);
            double num = 0.0, den = 0.0;
            for (std::size_t i = 0; i < ms.size(); ++i) {
                B[i] = rs::very_rough_brightness(ms[i].geometry, s, c);
                num += B[i] / ms[i].brightness;
                den += B[i] * B[i] / (ms[i].brightness * ms[i].brightness);
            }
            const double K = num / den;
            double sse = 0.0;
            for (std::size_t i = 0; i < ms.size(); ++i) {
                const double r = (K * B[i] - ms[i].brightness) / ms[i].brightness;
                sse += r * r;
            }
            if (sse < best) {
                best = sse;
                best_s = s;
            }
        }
        benchmark::DoNotOptimize(best_s);
    }
    state.SetLabel(c == rs::Correlation::Gaussian ? "gaussian" : "exponential");
}
BENCHMARK(BM_Fit205_GridSearchBaseline)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

}  // namespace
