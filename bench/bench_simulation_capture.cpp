// Synthetic capture of a 24-MP 16-bit image, rendered and written, against writing the same image
// file alone (the baseline, timed in the same run).
//
//   build*/bin/roughscope_bench --benchmark_filter='capture'
//
// Names: capture/render_write_<format>/<rows>  render_capture of a plane (very-rough brightness,
//                                              shot + read noise, 16 bits, keep_geometry off),
//                                              encode, write_file_atomic
//        capture/write_<format>/<rows>         baseline: encode + write of the same capture
// <rows> = 4096 is the 24-MP image (5859 x 4096 = 24.0 MP); 256 a small one (366 x 256, the same
// aspect) for the smoke run, which skips the /4096 sizes. The counter time_vs_write of
// render_write is its ratio to the baseline of the same format. Formats: tiff (16-bit uint,
// uncompressed) and png (16-bit, deflate level 1).
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

#include <benchmark/benchmark.h>
#include <unistd.h>

#include "bench_timing.hpp"
#include "roughscope/io/output_file.hpp"
#include "roughscope/simulation/capture.hpp"

namespace {

using namespace roughscope::simulation;

struct Setup {
    Scene scene;
    SurfaceTruth truth;
    CameraModel camera;
};

Setup setup_for(std::size_t rows) {
    Setup s;
    s.scene.shape = SceneShape::Plane;
    s.scene.height = rows;
    s.scene.width = (24'000'000 / 4096) * rows / 4096;  // 5859 x 4096 at rows = 4096
    s.scene.light = direction_from_angles(roughscope::deg_to_rad(30.0), roughscope::kPi);
    s.camera.bit_depth = 16;
    s.camera.gain_dn_per_e = 0.5;
    s.camera.electrons_per_unit_s = 40000.0;
    return s;
}

std::filesystem::path bench_path(const char* ext) {
    return std::filesystem::temp_directory_path() /
           (std::string("roughscope_bench_capture_") + std::to_string(::getpid()) + "." + ext);
}

using roughscope::bench::seconds_of;

void write_only(const Capture& c, const CameraModel& camera, CaptureFormat format,
                const std::filesystem::path& path) {
    roughscope::io::write_file_atomic(path, encode_capture(c, camera, format));
}

void render_write(const Setup& s, CaptureFormat format, const std::filesystem::path& path) {
    // As roughscope simulate capture renders for a file (capture_options_for_file).
    const Capture c =
        render_capture(s.scene, {s.truth}, {}, s.camera, capture_options_for_file(format, false));
    write_only(c, s.camera, format, path);
}

void BM_capture_render_write(benchmark::State& state, CaptureFormat format) {
    const Setup s = setup_for(static_cast<std::size_t>(state.range(0)));
    const auto path = bench_path(format == CaptureFormat::Png ? "png" : "tiff");
    for (auto _ : state) render_write(s, format, path);
    const Capture c = render_capture(s.scene, {s.truth}, {}, s.camera, {.keep_geometry = false});
    const double t_write = seconds_of([&] { write_only(c, s.camera, format, path); }, 3);
    const double t_total = seconds_of([&] { render_write(s, format, path); }, 1);
    state.counters["time_vs_write"] = t_total / t_write;
    state.counters["megapixels"] = static_cast<double>(c.dn.size()) / 1e6;
    std::filesystem::remove(path);
}

void BM_capture_write(benchmark::State& state, CaptureFormat format) {
    const Setup s = setup_for(static_cast<std::size_t>(state.range(0)));
    const auto path = bench_path(format == CaptureFormat::Png ? "png" : "tiff");
    const Capture c = render_capture(s.scene, {s.truth}, {}, s.camera, {.keep_geometry = false});
    for (auto _ : state) write_only(c, s.camera, format, path);
    std::filesystem::remove(path);
}

BENCHMARK_CAPTURE(BM_capture_render_write, tiff, CaptureFormat::Tiff)
    ->Name("capture/render_write_tiff")
    ->Arg(256)
    ->Arg(4096)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_capture_write, tiff, CaptureFormat::Tiff)
    ->Name("capture/write_tiff")
    ->Arg(256)
    ->Arg(4096)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_capture_render_write, png, CaptureFormat::Png)
    ->Name("capture/render_write_png")
    ->Arg(256)
    ->Arg(4096)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_capture_write, png, CaptureFormat::Png)
    ->Name("capture/write_png")
    ->Arg(256)
    ->Arg(4096)
    ->Unit(benchmark::kMillisecond);

}  // namespace
