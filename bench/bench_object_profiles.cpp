// Curved objects (image/cylinder.hpp, image/sphere.hpp) against decoding the photograph, baseline
// timed in the same run.
//
//   build*/bin/roughscope_bench --benchmark_filter='objects/'
//
// Names: objects/read_tiff_<shape>/<rows>    baseline: read_image of a 16-bit grey TIFF
//                                            (uncompressed) of a Lambert cylinder or sphere lit
//                                            from the camera
//        objects/cylinder_profile/<rows>     read_image + measure_cylinder_profile (silhouette,
//                                            axis, bins, models, fits, departures); the axis
//                                            along the image's columns
//        objects/cylinder_profile_horizontal/<rows>  the same, the axis along the image's rows
//        objects/sphere_table/<rows>         read_image + measure_sphere_table (no model
//                                            comparison: silhouette, circle, cells → BrdfTable)
//        objects/sphere_compare/<rows>       read_image + measure_sphere with compare_brdf
// <rows> = 4096 is the 24-MP image (5859 x 4096); 256 a small one (366 x 256) for the smoke run.
// The counter time_vs_read is each one's time over read_image's; time_vs_opencv_decode over
// OpenCV's imread of the file (IMREAD_UNCHANGED; the decoding baseline of bench_measure.cpp, a
// decoder this project does not tune — read_image itself is several times faster than it).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <opencv2/imgcodecs.hpp>
#include <tiffio.h>
#include <unistd.h>

#include "bench_timing.hpp"
#include "roughscope/objects/cylinder.hpp"
#include "roughscope/objects/sphere.hpp"
#include "roughscope/photo/read.hpp"

namespace {

using roughscope::bench::seconds_of;

std::size_t width_for(std::size_t rows) { return (24'000'000 / 4096) * rows / 4096; }

// Lambert object (L = V) on a dark background with a little deterministic texture:
// 16-bit codes 60000 · cos θi + 400 on the object, 400 off it.
enum class Shape { CylinderVertical, CylinderHorizontal, Sphere };

void write_object_tiff(const std::filesystem::path& path, Shape shape, std::size_t width,
                       std::size_t height) {
    TIFF* tif = TIFFOpen(path.c_str(), "w");
    if (tif == nullptr) throw std::runtime_error("cannot write " + path.string());
    TIFFSetField(tif, TIFFTAG_IMAGEWIDTH, static_cast<std::uint32_t>(width));
    TIFFSetField(tif, TIFFTAG_IMAGELENGTH, static_cast<std::uint32_t>(height));
    TIFFSetField(tif, TIFFTAG_BITSPERSAMPLE, 16);
    TIFFSetField(tif, TIFFTAG_SAMPLESPERPIXEL, 1);
    TIFFSetField(tif, TIFFTAG_PHOTOMETRIC, PHOTOMETRIC_MINISBLACK);
    TIFFSetField(tif, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
    TIFFSetField(tif, TIFFTAG_COMPRESSION, COMPRESSION_NONE);
    TIFFSetField(tif, TIFFTAG_ROWSPERSTRIP, TIFFDefaultStripSize(tif, 0));
    const double R = 0.4 * static_cast<double>(std::min(width, height));
    const double cx = 0.5 * static_cast<double>(width), cy = 0.5 * static_cast<double>(height);
    std::vector<std::uint16_t> row(width);
    for (std::size_t r = 0; r < height; ++r) {
        const double y = (static_cast<double>(r) + 0.5 - cy) / R;
        for (std::size_t c = 0; c < width; ++c) {
            const double x = (static_cast<double>(c) + 0.5 - cx) / R;
            const double rho2 = shape == Shape::Sphere             ? x * x + y * y
                                : shape == Shape::CylinderVertical ? x * x
                                                                   : y * y;
            const double texture = 1.0 + 0.01 * static_cast<double>(((r * 7 + c * 13) % 17)) / 17;
            row[c] = static_cast<std::uint16_t>(
                rho2 < 1.0 ? 400.0 + 60000.0 * std::sqrt(1.0 - rho2) / 1.01 * texture : 400.0);
        }
        TIFFWriteScanline(tif, row.data(), static_cast<std::uint32_t>(r), 0);
    }
    TIFFClose(tif);
}

struct BenchFile {
    std::filesystem::path path;
    ~BenchFile() {
        std::error_code ec;
        if (!path.empty()) std::filesystem::remove(path, ec);
    }
};

const std::filesystem::path& object_file(Shape shape, std::size_t rows) {
    static BenchFile files[3][2];
    BenchFile& f = files[static_cast<int>(shape)][rows == 4096 ? 1 : 0];
    if (f.path.empty()) {
        const char* name = shape == Shape::Sphere             ? "sphere"
                           : shape == Shape::CylinderVertical ? "cylinder"
                                                              : "cylinder_horizontal";
        f.path = std::filesystem::temp_directory_path() /
                 (std::string("roughscope_bench_") + name + "_" + std::to_string(rows) + "_" +
                  std::to_string(::getpid()) + ".tif");
        write_object_tiff(f.path, shape, width_for(rows), rows);
    }
    return f.path;
}

roughscope::image::LinearImage read(const std::filesystem::path& path) {
    return roughscope::image::read_image(path.string());
}

void cylinder(const std::filesystem::path& path) {
    const auto image = read(path);
    const auto p = roughscope::image::measure_cylinder_profile(image, nullptr, {});
    benchmark::DoNotOptimize(p.bins.data());
}

void sphere(const std::filesystem::path& path, bool compare) {
    const auto image = read(path);
    const auto r = compare ? roughscope::image::measure_sphere(image, nullptr, {})
                           : roughscope::image::measure_sphere_table(image, nullptr, {});
    benchmark::DoNotOptimize(r.table.measurements.data());
}

double opencv_decode_seconds(const std::filesystem::path& path) {
    return seconds_of(
        [&] { benchmark::DoNotOptimize(cv::imread(path.string(), cv::IMREAD_UNCHANGED).data); }, 3);
}

void set_counters(benchmark::State& state, std::size_t rows, double t, double t_read,
                  double t_opencv) {
    state.counters["time_vs_read"] = t / t_read;
    state.counters["time_vs_opencv_decode"] = t / t_opencv;
    state.counters["megapixels"] = static_cast<double>(width_for(rows) * rows) / 1e6;
}

void BM_read_cylinder(benchmark::State& state) {
    const auto& path =
        object_file(Shape::CylinderVertical, static_cast<std::size_t>(state.range(0)));
    for (auto _ : state) benchmark::DoNotOptimize(read(path).values.data());
}
void BM_read_sphere(benchmark::State& state) {
    const auto& path = object_file(Shape::Sphere, static_cast<std::size_t>(state.range(0)));
    for (auto _ : state) benchmark::DoNotOptimize(read(path).values.data());
}

void BM_cylinder_profile(benchmark::State& state, Shape shape) {
    const auto rows = static_cast<std::size_t>(state.range(0));
    const auto& path = object_file(shape, rows);
    for (auto _ : state) cylinder(path);
    const double t = seconds_of([&] { cylinder(path); }, 3);
    const double t_read =
        seconds_of([&] { benchmark::DoNotOptimize(read(path).values.data()); }, 3);
    set_counters(state, rows, t, t_read, opencv_decode_seconds(path));
}

void BM_sphere_table(benchmark::State& state) {
    const auto rows = static_cast<std::size_t>(state.range(0));
    const auto& path = object_file(Shape::Sphere, rows);
    for (auto _ : state) sphere(path, false);
    const double t = seconds_of([&] { sphere(path, false); }, 3);
    const double t_read =
        seconds_of([&] { benchmark::DoNotOptimize(read(path).values.data()); }, 3);
    set_counters(state, rows, t, t_read, opencv_decode_seconds(path));
}

void BM_sphere_compare(benchmark::State& state) {
    const auto rows = static_cast<std::size_t>(state.range(0));
    const auto& path = object_file(Shape::Sphere, rows);
    for (auto _ : state) sphere(path, true);
    const double t = seconds_of([&] { sphere(path, true); }, 3);
    const double t_read =
        seconds_of([&] { benchmark::DoNotOptimize(read(path).values.data()); }, 3);
    set_counters(state, rows, t, t_read, opencv_decode_seconds(path));
}

BENCHMARK(BM_read_cylinder)
    ->Name("objects/read_tiff_cylinder")
    ->Arg(256)
    ->Arg(4096)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_cylinder_profile, vertical, Shape::CylinderVertical)
    ->Name("objects/cylinder_profile")
    ->Arg(256)
    ->Arg(4096)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_cylinder_profile, horizontal, Shape::CylinderHorizontal)
    ->Name("objects/cylinder_profile_horizontal")
    ->Arg(256)
    ->Arg(4096)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_read_sphere)
    ->Name("objects/read_tiff_sphere")
    ->Arg(256)
    ->Arg(4096)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_sphere_table)
    ->Name("objects/sphere_table")
    ->Arg(256)
    ->Arg(4096)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_sphere_compare)
    ->Name("objects/sphere_compare")
    ->Arg(256)
    ->Arg(4096)
    ->Unit(benchmark::kMillisecond);

}  // namespace
