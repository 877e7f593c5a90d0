// `measure` on a pair of photographs against decoding the same two files alone (the baselines,
// timed in the same run): OpenCV's imread for 16-bit TIFFs, LibRaw's open + unpack for DNGs.
//
//   build*/bin/roughscope_bench --benchmark_filter='measure'
//
// Names: measure/pair_<format>/<rows>   image::measure of two captures (30°, 45°, camera on the
//                                       normal; the region the whole image but a 5 % margin)
//        measure/decode_<format>/<rows> baseline: the two files decoded by the reference decoder
// <rows> = 4096 is the 24-MP image (5859 x 4096); 256 a small one (the smoke run skips /4096).
// The counter time_vs_decode of pair_<format> is its ratio to the baseline of the same format.
//        measure/budget/<rows>/<0|1>    the uncertainty budget alone, first order (0) or Monte
//                                       Carlo with 10⁴ trials (1); its time_vs_decode is against
//                                       decoding the same pair
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <libraw/libraw.h>
#include <opencv2/imgcodecs.hpp>
#include <unistd.h>

#include "bench_timing.hpp"
#include "roughscope/io/output_file.hpp"
#include "roughscope/measure/measure.hpp"
#include "roughscope/simulation/capture.hpp"

namespace {

namespace sim = roughscope::simulation;
namespace img = roughscope::image;
namespace fs = std::filesystem;

struct Pair {
    std::vector<fs::path> files;
    img::MeasureRequest request;
};

// Two captures of a very-rough plane at 30° and 45°, written once per (format, rows).
Pair make_pair(sim::CaptureFormat format, std::size_t rows) {
    Pair p;
    const std::size_t width = (24'000'000 / 4096) * rows / 4096;
    const char* ext = format == sim::CaptureFormat::Dng ? "dng" : "tiff";
    for (const double theta : {30.0, 45.0}) {
        sim::Scene scene;
        scene.width = width;
        scene.height = rows;
        scene.light = sim::direction_from_angles(roughscope::deg_to_rad(theta), roughscope::kPi);
        sim::SurfaceTruth truth;
        sim::CameraModel camera;
        camera.bit_depth = format == sim::CaptureFormat::Dng ? 14 : 16;
        camera.gain_dn_per_e = format == sim::CaptureFormat::Dng ? 0.2 : 0.9;
        camera.seed = static_cast<std::uint64_t>(theta);
        const sim::Capture c =
            sim::render_capture(scene, {truth}, {}, camera, {.keep_geometry = false});
        const fs::path path =
            fs::temp_directory_path() /
            (std::string("roughscope_bench_measure_") + std::to_string(::getpid()) + "_" +
             std::to_string(static_cast<int>(theta)) + "." + ext);
        roughscope::io::write_file_atomic(path, sim::encode_capture(c, camera, format));
        p.files.push_back(path);
        img::CaptureSpec spec;
        spec.image = path.string();
        spec.geometry = roughscope::Geometry{roughscope::deg_to_rad(theta), 0.0, 0.0};
        spec.exposure_s = 1.0;
        p.request.captures.push_back(spec);
    }
    const double mx = 0.05 * static_cast<double>(width), my = 0.05 * static_cast<double>(rows);
    p.request.roi = img::RectangleRegion{mx, my, static_cast<double>(width) - 2 * mx,
                                         static_cast<double>(rows) - 2 * my};
    p.request.read.response = roughscope::Response::Linear;
    if (format != sim::CaptureFormat::Dng)
        p.request.read.black_level_dn = std::vector<double>{64.0};
    return p;
}

void decode(const Pair& p, sim::CaptureFormat format) {
    for (const fs::path& f : p.files) {
        if (format == sim::CaptureFormat::Dng) {
            LibRaw raw;
            raw.open_file(f.c_str());
            raw.unpack();
            benchmark::DoNotOptimize(raw.imgdata.rawdata.raw_alloc);
        } else {
            const cv::Mat m = cv::imread(f.string(), cv::IMREAD_UNCHANGED);
            benchmark::DoNotOptimize(m.data);
        }
    }
}

using roughscope::bench::seconds_of;

void BM_measure_pair(benchmark::State& state, sim::CaptureFormat format) {
    const Pair p = make_pair(format, static_cast<std::size_t>(state.range(0)));
    for (auto _ : state) benchmark::DoNotOptimize(img::measure(p.request));
    const double t_decode = seconds_of([&] { decode(p, format); }, 3);
    const double t_measure = seconds_of([&] { (void)img::measure(p.request); }, 2);
    state.counters["time_vs_decode"] = t_measure / t_decode;
    for (const auto& f : p.files) fs::remove(f);
}

void BM_measure_decode(benchmark::State& state, sim::CaptureFormat format) {
    const Pair p = make_pair(format, static_cast<std::size_t>(state.range(0)));
    for (auto _ : state) decode(p, format);
    for (const auto& f : p.files) fs::remove(f);
}

// The uncertainty budget alone (measure/budget.hpp) of a measured pair: first order (method 0)
// or Monte Carlo with one batch of 10⁴ trials on every core (method 1), against decoding the
// pair (OpenCV, as the TIFF baseline above, timed in the same run): the counter time_vs_decode.
// Args: rows (256, or 4096 = a 24-MP pair), method.
void BM_measure_budget(benchmark::State& state) {
    Pair p = make_pair(sim::CaptureFormat::Tiff, static_cast<std::size_t>(state.range(0)));
    p.request.uncertainty.angle_deg = 0.5;
    const bool monte_carlo = state.range(1) == 1;
    p.request.propagation.method = monte_carlo ? roughscope::PropagationMethod::MonteCarlo
                                               : roughscope::PropagationMethod::FirstOrder;
    p.request.propagation.batch_trials = 10'000;
    p.request.propagation.max_trials = 10'000;
    const img::MeasureResult result = img::measure(p.request);
    for (auto _ : state) benchmark::DoNotOptimize(img::uncertainty_budget(p.request, result));
    const double t_decode = seconds_of([&] { decode(p, sim::CaptureFormat::Tiff); }, 3);
    const double t_budget =
        seconds_of([&] { (void)img::uncertainty_budget(p.request, result); }, 3);
    state.counters["time_vs_decode"] = t_budget / t_decode;
    state.SetLabel(monte_carlo ? "monte carlo, 1e4 trials" : "first order");
    for (const auto& f : p.files) fs::remove(f);
}
BENCHMARK(BM_measure_budget)
    ->Name("measure/budget")
    ->Args({256, 0})
    ->Args({256, 1})
    ->Args({4096, 1})
    ->Unit(benchmark::kMillisecond);

BENCHMARK_CAPTURE(BM_measure_pair, tiff, sim::CaptureFormat::Tiff)
    ->Name("measure/pair_tiff")
    ->Arg(256)
    ->Arg(4096)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_measure_decode, tiff, sim::CaptureFormat::Tiff)
    ->Name("measure/decode_tiff")
    ->Arg(256)
    ->Arg(4096)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_measure_pair, dng, sim::CaptureFormat::Dng)
    ->Name("measure/pair_dng")
    ->Arg(256)
    ->Arg(4096)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_measure_decode, dng, sim::CaptureFormat::Dng)
    ->Name("measure/decode_dng")
    ->Arg(256)
    ->Arg(4096)
    ->Unit(benchmark::kMillisecond);

}  // namespace
