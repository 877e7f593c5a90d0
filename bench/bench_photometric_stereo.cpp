// Photometric stereo (objects/photometric_stereo.hpp) against decoding its photographs (the
// baseline, timed in the same run).
//
//   build*/bin/roughscope_bench --benchmark_filter='photometric_stereo'
//
// Names: photometric_stereo/lambert/<side>  read_image of six <side>² 16-bit TIFFs (a Lambertian
//                                           sphere under six lights) + the Lambertian solve
//        photometric_stereo/read/<side>     baseline: read_image of the six files
//        photometric_stereo/vh_gaussian/<side>  the rough model's solve alone on decoded images
// Counters: time_vs_read (lambert: decode + solve over decode alone); time_vs_lambert
// (vh_gaussian: its solve over the Lambertian solve of the same images).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <unistd.h>

#include "bench_timing.hpp"
#include "roughscope/io/output_file.hpp"
#include "roughscope/objects/photometric_stereo.hpp"
#include "roughscope/photo/read.hpp"
#include "roughscope/simulation/capture.hpp"

namespace {

namespace sim = roughscope::simulation;
namespace img = roughscope::image;
namespace fs = std::filesystem;

std::vector<Eigen::Vector3d> lights() {
    std::vector<Eigen::Vector3d> l;
    for (int j = 0; j < 6; ++j)
        l.push_back(sim::direction_from_angles(roughscope::deg_to_rad(30.0 + 4.0 * j),
                                               roughscope::deg_to_rad(60.0 * j)));
    return l;
}

// A sphere filling 80 % of a side² image under each light (Lambert, albedo 0.8), 16-bit TIFFs.
std::vector<fs::path> write_set(std::size_t side) {
    std::vector<fs::path> files;
    const double centre = 0.5 * static_cast<double>(side), r = 0.4 * static_cast<double>(side);
    const auto L = lights();
    for (std::size_t j = 0; j < L.size(); ++j) {
        sim::Capture c;
        c.width = c.height = side;
        c.bit_depth = 16;
        c.dn.assign(side * side, 0);
        c.saturated.assign(side * side, 0);
        for (std::size_t y = 0; y < side; ++y)
            for (std::size_t x = 0; x < side; ++x) {
                const double nx = (static_cast<double>(x) + 0.5 - centre) / r;
                const double ny = -(static_cast<double>(y) + 0.5 - centre) / r;
                if (nx * nx + ny * ny >= 1.0) continue;
                const Eigen::Vector3d n(nx, ny, std::sqrt(1.0 - nx * nx - ny * ny));
                c.dn[y * side + x] = static_cast<std::uint16_t>(
                    std::lround(60000 * 0.8 * std::max(0.0, n.dot(L[j]))));
            }
        files.push_back(fs::temp_directory_path() /
                        ("roughscope_bench_ps_" + std::to_string(::getpid()) + "_" +
                         std::to_string(side) + "_" + std::to_string(j) + ".tiff"));
        roughscope::io::write_file_atomic(files.back(), sim::encode_capture_tiff(c));
    }
    return files;
}

std::vector<img::LinearImage> read_set(const std::vector<fs::path>& files) {
    std::vector<img::LinearImage> images;
    for (const fs::path& f : files) images.push_back(img::read_image(f.string()));
    return images;
}

img::PhotometricStereoResult solve(const std::vector<img::LinearImage>& images,
                                   img::PhotometricModel model) {
    std::vector<const img::LinearImage*> p;
    for (const img::LinearImage& im : images) p.push_back(&im);
    img::PhotometricStereoOptions o;
    o.model = model;
    return img::photometric_stereo(p, lights(), {}, o);
}

void remove_all(const std::vector<fs::path>& files) {
    for (const fs::path& f : files) fs::remove(f);
}

void BM_lambert(benchmark::State& state) {
    const auto files = write_set(static_cast<std::size_t>(state.range(0)));
    const auto run = [&] { return solve(read_set(files), img::PhotometricModel::Lambert); };
    for (auto _ : state) benchmark::DoNotOptimize(run());
    const double t_read = roughscope::bench::seconds_of([&] { (void)read_set(files); }, 3);
    const double t_all = roughscope::bench::seconds_of([&] { (void)run(); }, 3);
    state.counters["time_vs_read"] = t_all / t_read;
    remove_all(files);
}

void BM_read(benchmark::State& state) {
    const auto files = write_set(static_cast<std::size_t>(state.range(0)));
    for (auto _ : state) benchmark::DoNotOptimize(read_set(files));
    remove_all(files);
}

void BM_rough(benchmark::State& state) {
    const auto files = write_set(static_cast<std::size_t>(state.range(0)));
    const auto images = read_set(files);
    for (auto _ : state)
        benchmark::DoNotOptimize(solve(images, img::PhotometricModel::VeryRoughGaussian));
    const double t_lambert = roughscope::bench::seconds_of(
        [&] { (void)solve(images, img::PhotometricModel::Lambert); }, 3);
    const double t_rough = roughscope::bench::seconds_of(
        [&] { (void)solve(images, img::PhotometricModel::VeryRoughGaussian); }, 1);
    state.counters["time_vs_lambert"] = t_rough / t_lambert;
    remove_all(files);
}

BENCHMARK(BM_lambert)
    ->Name("photometric_stereo/lambert")
    ->Arg(1024)
    ->Arg(2048)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_read)
    ->Name("photometric_stereo/read")
    ->Arg(1024)
    ->Arg(2048)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_rough)
    ->Name("photometric_stereo/vh_gaussian")
    ->Arg(128)
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond);

}  // namespace
