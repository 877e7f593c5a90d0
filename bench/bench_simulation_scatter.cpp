// The Kirchhoff Monte Carlo (simulation/kirchhoff.hpp) against the FFT it needs, in the same run.
//
//   build*/bin/roughscope_bench --benchmark_filter='simulation/'
//
// Names: simulation/complex_fft/<n>          the baseline: one in-place n × n complex FFTW
//                                            transform (FFTW_ESTIMATE, as the library plans it)
//        simulation/lattice/<n>              scattering_integral_lattice of an n × n map for one
//                                            v_z: exp(i v_z z), the FFT, the centred-coordinate
//                                            phases; counter time_vs_fft = its time over the
//                                            baseline's (target ≤ 1.5)
//        simulation/direct_one_direction/<n> scattering_integral_at: one direction by direct
//                                            summation; counter lattice_speedup = n² directions
//                                            × this time / the lattice's time
//        simulation/ensemble_200/<n>         simulate_scattering at one geometry, 200
//                                            realisations on 2 threads (wall time: the figure a
//                                            user waits for)
// Times are processor time (manual time) except the ensemble's.
#include <chrono>
#include <complex>
#include <cstddef>
#include <cstring>
#include <ctime>
#include <map>
#include <string>

#include <benchmark/benchmark.h>
#include <fftw3.h>

#include "roughscope/scattering/geometry.hpp"
#include "roughscope/simulation/kirchhoff.hpp"
#include "roughscope/surface/generate.hpp"

namespace {

using namespace roughscope;

double cpu_seconds() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

double run_complex_fft(std::size_t n) {
    auto* data = static_cast<fftw_complex*>(fftw_malloc(n * n * sizeof(fftw_complex)));
    const double start = cpu_seconds();
    const fftw_plan plan = fftw_plan_dft_2d(static_cast<int>(n), static_cast<int>(n), data, data,
                                            FFTW_FORWARD, FFTW_ESTIMATE);
    for (std::size_t k = 0; k < n * n; ++k) {
        data[k][0] = 1.0;
        data[k][1] = 0.0;
    }
    fftw_execute(plan);
    benchmark::DoNotOptimize(data[0][0]);
    const double t = cpu_seconds() - start;
    fftw_destroy_plan(plan);
    fftw_free(data);
    return t;
}

double baseline_seconds(std::size_t n) {
    static std::map<std::size_t, double> cache;
    const auto it = cache.find(n);
    if (it != cache.end()) return it->second;
    double best = run_complex_fft(n);
    for (int i = 1; i < 3; ++i) best = std::min(best, run_complex_fft(n));
    return cache[n] = best;
}

surface::HeightMap map_of(std::size_t n) {
    surface::GenerationOptions o;
    o.sigma_um = 0.1;
    o.T_um = 8.0;
    o.nx = o.ny = n;
    o.dx_um = o.dy_um = 1.0;
    return surface::generate_surface(o);
}

double lattice_seconds(const surface::HeightMap& map) {
    const double start = cpu_seconds();
    benchmark::DoNotOptimize(simulation::scattering_integral_lattice(map, -20.0));
    return cpu_seconds() - start;
}

void complex_fft(benchmark::State& state) {
    const auto n = static_cast<std::size_t>(state.range(0));
    for (auto _ : state) state.SetIterationTime(run_complex_fft(n));
}

void lattice(benchmark::State& state) {
    const auto n = static_cast<std::size_t>(state.range(0));
    const surface::HeightMap map = map_of(n);
    const double baseline = baseline_seconds(n);
    double total = 0;
    for (auto _ : state) {
        const double t = lattice_seconds(map);
        state.SetIterationTime(t);
        total += t;
    }
    state.counters["time_vs_fft"] = total / static_cast<double>(state.iterations()) / baseline;
}

void direct_one_direction(benchmark::State& state) {
    const auto n = static_cast<std::size_t>(state.range(0));
    const surface::HeightMap map = map_of(n);
    double lattice_best = lattice_seconds(map);
    for (int i = 1; i < 3; ++i) lattice_best = std::min(lattice_best, lattice_seconds(map));
    double total = 0;
    for (auto _ : state) {
        const double start = cpu_seconds();
        benchmark::DoNotOptimize(simulation::scattering_integral_at(map, {0.3, 0.1, -20.0}));
        const double t = cpu_seconds() - start;
        state.SetIterationTime(t);
        total += t;
    }
    const double per_direction = total / static_cast<double>(state.iterations());
    state.counters["lattice_speedup"] =
        static_cast<double>(n) * static_cast<double>(n) * per_direction / lattice_best;
}

void ensemble_200(benchmark::State& state) {
    simulation::ScatterOptions o;
    o.sigma_um = 0.05;
    o.T_um = 1.0;
    o.wavelength_um = 0.5;
    o.n = static_cast<std::size_t>(state.range(0));
    o.dx_um = 16.0 / static_cast<double>(o.n);
    o.realisations = 200;
    o.threads = 2;
    const Geometry geom = make_geometry(deg_to_rad(30.0), 0.0, 0.0);
    for (auto _ : state) {
        const auto start = std::chrono::steady_clock::now();
        benchmark::DoNotOptimize(simulation::simulate_scattering(geom, o));
        state.SetIterationTime(
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
}

BENCHMARK(complex_fft)
    ->Name("simulation/complex_fft")
    ->Arg(256)
    ->Arg(1024)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(lattice)
    ->Name("simulation/lattice")
    ->Arg(256)
    ->Arg(1024)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(direct_one_direction)
    ->Name("simulation/direct_one_direction")
    ->Arg(256)
    ->Arg(1024)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);
// 512: the size the figure is reported for; the smoke run (ctest bench_smoke) skips /4096 only,
// so the ensemble is registered at 64 too and the 512 one is named /4096-free but long (~3 s).
BENCHMARK(ensemble_200)
    ->Name("simulation/ensemble_200")
    ->Arg(64)
    ->Arg(512)
    ->Iterations(1)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace
