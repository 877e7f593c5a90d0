// SDF reading speed: decoding a binary ISO 25178-71 SDF of doubles held in memory, against the
// baseline of reading the same raw bytes into a fresh array of doubles (allocation + memcpy, the
// least any reader must do). Same sizes, same run; the ratio is decode time / baseline time
// (target: within 2x at 4096 x 4096).
//
//   build*/bin/roughscope_bench --benchmark_filter='sdf'
//
// Names: sdf_decode_binary_double/<n>   decode_sdf of an n x n map (n = 256 and 4096)
//        sdf_raw_bytes_baseline/<n>     std::vector<double>(n·n) + memcpy of the same data bytes
#include <cmath>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "roughscope/surface/formats.hpp"
#include "roughscope/surface/height_map.hpp"

namespace {

using namespace roughscope::surface;

constexpr std::size_t kSdfHeaderBytes = 81;

// The bytes of a binary SDF (double data) of an n x n map, made once per size.
const std::string& sdf_bytes(std::size_t n) {
    static std::map<std::size_t, std::string> cache;
    auto found = cache.find(n);
    if (found != cache.end()) return found->second;
    HeightMap map = make_height_map(n, n, 0.5, 0.5);
    for (std::size_t i = 0; i < map.size(); ++i) {
        map.heights_um[i] = std::sin(0.001 * static_cast<double>(i)) * 0.3;
    }
    return cache.emplace(n, formats::encode_sdf(map, {})).first->second;
}

void sdf_decode_binary_double(benchmark::State& state) {
    const auto n = static_cast<std::size_t>(state.range(0));
    const std::string& bytes = sdf_bytes(n);
    for (auto _ : state) {
        HeightMap map = formats::decode_sdf(bytes, "bench.sdf", {});
        benchmark::DoNotOptimize(map.heights_um.data());
    }
    state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * n * n * 8));
}

void sdf_raw_bytes_baseline(benchmark::State& state) {
    const auto n = static_cast<std::size_t>(state.range(0));
    const std::string& bytes = sdf_bytes(n);
    for (auto _ : state) {
        std::vector<double> heights(n * n);
        std::memcpy(heights.data(), bytes.data() + kSdfHeaderBytes, n * n * sizeof(double));
        benchmark::DoNotOptimize(heights.data());
    }
    state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * n * n * 8));
}

BENCHMARK(sdf_raw_bytes_baseline)->Arg(256)->Arg(4096)->Unit(benchmark::kMillisecond);
BENCHMARK(sdf_decode_binary_double)->Arg(256)->Arg(4096)->Unit(benchmark::kMillisecond);

}  // namespace
