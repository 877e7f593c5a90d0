// Roughness maps (image/maps.hpp) of a 24-MP pair against decoding the same two files (the
// baseline, timed in the same run).
//
//   build*/bin/roughscope_bench --benchmark_filter='maps'
//
// Names: maps/decode/<rows>          baseline: read_image of the two 16-bit TIFFs
//        maps/registration/<rows>    estimate_misregistration of the decoded pair (part of a map)
//        maps/map_tiles8/<rows>      read_image of both + roughness_map, window 8
//        maps/map_pixels/<rows>      read_image of both + roughness_map, per pixel (the default
//                                    layers: σ/T of one correlation, its error, the class)
//        maps/map_pixels_every_layer/<rows>  the same with both correlations and E1/E2
//        maps/builds/<what>/<rows>   roughness_map of the decoded pair (no decode) in the
//                                    processor's best build of the row loops against their
//                                    baseline build (limit_map_instruction_set), what = pixels
//                                    (the default layers), pixels_every_layer or tiles8
// <rows> = 4096 is the 24-MP pair (5859 x 4096 = 24.0 MP, the size of the other image benchmarks;
// 6000 x 4000 has the same pixel count); 256 a small one (the smoke run skips /4096).
// Counters: time_vs_decode = (decode + map) / decode of the two files by read_image (one after
// the other; decode + map reads them at once, as `measure` does), each the best of 7 runs, the
// two alternating (a shared VM's speed drifts by tens of percent within a run);
// time_vs_opencv_decode = the same over OpenCV's imread of the two files (IMREAD_UNCHANGED: the
// decoding baseline of bench_measure.cpp, a decoder this project does not tune — read_image
// itself is 3-7x faster than it since its buffers ask for huge pages); peak_vs_image = the peak
// resident memory of decode + map above the resident memory before it, divided by that of
// decoding one image. The peak is Linux's VmHWM of /proc/self/status, reset before each
// measurement by writing 5 to /proc/self/clear_refs (0 when the kernel does not allow it).
// maps/builds: time_vs_baseline = map in the best build / map in the baseline build (x86-64:
// SSE2), the best of 7 runs each, alternating; the label names the processor's best.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <benchmark/benchmark.h>
#include <opencv2/imgcodecs.hpp>
#include <unistd.h>

#include "bench_timing.hpp"
#include "roughscope/io/output_file.hpp"
#include "roughscope/maps/maps.hpp"
#include "roughscope/maps/registration.hpp"
#include "roughscope/photo/read.hpp"
#include "roughscope/simulation/capture.hpp"

