// The least-squares engine (fit/engine.hpp) on a CUReT-sized problem: 205 measurements at
// pseudo-random geometries, V–H Gaussian very-rough brightness (Eq. 4, σ/T = 0.4) times a gain,
// 2 % multiplicative noise.
//
// Baseline in the same run: one evaluation of the model over the data set (205 calls of
// very_rough_brightness). Every fit reports
//   model_evals       model evaluations over the data set per fit (grid start + Ceres + Jacobian),
//   x_model_once      time per fit / time of the baseline (measured in the same process),
// so that the cost of a fit reads as "so many model evaluations' worth".
// Variants: the gain profiled out (variable projection, the default), the gain as a free
// parameter (what a robust loss needs), and the 2-parameter Oren–Nayar fit of the comparison.
#include <chrono>
#include <cmath>
#include <random>
#include <vector>

#include <benchmark/benchmark.h>

#include "roughscope/fit/engine.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/scattering/reflectance_models.hpp"

namespace {

namespace rs = roughscope;

struct Data {
    std::vector<rs::Geometry> geoms;
    std::vector<double> brightness;
};

const Data& data() {
    static const Data d = [] {
        Data out;
        std::mt19937_64 rng(2026);
        std::uniform_real_distribution<double> th(0.0, rs::deg_to_rad(75.0)),
            ph(0.0, 2.0 * rs::kPi);
        std::normal_distribution<double> noise(0.0, 0.02);
        for (int i = 0; i < 205; ++i) {
            const rs::Geometry g = rs::make_geometry(th(rng), th(rng), ph(rng));
            out.geoms.push_back(g);
            out.brightness.push_back(3.0 *
                                     rs::very_rough_brightness(g, 0.4, rs::Correlation::Gaussian) *
                                     (1.0 + noise(rng)));
        }
        return out;
    }();
    return d;
}

bool very_rough_model(std::span<const double> theta, std::span<double> out) {
    const Data& d = data();
    for (std::size_t i = 0; i < d.geoms.size(); ++i)
        out[i] = rs::very_rough_brightness(d.geoms[i], theta[0], rs::Correlation::Gaussian);
    return true;
}

bool oren_nayar_model(std::span<const double> theta, std::span<double> out) {
    const Data& d = data();
    for (std::size_t i = 0; i < d.geoms.size(); ++i)
        out[i] = rs::oren_nayar_radiance(d.geoms[i], {theta[0], theta[1]});
    return true;
}

// Seconds per evaluation of a model over the data set, measured once per process.
double seconds_per_model_call(bool (*model)(std::span<const double>, std::span<double>),
                              std::vector<double> theta) {
    std::vector<double> out(data().geoms.size());
    const int calls = 2000;
    const auto t0 = std::chrono::steady_clock::now();
    for (int k = 0; k < calls; ++k) {
        model(theta, out);
        benchmark::DoNotOptimize(out.data());
    }
    const std::chrono::duration<double> dt = std::chrono::steady_clock::now() - t0;
    return dt.count() / calls;
}

rs::ParameterSpec spec(const char* name, double lo, double hi, rs::Transform t, int grid) {
    rs::ParameterSpec s;
    s.name = name;
    s.lower = lo;
    s.upper = hi;
    s.transform = t;
    s.grid_points = grid;
    return s;
}

void BM_FitEngineBaseline_ModelOnce(benchmark::State& state) {
    std::vector<double> out(data().geoms.size());
    const std::vector<double> theta = {0.4};
    for (auto _ : state) {
        very_rough_model(theta, out);
        benchmark::DoNotOptimize(out.data());
    }
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(out.size()));
}
BENCHMARK(BM_FitEngineBaseline_ModelOnce);

template <class Solve>
void run_fit(benchmark::State& state, Solve&& solve, double baseline_seconds) {
    int evals = 0;
    const auto t0 = std::chrono::steady_clock::now();
    for (auto _ : state) {
        const rs::LeastSquaresResult r = solve();
        evals = r.evaluations;
        benchmark::DoNotOptimize(r.sse);
    }
    const std::chrono::duration<double> dt = std::chrono::steady_clock::now() - t0;
    state.counters["model_evals"] = evals;
    state.counters["x_model_once"] =
        dt.count() / static_cast<double>(state.iterations()) / baseline_seconds;
}

// Arg: 0 = gain profiled out (variable projection), 1 = gain as a free parameter.
void BM_FitEngine_VeryRoughSigmaOverT(benchmark::State& state) {
    rs::LeastSquaresProblem P;
    P.parameters = {spec("sigma_over_T", 0.01, 100.0, rs::Transform::Log, 41)};
    P.model = very_rough_model;
    P.data = data().brightness;
    P.residual = rs::ResidualType::Relative;
    P.gain = state.range(0) == 0 ? rs::GainMode::Profiled : rs::GainMode::Free;
    const double baseline = seconds_per_model_call(very_rough_model, {0.4});
    run_fit(
        state, [&] { return rs::solve_least_squares(P); }, baseline);
}
BENCHMARK(BM_FitEngine_VeryRoughSigmaOverT)
    ->ArgName("free_gain")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMicrosecond);

// The comparison's Oren–Nayar fit: 16 × 21 grid start, then Levenberg–Marquardt.
void BM_FitEngine_OrenNayar(benchmark::State& state) {
    rs::LeastSquaresProblem P;
    P.parameters = {spec("sigma_rad", 0.0, 1.5, rs::Transform::Linear, 16),
                    spec("albedo", 1e-3, 1.0, rs::Transform::Linear, 21)};
    P.model = oren_nayar_model;
    P.data = data().brightness;
    P.gain = rs::GainMode::Profiled;
    const double baseline = seconds_per_model_call(oren_nayar_model, {0.3, 0.8});
    run_fit(
        state, [&] { return rs::solve_least_squares(P); }, baseline);
}
BENCHMARK(BM_FitEngine_OrenNayar)->Unit(benchmark::kMicrosecond);

}  // namespace
