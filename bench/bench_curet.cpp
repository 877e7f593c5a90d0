// The CUReT comparison (paper §5.3) on the whole database: 61 samples × 205 measurements, every
// model including the least-squares fits. Target: ≤ 2 s on 2 cores.
//
// Baselines in the same run: the paper's methods only (no fits) on one thread, and loading the
// files. Every BM_CuretAll run reports
//   x_paper_methods   its CPU time per comparison of the database / that of the paper's methods
//                     alone (fits:0, threads:1), the baseline measured in the same process;
// so BM_CuretAll/fits:1/threads:1 reads "the comparison with fits costs so many times the paper's
// methods" (target ≤ 3), and threads:1 vs threads:2 gives the parallel speed-up.
//
// Data: ../shared/data/curet relative to the working directory, $ROUGHSCOPE_CURET, or
// <repo>/../shared/data/curet found from the executable (<repo>/<build>/bin/roughscope_bench).
// Without it the benchmarks report an error and do nothing.
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <optional>
#include <string>

#include <benchmark/benchmark.h>
#include <time.h>

#include "roughscope/brdf/comparison.hpp"
#include "roughscope/brdf/curet.hpp"
#include "roughscope/core/errors.hpp"

namespace {

namespace fs = std::filesystem;

std::optional<fs::path> curet_directory() {
    try {
        return roughscope::find_curet_directory();
    } catch (const roughscope::DataError&) {
    }
    std::error_code ec;
    const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    if (ec) return std::nullopt;
    const fs::path candidate =
        exe.parent_path().parent_path().parent_path().parent_path() / "shared" / "data" / "curet";
    if (fs::exists(candidate / "abrdf.dat", ec) && fs::exists(candidate / "table.txt", ec))
        return candidate;
    return std::nullopt;
}

const roughscope::CuretDatabase* database() {
    static const std::optional<roughscope::CuretDatabase> db =
        []() -> std::optional<roughscope::CuretDatabase> {
        const auto dir = curet_directory();
        if (!dir) return std::nullopt;
        return roughscope::load_curet(*dir);
    }();
    return db ? &*db : nullptr;
}

void BM_CuretLoad(benchmark::State& state) {
    const auto dir = curet_directory();
    if (!dir) {
        state.SkipWithError("CUReT data not found (../shared/data/curet or $ROUGHSCOPE_CURET)");
        return;
    }
    for (auto _ : state) benchmark::DoNotOptimize(roughscope::load_curet(*dir));
}
BENCHMARK(BM_CuretLoad)->Unit(benchmark::kMillisecond);

// CPU seconds of this process (all threads).
double cpu_seconds() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// CPU seconds of the paper's methods alone (no fits, one thread) over the database: the best of
// five runs, measured once per process.
double paper_methods_cpu_seconds(const roughscope::CuretDatabase& db) {
    static const double seconds = [&db] {
        roughscope::ComparisonOptions o;
        o.fits = false;
        double best = 1e300;
        for (int k = 0; k < 5; ++k) {
            const double t0 = cpu_seconds();
            benchmark::DoNotOptimize(roughscope::compare_curet_all(db, o, 1));
            best = std::min(best, cpu_seconds() - t0);
        }
        return best;
    }();
    return seconds;
}

// Arg 0: fits (0/1); arg 1: threads.
void BM_CuretAll(benchmark::State& state) {
    const roughscope::CuretDatabase* db = database();
    if (!db) {
        state.SkipWithError("CUReT data not found (../shared/data/curet or $ROUGHSCOPE_CURET)");
        return;
    }
    roughscope::ComparisonOptions o;
    o.fits = state.range(0) != 0;
    const int threads = static_cast<int>(state.range(1));
    const double baseline = paper_methods_cpu_seconds(*db);
    const double t0 = cpu_seconds();
    for (auto _ : state) benchmark::DoNotOptimize(roughscope::compare_curet_all(*db, o, threads));
    const double per_run = (cpu_seconds() - t0) / static_cast<double>(state.iterations());
    state.counters["samples"] = static_cast<double>(db->samples.size());
    state.counters["x_paper_methods"] = per_run / baseline;
}
BENCHMARK(BM_CuretAll)
    ->ArgNames({"fits", "threads"})
    ->Args({0, 1})
    ->Args({1, 1})
    ->Args({1, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// One sample with everything (the unit of work of --all).
void BM_CuretSample25(benchmark::State& state) {
    const roughscope::CuretDatabase* db = database();
    if (!db) {
        state.SkipWithError("CUReT data not found (../shared/data/curet or $ROUGHSCOPE_CURET)");
        return;
    }
    for (auto _ : state) benchmark::DoNotOptimize(roughscope::compare_curet_sample(*db, 25));
}
BENCHMARK(BM_CuretSample25)->Unit(benchmark::kMillisecond);

}  // namespace