namespace {

namespace sim = roughscope::simulation;
namespace img = roughscope::image;
namespace fs = std::filesystem;
using roughscope::bench::seconds_of;
using roughscope::bench::seconds_of_interleaved;

struct PairFiles {
    std::vector<fs::path> files;
    ~PairFiles() {
        for (const auto& f : files) fs::remove(f);
    }
};

void make_pair(PairFiles& p, std::size_t rows) {
    const std::size_t width = (24'000'000 / 4096) * rows / 4096;
    for (const double theta : {30.0, 45.0}) {
        sim::Scene scene;
        scene.width = width;
        scene.height = rows;
        scene.light = sim::direction_from_angles(roughscope::deg_to_rad(theta), roughscope::kPi);
        sim::SurfaceTruth truth;  // very rough, σ/T = 0.2
        sim::CameraModel camera;
        camera.bit_depth = 16;
        camera.gain_dn_per_e = 0.9;
        camera.seed = static_cast<std::uint64_t>(theta);
        const sim::Capture c =
            sim::render_capture(scene, {truth}, {}, camera, {.keep_geometry = false});
        const fs::path path =
            fs::temp_directory_path() / ("roughscope_bench_maps_" + std::to_string(::getpid()) +
                                         "_" + std::to_string(static_cast<int>(theta)) + ".tiff");
        roughscope::io::write_file_atomic(path,
                                          sim::encode_capture(c, camera, sim::CaptureFormat::Tiff));
        p.files.push_back(path);
    }
}

img::ReadOptions read_options() {
    img::ReadOptions o;
    o.response = roughscope::Response::Linear;
    o.black_level_dn = std::vector<double>{64.0};
    return o;
}

void decode_pair(const PairFiles& p) {
    for (const auto& f : p.files) {
        const img::LinearImage im = img::read_image(f.string(), read_options());
        benchmark::DoNotOptimize(im.values.data());
    }
}

void opencv_decode_pair(const PairFiles& p) {
    for (const auto& f : p.files) {
        const cv::Mat m = cv::imread(f.string(), cv::IMREAD_UNCHANGED);
        benchmark::DoNotOptimize(m.data);
    }
}

// As `measure` makes a map: the two photographs read at once (one thread each), then the map.
img::RoughnessMap decode_and_map(const PairFiles& p, std::size_t window, bool every_layer) {
    img::LinearImage b;
    std::thread second([&] { b = img::read_image(p.files[1].string(), read_options()); });
    const img::LinearImage a = img::read_image(p.files[0].string(), read_options());
    second.join();
    std::vector<img::MapCapture> c(2);
    c[0].image = &a;
    c[0].geometry = roughscope::normal_view_geometry(roughscope::deg_to_rad(30.0));
    c[1].image = &b;
    c[1].geometry = roughscope::normal_view_geometry(roughscope::deg_to_rad(45.0));
    img::MapOptions o;
    o.window_px = window;
    o.both_correlations = every_layer;
    o.ratio_layer = every_layer;
    return img::roughness_map(c, o);
}

img::RoughnessMap map_of(const img::LinearImage& a, const img::LinearImage& b, std::size_t window,
                         bool every_layer) {
    std::vector<img::MapCapture> c(2);
    c[0].image = &a;
    c[0].geometry = roughscope::normal_view_geometry(roughscope::deg_to_rad(30.0));
    c[1].image = &b;
    c[1].geometry = roughscope::normal_view_geometry(roughscope::deg_to_rad(45.0));
    img::MapOptions o;
    o.window_px = window;
    o.both_correlations = every_layer;
    o.ratio_layer = every_layer;
    o.check_registration = false;  // (the same in both builds: not what is compared)
    return img::roughness_map(c, o);
}

// Resident memory (kB) of this process: "VmRSS" now or "VmHWM" (peak since the last reset).
long status_kb(const std::string& key) {
    std::ifstream in("/proc/self/status");
    std::string line;
    while (std::getline(in, line))
        if (line.rfind(key + ":", 0) == 0) return std::stol(line.substr(key.size() + 1));
    return 0;
}
bool reset_peak() {
    std::ofstream out("/proc/self/clear_refs");
    out << "5";
    return static_cast<bool>(out);
}
template <class F>
long peak_above_now_kb(F&& body) {
    if (!reset_peak()) return 0;
    const long before = status_kb("VmRSS");
    body();
    return status_kb("VmHWM") - before;
}

void BM_maps_decode(benchmark::State& state) {
    PairFiles p;
    make_pair(p, static_cast<std::size_t>(state.range(0)));
    for (auto _ : state) decode_pair(p);
}

void BM_maps_map(benchmark::State& state, std::size_t window, bool every_layer) {
    PairFiles p;
    make_pair(p, static_cast<std::size_t>(state.range(0)));
    for (auto _ : state) benchmark::DoNotOptimize(decode_and_map(p, window, every_layer).valid);
    const auto [t_decode, t_map] = seconds_of_interleaved(
        [&] { decode_pair(p); }, [&] { (void)decode_and_map(p, window, every_layer); }, 7);
    const double t_opencv = seconds_of([&] { opencv_decode_pair(p); }, 5);
    state.counters["time_vs_decode"] = t_map / t_decode;
    state.counters["time_vs_opencv_decode"] = t_map / t_opencv;
    const long one = peak_above_now_kb([&] {
        const img::LinearImage im = img::read_image(p.files[0].string(), read_options());
        benchmark::DoNotOptimize(im.values.data());
    });
    const long map = peak_above_now_kb([&] { (void)decode_and_map(p, window, every_layer); });
    state.counters["peak_vs_image"] = one > 0 ? static_cast<double>(map) / one : 0.0;
    state.counters["peak_MB"] = static_cast<double>(map) / 1024.0;
}

// The registration check alone (phase correlation of the central 512² crop), on the decoded pair.
void BM_maps_registration(benchmark::State& state) {
    PairFiles p;
    make_pair(p, static_cast<std::size_t>(state.range(0)));
    const img::LinearImage a = img::read_image(p.files[0].string(), read_options());
    const img::LinearImage b = img::read_image(p.files[1].string(), read_options());
    for (auto _ : state) benchmark::DoNotOptimize(img::estimate_misregistration(a, b).shift_x_px);
    const double t_decode = seconds_of([&] { decode_pair(p); }, 3);
    const double t_registration = seconds_of([&] { (void)img::estimate_misregistration(a, b); }, 3);
    state.counters["time_vs_decode"] = t_registration / t_decode;
}

// The row loops' builds (core/target_clones.hpp): the map of the decoded pair in the processor's
// best build against the baseline build, in the same run.
void BM_maps_builds(benchmark::State& state, std::size_t window, bool every_layer) {
    PairFiles p;
    make_pair(p, static_cast<std::size_t>(state.range(0)));
    const img::LinearImage a = img::read_image(p.files[0].string(), read_options());
    const img::LinearImage b = img::read_image(p.files[1].string(), read_options());
    const img::MapInstructionSet before = img::map_instruction_set();
    for (auto _ : state) benchmark::DoNotOptimize(map_of(a, b, window, every_layer).valid);
    const auto [t_baseline, t_best] = seconds_of_interleaved(
        [&] {
            img::limit_map_instruction_set(img::MapInstructionSet::Baseline);
            (void)map_of(a, b, window, every_layer);
        },
        [&] {
            img::limit_map_instruction_set(img::MapInstructionSet::Best);
            (void)map_of(a, b, window, every_layer);
        },
        7);
    img::limit_map_instruction_set(before);
    state.counters["time_vs_baseline"] = t_best / t_baseline;
#if defined(__x86_64__)
    state.SetLabel(__builtin_cpu_supports("avx512f") ? "best: AVX-512"
                   : __builtin_cpu_supports("avx2")  ? "best: AVX2"
                                                     : "best: baseline");
#endif
}

BENCHMARK(BM_maps_registration)
    ->Name("maps/registration")
    ->Arg(256)
    ->Arg(4096)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_maps_decode)->Name("maps/decode")->Arg(256)->Arg(4096)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_maps_map, tiles8, 8, false)
    ->Name("maps/map_tiles8")
    ->Arg(256)
    ->Arg(4096)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_maps_map, pixels, 1, false)
    ->Name("maps/map_pixels")
    ->Arg(256)
    ->Arg(4096)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_maps_map, pixels_every_layer, 1, true)
    ->Name("maps/map_pixels_every_layer")
    ->Arg(256)
    ->Arg(4096)
    ->Unit(benchmark::kMillisecond);

BENCHMARK_CAPTURE(BM_maps_builds, pixels, 1, false)
    ->Name("maps/builds/pixels")
    ->Arg(256)
    ->Arg(2048)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_maps_builds, pixels_every_layer, 1, true)
    ->Name("maps/builds/pixels_every_layer")
    ->Arg(256)
    ->Arg(2048)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_maps_builds, tiles8, 8, false)
    ->Name("maps/builds/tiles8")
    ->Arg(256)
    ->Arg(2048)
    ->Unit(benchmark::kMillisecond);

}  // namespace
