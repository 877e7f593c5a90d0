// Core benchmarks: the B–K series sums (Eq. 2 and the exact exponential series) against the
// textbook summation, and the very-rough closed forms (Eq. 4, Eq. 5) against a Lambert baseline.
//
//   build*/bin/roughscope_bench --benchmark_filter='series|naive'     # series vs naive
//   build*/bin/roughscope_bench --benchmark_filter='very_rough|lambert'
//
// Names: series/<kind>/g=<g>            careful sum, one evaluation per iteration
//        naive/<kind>/g=<g>             the same sum by diffuse_series_sum_naive with
//                                       g + 10√g + 20 terms; only for g ≤ 700 (beyond, Σ gⁿ/n!
//                                       overflows and e^{−g} underflows: the series benchmark is
//                                       labelled "naive overflows" there)
//        lambert_baseline/1M            cos θi over 1M random geometries (the baseline)
//        very_rough/<eq>/<how>/1M       Eq. 4 / Eq. 5 over the same 1M geometries
//        very_rough/<eq>/batch/1M       the batch kernel (scattering/brightness_batch.hpp) over
//                                       the same geometries; its counters give the ratios
//                                       speedup_vs_scalar (very_rough_brightness in a loop, timed
//                                       in the same run) and time_vs_lambert (the baseline loop)
// items_per_second counts evaluations; divide times by the baseline's for ratios.
#include <chrono>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "bench_timing.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/brightness_batch.hpp"
#include "roughscope/scattering/factors.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/scattering/reflectance_models.hpp"

namespace {

using namespace roughscope;

constexpr double kNaiveMaxG = 700.0;  // e^{−g}·Σ gⁿ/n! stays finite below g ≈ 709

// T² v_xy² at which the sums are evaluated: X = g, a point inside the diffuse lobe (for Eq. 2 it
// is v_xy T/(σ v_z) = 1, i.e. exp(−1/4) of the peak of Eq. 4).
double lobe_X(double g) { return g; }

int naive_terms(double g) { return static_cast<int>(g + 10.0 * std::sqrt(g) + 20.0); }

void BM_series(benchmark::State& state, bool gaussian, double g) {
    const double X = lobe_X(g);
    // Alternate between two nearby X so that no call can be hoisted out of the loop.
    const double Xs[2] = {X, X * (1.0 + 1e-9)};
    std::size_t i = 0;
    for (auto _ : state) {
        const double x = Xs[i++ & 1];
        benchmark::DoNotOptimize(
            diffuse_series_sum(gaussian ? Correlation::Gaussian : Correlation::Exponential, g, x));
    }
    state.SetItemsProcessed(state.iterations());
    if (g > kNaiveMaxG) state.SetLabel("naive overflows");
}

void BM_naive(benchmark::State& state, bool gaussian, double g) {
    const double X = lobe_X(g);
    const double Xs[2] = {X, X * (1.0 + 1e-9)};
    const int terms = naive_terms(g);
    std::size_t i = 0;
    for (auto _ : state) {
        const double x = Xs[i++ & 1];
        benchmark::DoNotOptimize(diffuse_series_sum_naive(
            gaussian ? Correlation::Gaussian : Correlation::Exponential, g, x, terms));
    }
    state.SetItemsProcessed(state.iterations());
    state.counters["terms"] = terms;
}

std::string g_name(double g) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", g);
    return buf;
}

// Registered at static-initialisation time like BENCHMARK(); BENCHMARK_MAIN is in bench/main.cpp.
[[maybe_unused]] const bool kSeriesRegistered = [] {
    for (bool gaussian : {true, false}) {
        const std::string kind = gaussian ? "gaussian" : "exponential";
        for (double g : {1e-3, 1e-1, 1.0, 10.0, 1e2, 7e2, 1e3, 1e4, 1e5, 1e6}) {
            benchmark::RegisterBenchmark(("series/" + kind + "/g=" + g_name(g)).c_str(), BM_series,
                                         gaussian, g);
            if (g <= kNaiveMaxG)
                benchmark::RegisterBenchmark(("naive/" + kind + "/g=" + g_name(g)).c_str(),
                                             BM_naive, gaussian, g);
        }
    }
    return true;
}();

// ---------------------------------------------------------------------------------------------
// Very-rough closed forms over 1M random geometries.

constexpr std::size_t kGeometries = 1'000'000;

const std::vector<Geometry>& random_geometries() {
    static const std::vector<Geometry> geoms = [] {
        std::mt19937_64 rng(20070101);
        std::uniform_real_distribution<double> polar(0.0, deg_to_rad(85.0));
        std::uniform_real_distribution<double> azimuth(0.0, 2.0 * kPi);
        std::vector<Geometry> out(kGeometries);
        for (Geometry& g : out) g = Geometry{polar(rng), polar(rng), azimuth(rng)};
        return out;
    }();
    return geoms;
}

constexpr double kSigmaOverT = 0.3;

// Baseline: Lambert's cos θi at every geometry (the cheapest physically meaningful brightness).
void BM_lambert_baseline(benchmark::State& state) {
    const std::vector<Geometry>& geoms = random_geometries();
    for (auto _ : state) {
        double sum = 0.0;
        for (const Geometry& g : geoms) sum += std::cos(g.theta_i_rad);
        benchmark::DoNotOptimize(sum);
    }
    state.SetItemsProcessed(state.iterations() * geoms.size());
}
BENCHMARK(BM_lambert_baseline)->Name("lambert_baseline/1M")->Unit(benchmark::kMillisecond);

