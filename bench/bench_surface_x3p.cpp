// Reading a 4096² x3p held in memory (float64 binary, the layout encode_x3p writes: main.xml
// deflated, bindata/data.bin stored) against reading the same number of raw bytes.
//
//   build*/bin/roughscope_bench --benchmark_filter='x3p'
//
// Names: x3p/decode/<n>            formats::decode_x3p of the whole file (zip, XML, MD5 of
//                                  main.xml and of the 8·n² data bytes, conversion to µm)
//        x3p/raw_memcpy/<n>        baseline: memcpy of the 8·n² data bytes into a new buffer
//        x3p/raw_md5/<n>           baseline: one MD5 pass over the 8·n² bytes (the checksum
//                                  ISO 5436-2 requires a reader to verify)
// The counters time_vs_memcpy and time_vs_md5 of x3p/decode are its ratios to the baselines,
// timed in the same run. n = 4096 by default; n = 256 is registered for the smoke run.
#include <chrono>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <openssl/evp.h>

#include "roughscope/surface/formats.hpp"
#include "roughscope/surface/height_map.hpp"

namespace {

using namespace roughscope::surface;

const std::string& x3p_bytes(std::size_t n) {
    static std::size_t cached_n = 0;
    static std::string cached;
    if (cached_n != n) {
        HeightMap map = make_height_map(n, n, 0.5, 0.5);
        for (std::size_t i = 0; i < map.size(); ++i) {
            map.heights_um[i] =
                std::sin(0.001 * static_cast<double>(i)) + 1e-9 * static_cast<double>(i % 997);
        }
        cached = formats::encode_x3p(map, {});
        cached_n = n;
    }
    return cached;
}

double seconds_of(auto&& body, int repeats) {
    const auto start = std::chrono::steady_clock::now();
    for (int i = 0; i < repeats; ++i) body();
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() /
           repeats;
}

void raw_memcpy(std::vector<double>& out, const std::vector<double>& in) {
    out.resize(in.size());
    std::memcpy(out.data(), in.data(), in.size() * sizeof(double));
    benchmark::DoNotOptimize(out.data());
}

void raw_md5(const std::vector<double>& in) {
    unsigned char digest[EVP_MAX_MD_SIZE];
    unsigned int length = 0;
    EVP_Digest(in.data(), in.size() * sizeof(double), digest, &length, EVP_md5(), nullptr);
    benchmark::DoNotOptimize(digest);
}

void BM_x3p_decode(benchmark::State& state) {
    const auto n = static_cast<std::size_t>(state.range(0));
    const std::string& bytes = x3p_bytes(n);
    for (auto _ : state) {
        HeightMap map = formats::decode_x3p(bytes, "bench.x3p", {});
        benchmark::DoNotOptimize(map.heights_um.data());
    }
    const std::vector<double> raw(n * n, 1.0);
    std::vector<double> out;
    const double t_decode =
        seconds_of([&] { (void)formats::decode_x3p(bytes, "bench.x3p", {}); }, 1);
    const double t_memcpy = seconds_of([&] { raw_memcpy(out, raw); }, 3);
    const double t_md5 = seconds_of([&] { raw_md5(raw); }, 1);
    state.counters["time_vs_memcpy"] = t_decode / t_memcpy;
    state.counters["time_vs_md5"] = t_decode / t_md5;
    state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * n * n * sizeof(double)));
}

void BM_x3p_raw_memcpy(benchmark::State& state) {
    const auto n = static_cast<std::size_t>(state.range(0));
    const std::vector<double> raw(n * n, 1.0);
    std::vector<double> out;
    for (auto _ : state) raw_memcpy(out, raw);
    state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * n * n * sizeof(double)));
}

void BM_x3p_raw_md5(benchmark::State& state) {
    const auto n = static_cast<std::size_t>(state.range(0));
    const std::vector<double> raw(n * n, 1.0);
    for (auto _ : state) raw_md5(raw);
    state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * n * n * sizeof(double)));
}

}  // namespace

BENCHMARK(BM_x3p_decode)
    ->Name("x3p/decode")
    ->Arg(256)
    ->Arg(4096)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);
BENCHMARK(BM_x3p_raw_memcpy)
    ->Name("x3p/raw_memcpy")
    ->Arg(256)
    ->Arg(4096)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_x3p_raw_md5)->Name("x3p/raw_md5")->Arg(256)->Arg(4096)->Unit(benchmark::kMillisecond);
