// Surface statistics benchmarks: surface_statistics on an n × n map against the FFTW transforms
// it needs, and the single-pass height moments against a plain read of the map, each pair in the
// same run.
//
//   build*/bin/roughscope_bench --benchmark_filter='surface_stats/'
//
// Names: surface_stats/statistics/<n>      surface_statistics (plane levelling, unbiased ACF,
//                                          curves kept) on an n × n map of AR(1) rows, T = 8 px
//        surface_stats/fftw_baseline/<n>   the real FFTs that call makes (same sizes, FFTW_ESTIMATE
//                                          plans): r2c + c2r of each zero-padded row and column,
//                                          and of the sub-profiles (L, L/2, L/4) of the 256 rows
//                                          the length extrapolation uses; the 2-D r2c + c2r of the
//                                          zero-padded map (acf_2d), the forward 2-D transform
//                                          (psd_radial) and the row transforms (psd_x); planning
//                                          excluded
//        surface_stats/moments/<n>         height_moments (Sq, Sa, Ssk, Sku, Sp, Sv, Sz)
//        surface_stats/memory_read/<n>     the sum of the map's heights (one plain pass)
// Ratio = statistics / fftw_baseline and moments / memory_read at the same n. n = 4096 is the
// size to quote; 512 keeps bench_smoke quick.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <map>
#include <vector>

#include <benchmark/benchmark.h>
#include <fftw3.h>

#include "roughscope/surface/height_map.hpp"
#include "roughscope/surface/statistics.hpp"