// The validated Lambert entry point, for comparison with the validated very-rough one.
void BM_lambert_api(benchmark::State& state) {
    const std::vector<Geometry>& geoms = random_geometries();
    for (auto _ : state) {
        double sum = 0.0;
        for (const Geometry& g : geoms) sum += lambert_brightness(g.theta_i_rad);
        benchmark::DoNotOptimize(sum);
    }
    state.SetItemsProcessed(state.iterations() * geoms.size());
}
BENCHMARK(BM_lambert_api)->Name("lambert_brightness/1M")->Unit(benchmark::kMillisecond);

// Inline shapes: scattering direction + F² (Vernold–Harvey) + Eq. 4 / Eq. 5 shape.
template <bool kGaussian>
void BM_very_rough_shape(benchmark::State& state) {
    const std::vector<Geometry>& geoms = random_geometries();
    for (auto _ : state) {
        double sum = 0.0;
        for (const Geometry& g : geoms) {
            const ScatteringDirection q = scattering_direction(g);
            const double F2 = geometric_factor_squared(GeometricFactor::VernoldHarvey, g);
            sum += very_rough_shape(kGaussian ? Correlation::Gaussian : Correlation::Exponential,
                                    F2, q, kSigmaOverT);
        }
        benchmark::DoNotOptimize(sum);
    }
    state.SetItemsProcessed(state.iterations() * geoms.size());
}
BENCHMARK(BM_very_rough_shape<true>)
    ->Name("very_rough/eq4/inline_shape/1M")
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_very_rough_shape<false>)
    ->Name("very_rough/eq5/inline_shape/1M")
    ->Unit(benchmark::kMillisecond);

// Validated API: very_rough_brightness (checks the angles and σ/T on every call).
template <bool kGaussian>
void BM_very_rough_brightness(benchmark::State& state) {
    const std::vector<Geometry>& geoms = random_geometries();
    const Correlation c = kGaussian ? Correlation::Gaussian : Correlation::Exponential;
    for (auto _ : state) {
        double sum = 0.0;
        for (const Geometry& g : geoms) sum += very_rough_brightness(g, kSigmaOverT, c);
        benchmark::DoNotOptimize(sum);
    }
    state.SetItemsProcessed(state.iterations() * geoms.size());
}
BENCHMARK(BM_very_rough_brightness<true>)
    ->Name("very_rough/eq4/very_rough_brightness/1M")
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_very_rough_brightness<false>)
    ->Name("very_rough/eq5/very_rough_brightness/1M")
    ->Unit(benchmark::kMillisecond);

// The batch kernel over the same geometries (structure of arrays), with the ratios to the scalar
// API and to the Lambert baseline measured in the same process, and time_vs_generic: the kernel
// in the processor's best build (core/target_clones.hpp, libmvec's exp) over its baseline build
// (std::exp), the best of 7 runs each, alternating.
template <bool kGaussian>
void BM_very_rough_batch(benchmark::State& state) {
    const std::vector<Geometry>& geoms = random_geometries();
    const Correlation c = kGaussian ? Correlation::Gaussian : Correlation::Exponential;
    std::vector<double> ti, ts, ps, out(geoms.size());
    for (const Geometry& g : geoms) {
        ti.push_back(g.theta_i_rad);
        ts.push_back(g.theta_s_rad);
        ps.push_back(g.phi_s_rad);
    }
    const std::vector<double> m = {kSigmaOverT};
    using Clock = std::chrono::steady_clock;
    auto seconds = [](Clock::duration d) { return std::chrono::duration<double>(d).count(); };
    // Baselines, timed once each with the same clock.
    auto t0 = Clock::now();
    double sum = 0.0;
    for (const Geometry& g : geoms) sum += very_rough_brightness(g, kSigmaOverT, c);
    const double scalar_s = seconds(Clock::now() - t0);
    t0 = Clock::now();
    for (const Geometry& g : geoms) sum += std::cos(g.theta_i_rad);
    const double lambert_s = seconds(Clock::now() - t0);
    benchmark::DoNotOptimize(sum);

    double batch_s = 0.0;
    std::size_t runs = 0;
    for (auto _ : state) {
        const auto t = Clock::now();
        very_rough_brightness_batch({ti, ts, ps, m}, out, {c});
        batch_s += seconds(Clock::now() - t);
        ++runs;
        benchmark::DoNotOptimize(out.data());
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(state.iterations() * geoms.size());
    if (runs > 0 && batch_s > 0.0) {
        const double per_run = batch_s / static_cast<double>(runs);
        state.counters["speedup_vs_scalar"] = scalar_s / per_run;
        state.counters["time_vs_lambert"] = per_run / lambert_s;
    }
    const auto [t_generic, t_best] = roughscope::bench::seconds_of_interleaved(
        [&] {
            set_vector_isa_cap(VectorIsa::Generic);
            very_rough_brightness_batch({ti, ts, ps, m}, out, {c});
        },
        [&] {
            set_vector_isa_cap(VectorIsa::Avx512);
            very_rough_brightness_batch({ti, ts, ps, m}, out, {c});
        },
        7);
    state.counters["time_vs_generic"] = t_best / t_generic;
    state.SetLabel(std::string(to_string(active_vector_isa())));
}
BENCHMARK(BM_very_rough_batch<true>)
    ->Name("very_rough/eq4/batch/1M")
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_very_rough_batch<false>)
    ->Name("very_rough/eq5/batch/1M")
    ->Unit(benchmark::kMillisecond);

}  // namespace
