// The light's direction from a mirror sphere (objects/mirror_sphere.hpp) against reading the
// photograph alone (the baseline, timed in the same run).
//
//   build*/bin/roughscope_bench --benchmark_filter='calibrate'
//
// Names: calibrate/mirror_sphere/<side>  read_image + mirror_sphere_light of a <side>² 16-bit TIFF
//        calibrate/read/<side>           baseline: read_image of the same file
// The counter time_vs_read of mirror_sphere is its ratio to the baseline.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

#include <benchmark/benchmark.h>
#include <unistd.h>

#include "bench_timing.hpp"
#include "roughscope/io/output_file.hpp"
#include "roughscope/objects/mirror_sphere.hpp"
#include "roughscope/photo/read.hpp"
#include "roughscope/simulation/capture.hpp"

namespace {

namespace sim = roughscope::simulation;
namespace img = roughscope::image;
namespace fs = std::filesystem;

// A mirror sphere filling 80 % of a side² image, lit from 30° (a 2° lobe), as a 16-bit TIFF.
fs::path write_sphere(std::size_t side) {
    sim::Capture c;
    c.width = c.height = side;
    c.bit_depth = 16;
    c.dn.assign(side * side, 200);
    c.saturated.assign(side * side, 0);
    const double centre = 0.5 * static_cast<double>(side), r = 0.4 * static_cast<double>(side);
    const Eigen::Vector3d light = sim::direction_from_angles(roughscope::deg_to_rad(30.0), 1.0);
    const double lobe = roughscope::deg_to_rad(2.0);
    for (std::size_t y = 0; y < side; ++y)
        for (std::size_t x = 0; x < side; ++x) {
            const double nx = (static_cast<double>(x) + 0.5 - centre) / r;
            const double ny = -(static_cast<double>(y) + 0.5 - centre) / r;
            if (nx * nx + ny * ny >= 1.0) continue;
            const Eigen::Vector3d n(nx, ny, std::sqrt(1.0 - nx * nx - ny * ny));
            const Eigen::Vector3d mirror = 2.0 * n.z() * n - Eigen::Vector3d::UnitZ();
            const double angle = std::acos(std::clamp(mirror.dot(light), -1.0, 1.0));
            c.dn[y * side + x] = static_cast<std::uint16_t>(
                std::lround(200 + 60000 * (0.9 * std::exp(-angle * angle / (2 * lobe * lobe)) +
                                           0.02 * std::max(0.0, n.dot(light)))));
        }
    const fs::path path =
        fs::temp_directory_path() / ("roughscope_bench_sphere_" + std::to_string(::getpid()) + "_" +
                                     std::to_string(side) + ".tiff");
    roughscope::io::write_file_atomic(path, sim::encode_capture_tiff(c));
    return path;
}

img::CircleFit circle_of(std::size_t side) {
    img::CircleFit c;
    c.centre_x_px = c.centre_y_px = 0.5 * static_cast<double>(side);
    c.radius_px = 0.4 * static_cast<double>(side);
    return c;
}

void BM_mirror_sphere(benchmark::State& state) {
    const auto side = static_cast<std::size_t>(state.range(0));
    const fs::path file = write_sphere(side);
    const img::CircleFit circle = circle_of(side);
    const auto calibrate = [&] {
        return img::mirror_sphere_light(img::read_image(file.string()), circle);
    };
    for (auto _ : state) benchmark::DoNotOptimize(calibrate());
    const double t_read =
        roughscope::bench::seconds_of([&] { (void)img::read_image(file.string()); }, 3);
    const double t_calibrate = roughscope::bench::seconds_of([&] { (void)calibrate(); }, 3);
    state.counters["time_vs_read"] = t_calibrate / t_read;
    fs::remove(file);
}

void BM_mirror_sphere_read(benchmark::State& state) {
    const fs::path file = write_sphere(static_cast<std::size_t>(state.range(0)));
    for (auto _ : state) benchmark::DoNotOptimize(img::read_image(file.string()));
    fs::remove(file);
}

BENCHMARK(BM_mirror_sphere)
    ->Name("calibrate/mirror_sphere")
    ->Arg(512)
    ->Arg(1024)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_mirror_sphere_read)
    ->Name("calibrate/read")
    ->Arg(512)
    ->Arg(1024)
    ->Unit(benchmark::kMillisecond);

}  // namespace
