// The CUReT comparison (paper §5.3) on the whole database: 61 samples × 205 measurements, every
// model including the least-squares fits. Target: ≤ 2 s on 2 cores.
//
// Baselines in the same run: the paper's methods only (no fits) on one thread, and loading the
// files. Compare BM_CuretAll/fits:1/threads:2 with BM_CuretAll/fits:0/threads:1 for the cost of
// the fits, and threads:1 vs threads:2 for the parallel speed-up.
//
// Data: ../shared/data/curet relative to the working directory, $ROUGHSCOPE_CURET, or
// <repo>/../shared/data/curet found from the executable (<repo>/<build>/bin/roughscope_bench).
// Without it the benchmarks report an error and do nothing.
#include <filesystem>
#include <optional>
#include <string>

#include <benchmark/benchmark.h>

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
    for (auto _ : state) benchmark::DoNotOptimize(roughscope::compare_curet_all(*db, o, threads));
    state.counters["samples"] = static_cast<double>(db->samples.size());
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
