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
//        x3p/decode_unverified/<n> the same without the MD5 passes (--no-verify-checksums)
//        x3p/decode_deflated/<n>   the same file with data.bin deflated (as instruments write
//                                  it); its counter time_vs_inflate is the ratio to
//        x3p/raw_inflate/<n>       baseline: libzip's decompression of that data.bin alone
// The counters time_vs_memcpy and time_vs_md5 of x3p/decode are its ratios to the baselines,
// timed in the same run. n = 4096 and 256 for the stored file; the deflated variant runs at
// n = 1024 and 256 (deflating 128 MiB to build its input would dominate the smoke run, and the
// ratio to inflate does not depend on n).
#include <chrono>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <openssl/evp.h>
#include <zip.h>

#include "roughscope/core/memory.hpp"
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

// `stored` (an x3p of encode_x3p) with every member deflated, by plain libzip calls.
std::string deflated_copy(const std::string& stored) {
    zip_error_t error;
    zip_error_init(&error);
    zip_t* in = zip_open_from_source(
        zip_source_buffer_create(stored.data(), stored.size(), 0, &error), ZIP_RDONLY, &error);
    zip_source_t* buffer = zip_source_buffer_create(nullptr, 0, 0, &error);
    zip_source_keep(buffer);
    zip_t* out = zip_open_from_source(buffer, ZIP_TRUNCATE, &error);
    std::vector<std::string> contents;
    contents.reserve(8);
    for (zip_int64_t i = 0; i < zip_get_num_entries(in, 0); ++i) {
        const auto index = static_cast<zip_uint64_t>(i);
        zip_stat_t st;
        zip_stat_index(in, index, 0, &st);
        std::string& data = contents.emplace_back(st.size, '\0');
        zip_file_t* f = zip_fopen_index(in, index, 0);
        zip_fread(f, data.data(), data.size());
        zip_fclose(f);
        const zip_int64_t added =
            zip_file_add(out, st.name, zip_source_buffer(out, data.data(), data.size(), 0), 0);
        zip_set_file_compression(out, static_cast<zip_uint64_t>(added), ZIP_CM_DEFLATE, 1);
    }
    zip_close(out);
    zip_discard(in);
    zip_stat_t st;
    zip_source_stat(buffer, &st);
    zip_source_open(buffer);
    std::string bytes(st.size, '\0');
    zip_source_read(buffer, bytes.data(), bytes.size());
    zip_source_close(buffer);
    zip_source_free(buffer);
    zip_error_fini(&error);
    return bytes;
}

const std::string& deflated_bytes(std::size_t n) {
    static std::size_t cached_n = 0;
    static std::string cached;
    if (cached_n != n) {
        cached = deflated_copy(x3p_bytes(n));
        cached_n = n;
    }
    return cached;
}

// Decompresses bindata/data.bin of `bytes` into `out` (libzip only: no XML, no checksum).
void raw_inflate(const std::string& bytes, std::vector<char>& out) {
    zip_error_t error;
    zip_error_init(&error);
    zip_t* z = zip_open_from_source(zip_source_buffer_create(bytes.data(), bytes.size(), 0, &error),
                                    ZIP_RDONLY, &error);
    zip_stat_t st;
    zip_stat(z, "bindata/data.bin", 0, &st);
    out.resize(st.size);
    zip_file_t* f = zip_fopen(z, "bindata/data.bin", 0);
    zip_fread(f, out.data(), out.size());
    zip_fclose(f);
    zip_discard(z);
    zip_error_fini(&error);
    benchmark::DoNotOptimize(out.data());
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

// The same without verifying the checksums (HeightReadOptions::x3p_verify_checksums = false,
// CLI --no-verify-checksums): the zip, the XML and the conversion only. time_vs_memcpy as above;
// time_vs_fresh_copy against a memcpy of the bytes into newly allocated storage with the
// library's large-buffer policy (core/memory.hpp), as any reader's result is.
void BM_x3p_decode_unverified(benchmark::State& state) {
    const auto n = static_cast<std::size_t>(state.range(0));
    const std::string& bytes = x3p_bytes(n);
    HeightReadOptions unverified;
    unverified.x3p_verify_checksums = false;
    for (auto _ : state) {
        HeightMap map = formats::decode_x3p(bytes, "bench.x3p", unverified);
        benchmark::DoNotOptimize(map.heights_um.data());
    }
    const std::vector<double> raw(n * n, 1.0);
    std::vector<double> out;
    const double t_decode =
        seconds_of([&] { (void)formats::decode_x3p(bytes, "bench.x3p", unverified); }, 3);
    const double t_memcpy = seconds_of([&] { raw_memcpy(out, raw); }, 3);
    const double t_fresh = seconds_of(
        [&] {
            std::vector<double> fresh;
            roughscope::assign_large(fresh, raw.size(), 0.0);
            std::memcpy(fresh.data(), raw.data(), raw.size() * sizeof(double));
            benchmark::DoNotOptimize(fresh.data());
        },
        3);
    state.counters["time_vs_memcpy"] = t_decode / t_memcpy;
    state.counters["time_vs_fresh_copy"] = t_decode / t_fresh;
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

void BM_x3p_decode_deflated(benchmark::State& state) {
    const auto n = static_cast<std::size_t>(state.range(0));
    const std::string& bytes = deflated_bytes(n);
    for (auto _ : state) {
        HeightMap map = formats::decode_x3p(bytes, "bench.x3p", {});
        benchmark::DoNotOptimize(map.heights_um.data());
    }
    std::vector<char> out;
    const double t_decode =
        seconds_of([&] { (void)formats::decode_x3p(bytes, "bench.x3p", {}); }, 1);
    const double t_inflate = seconds_of([&] { raw_inflate(bytes, out); }, 1);
    state.counters["time_vs_inflate"] = t_decode / t_inflate;
    state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * n * n * sizeof(double)));
}

void BM_x3p_raw_inflate(benchmark::State& state) {
    const auto n = static_cast<std::size_t>(state.range(0));
    const std::string& bytes = deflated_bytes(n);
    std::vector<char> out;
    for (auto _ : state) raw_inflate(bytes, out);
    state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * n * n * sizeof(double)));
}

}  // namespace

BENCHMARK(BM_x3p_decode_deflated)
    ->Name("x3p/decode_deflated")
    ->Arg(256)
    ->Arg(1024)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);
BENCHMARK(BM_x3p_raw_inflate)
    ->Name("x3p/raw_inflate")
    ->Arg(256)
    ->Arg(1024)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);
BENCHMARK(BM_x3p_decode)
    ->Name("x3p/decode")
    ->Arg(256)
    ->Arg(4096)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);
BENCHMARK(BM_x3p_decode_unverified)
    ->Name("x3p/decode_unverified")
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