namespace {

using namespace roughscope::surface;

// An n × n map of AR(1) rows (correlation length 8 samples), built once per size.
const HeightMap& test_map(std::size_t n) {
    static std::map<std::size_t, HeightMap> cache;
    auto it = cache.find(n);
    if (it != cache.end()) return it->second;
    HeightMap m = make_height_map(n, n, 0.1, 0.1);
    const double phi = std::exp(-1.0 / 8.0);
    const double s = std::sqrt(1 - phi * phi);
    std::uint64_t state = 0x9E3779B97F4A7C15ULL;
    const auto uniform = [&state] {  // xorshift64*: cheap, fixed
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        return static_cast<double>((state * 2685821657736338717ULL) >> 11) * 0x1.0p-53 - 0.5;
    };
    for (std::size_t iy = 0; iy < n; ++iy) {
        double z = 0;
        for (std::size_t ix = 0; ix < n; ++ix) {
            z = phi * z + s * 3.4641 * uniform();                     // uniform of unit variance
            m.at(ix, iy) = z + 0.001 * static_cast<double>(ix + iy);  // plus a small tilt
        }
    }
    return cache.emplace(n, std::move(m)).first->second;
}

std::size_t friendly(std::size_t n) {
    for (std::size_t m = n;; ++m) {
        std::size_t r = m;
        for (std::size_t p : {2U, 3U, 5U})
            while (r % p == 0) r /= p;
        if (r == 1) return m;
    }
}

// `count` r2c + c2r transforms of a zero-padded line of `length` points.
struct LineTransforms {
    std::size_t nfft;
    double* real;
    fftw_complex* spec;
    fftw_plan fwd, bwd;
    explicit LineTransforms(std::size_t length) : nfft(friendly(2 * length - 1)) {
        real = fftw_alloc_real(nfft);
        spec = fftw_alloc_complex(nfft / 2 + 1);
        fwd = fftw_plan_dft_r2c_1d(static_cast<int>(nfft), real, spec, FFTW_ESTIMATE);
        bwd = fftw_plan_dft_c2r_1d(static_cast<int>(nfft), spec, real, FFTW_ESTIMATE);
        for (std::size_t k = 0; k < nfft; ++k) real[k] = 0;
    }
    ~LineTransforms() {
        fftw_destroy_plan(fwd);
        fftw_destroy_plan(bwd);
        fftw_free(real);
        fftw_free(spec);
    }
    LineTransforms(const LineTransforms&) = delete;
    LineTransforms& operator=(const LineTransforms&) = delete;
    void run(std::size_t count) {
        for (std::size_t i = 0; i < count; ++i) {
            fftw_execute(fwd);
            fftw_execute(bwd);
        }
    }
};

// One 2-D r2c (and, when `inverse`, c2r) transform of a rows × cols array (out of place).
struct PlaneTransforms {
    double* real;
    fftw_complex* spec;
    fftw_plan fwd, bwd;
    bool inverse;
    PlaneTransforms(std::size_t rows, std::size_t cols, bool with_inverse) : inverse(with_inverse) {
        real = fftw_alloc_real(rows * cols);
        spec = fftw_alloc_complex(rows * (cols / 2 + 1));
        fwd = fftw_plan_dft_r2c_2d(static_cast<int>(rows), static_cast<int>(cols), real, spec,
                                   FFTW_ESTIMATE);
        bwd = fftw_plan_dft_c2r_2d(static_cast<int>(rows), static_cast<int>(cols), spec, real,
                                   FFTW_ESTIMATE);
        for (std::size_t k = 0; k < rows * cols; ++k) real[k] = 0;
    }
    ~PlaneTransforms() {
        fftw_destroy_plan(fwd);
        fftw_destroy_plan(bwd);
        fftw_free(real);
        fftw_free(spec);
    }
    PlaneTransforms(const PlaneTransforms&) = delete;
    PlaneTransforms& operator=(const PlaneTransforms&) = delete;
    void run() {
        fftw_execute(fwd);
        if (inverse) fftw_execute(bwd);
    }
};

void BM_Statistics(benchmark::State& state) {
    const HeightMap& map = test_map(static_cast<std::size_t>(state.range(0)));
    for (auto _ : state) {
        SurfaceStatistics s = surface_statistics(map);
        benchmark::DoNotOptimize(s.sigma_um);
    }
    state.counters["points"] = static_cast<double>(map.size());
}

void BM_FftwBaseline(benchmark::State& state) {
    const auto n = static_cast<std::size_t>(state.range(0));
    LineTransforms full(n), half(n / 2), quarter(n / 4);
    const std::size_t extrapolation_rows = std::min<std::size_t>(n, 256);
    const std::size_t padded = friendly(2 * n - 1);
    PlaneTransforms acf_2d(padded, padded, true);  // spectral.hpp: acf_2d (no missing points)
    PlaneTransforms psd_2d(n, n, false);           // psd_radial: one forward transform
    PlaneTransforms psd_rows(1, n, false);         // psd_x: one forward transform per row
    for (auto _ : state) {
        acf_2d.run();
        psd_2d.run();
        for (std::size_t r = 0; r < n; ++r) psd_rows.run();
        full.run(n);                          // rows
        full.run(n);                          // columns (square map)
        full.run(extrapolation_rows);         // sub-profiles of L
        half.run(2 * extrapolation_rows);     // L/2
        quarter.run(4 * extrapolation_rows);  // L/4
        benchmark::ClobberMemory();
    }
}

void BM_Moments(benchmark::State& state) {
    const HeightMap& map = test_map(static_cast<std::size_t>(state.range(0)));
    for (auto _ : state) {
        HeightMoments m = height_moments(map);
        benchmark::DoNotOptimize(m);
    }
    state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) *
                            static_cast<std::int64_t>(map.size() * sizeof(double)));
}

void BM_MemoryRead(benchmark::State& state) {
    const HeightMap& map = test_map(static_cast<std::size_t>(state.range(0)));
    for (auto _ : state) {
        double sum = 0;
        for (double z : map.heights_um) sum += z;
        benchmark::DoNotOptimize(sum);
    }
    state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) *
                            static_cast<std::int64_t>(map.size() * sizeof(double)));
}

}  // namespace

BENCHMARK(BM_Statistics)
    ->Name("surface_stats/statistics")
    ->Arg(512)
    ->Arg(4096)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FftwBaseline)
    ->Name("surface_stats/fftw_baseline")
    ->Arg(512)
    ->Arg(4096)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Moments)
    ->Name("surface_stats/moments")
    ->Arg(512)
    ->Arg(4096)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MemoryRead)
    ->Name("surface_stats/memory_read")
    ->Arg(512)
    ->Arg(4096)
    ->Unit(benchmark::kMillisecond);
