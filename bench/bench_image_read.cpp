// Reading photographs (image/read.hpp) against the bare decoders, baselines timed in the same run.
//
//   build*/bin/roughscope_bench --benchmark_filter='image/'
//
// Names: image/read_tiff/<rows>       read_image of a 16-bit RGB TIFF (uncompressed): file read,
//                                     libtiff, linear float planes and pixel flags
//        image/cv_imread_tiff/<rows>  baseline: cv::imread(IMREAD_UNCHANGED) of the same file
//                                     (16-bit BGR, interleaved)
//        image/read_dng/<rows>        read_image of a 16-bit Bayer DNG (uncompressed): LibRaw
//                                     open + unpack, half-size RGB planes, flags
//        image/libraw_unpack_dng/<rows>  baseline: LibRaw open_file + unpack of the same file
// <rows> = 4096 is the 24-MP image (5859 x 4096 = 24.0 MP; the DNG has that many sites); 256 a
// small one (366 x 256) for the smoke run, which skips the /4096 sizes. The counters
// time_vs_opencv and time_vs_libraw are the ratio of read_image to its baseline.
#include <algorithm>
#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <libraw/libraw.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <tiffio.h>
#include <unistd.h>

#include "bench_timing.hpp"
#include "roughscope/photo/read.hpp"

namespace {

std::size_t width_for(std::size_t rows) { return (24'000'000 / 4096) * rows / 4096; }

std::filesystem::path bench_path(const std::string& stem, std::size_t rows, const char* ext) {
    return std::filesystem::temp_directory_path() /
           (std::string("roughscope_bench_") + stem + "_" + std::to_string(rows) + "_" +
            std::to_string(::getpid()) + "." + ext);
}

using roughscope::bench::seconds_of;

std::uint16_t sample(std::size_t i) {
    return static_cast<std::uint16_t>((i * 2654435761U) >> 16);  // spread over 0..65535
}

void set_strip_tags(TIFF* tif, std::size_t width, std::size_t height, int samples,
                    int photometric) {
    TIFFSetField(tif, TIFFTAG_IMAGEWIDTH, static_cast<std::uint32_t>(width));
    TIFFSetField(tif, TIFFTAG_IMAGELENGTH, static_cast<std::uint32_t>(height));
    TIFFSetField(tif, TIFFTAG_BITSPERSAMPLE, 16);
    TIFFSetField(tif, TIFFTAG_SAMPLESPERPIXEL, samples);
    TIFFSetField(tif, TIFFTAG_PHOTOMETRIC, photometric);
    TIFFSetField(tif, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
    TIFFSetField(tif, TIFFTAG_COMPRESSION, COMPRESSION_NONE);
    TIFFSetField(tif, TIFFTAG_ROWSPERSTRIP, TIFFDefaultStripSize(tif, 0));
}

void write_rows(TIFF* tif, std::size_t width, std::size_t height, std::size_t samples) {
    std::vector<std::uint16_t> row(width * samples);
    for (std::size_t r = 0; r < height; ++r) {
        for (std::size_t i = 0; i < row.size(); ++i) row[i] = sample(r * row.size() + i);
        TIFFWriteScanline(tif, row.data(), static_cast<std::uint32_t>(r), 0);
    }
}

void write_rgb_tiff(const std::filesystem::path& path, std::size_t width, std::size_t height) {
    TIFF* tif = TIFFOpen(path.c_str(), "w");
    if (tif == nullptr) throw std::runtime_error("cannot write " + path.string());
    set_strip_tags(tif, width, height, 3, PHOTOMETRIC_RGB);
    write_rows(tif, width, height, 3);
    TIFFClose(tif);
}

// DNG 1.4, one IFD: a 16-bit RGGB Bayer image, black 256, white 65535.
void write_bayer_dng(const std::filesystem::path& path, std::size_t width, std::size_t height) {
    TIFF* tif = TIFFOpen(path.c_str(), "w");
    if (tif == nullptr) throw std::runtime_error("cannot write " + path.string());
    TIFFSetField(tif, TIFFTAG_SUBFILETYPE, 0);
    set_strip_tags(tif, width, height, 1, PHOTOMETRIC_CFA);
    TIFFSetField(tif, TIFFTAG_MAKE, "roughscope");
    TIFFSetField(tif, TIFFTAG_MODEL, "bench");
    const std::array<std::uint16_t, 2> repeat{2, 2};
    TIFFSetField(tif, TIFFTAG_CFAREPEATPATTERNDIM, repeat.data());
    const std::array<std::uint8_t, 4> pattern{0, 1, 1, 2};
    TIFFSetField(tif, TIFFTAG_CFAPATTERN, 4, pattern.data());
    const std::array<std::uint8_t, 4> version{1, 4, 0, 0};
    TIFFSetField(tif, TIFFTAG_DNGVERSION, version.data());
    TIFFSetField(tif, TIFFTAG_UNIQUECAMERAMODEL, "roughscope bench");
    const std::array<float, 1> black{256.0F};
    TIFFSetField(tif, TIFFTAG_BLACKLEVEL, std::uint16_t{1}, black.data());
    const std::array<std::uint32_t, 1> white{65535};
    TIFFSetField(tif, TIFFTAG_WHITELEVEL, std::uint16_t{1}, white.data());
    const std::array<float, 9> identity{1, 0, 0, 0, 1, 0, 0, 0, 1};
    TIFFSetField(tif, TIFFTAG_COLORMATRIX1, std::uint16_t{9}, identity.data());
    const std::array<float, 3> neutral{1, 1, 1};
    TIFFSetField(tif, TIFFTAG_ASSHOTNEUTRAL, std::uint16_t{3}, neutral.data());
    write_rows(tif, width, height, 1);
    TIFFClose(tif);
}

// One file per size, written on first use and removed at exit.
struct BenchFile {
    std::filesystem::path path;
    ~BenchFile() {
        std::error_code ec;
        if (!path.empty()) std::filesystem::remove(path, ec);
    }
};

const std::filesystem::path& tiff_file(std::size_t rows) {
    static BenchFile small, large;
    BenchFile& f = rows == 4096 ? large : small;
    if (f.path.empty()) {
        f.path = bench_path("image_rgb16", rows, "tif");
        write_rgb_tiff(f.path, width_for(rows), rows);
    }
    return f.path;
}

const std::filesystem::path& dng_file(std::size_t rows) {
    static BenchFile small, large;
    BenchFile& f = rows == 4096 ? large : small;
    if (f.path.empty()) {
        f.path = bench_path("image_bayer", rows, "dng");
        write_bayer_dng(f.path, width_for(rows), rows);
    }
    return f.path;
}

void cv_read(const std::filesystem::path& path) {
    cv::Mat m = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
    if (m.empty()) throw std::runtime_error("cv::imread failed");
    benchmark::DoNotOptimize(m.data);
}

void libraw_unpack(const std::filesystem::path& path) {
    auto raw = std::make_unique<LibRaw>();
    if (raw->open_file(path.c_str()) != LIBRAW_SUCCESS || raw->unpack() != LIBRAW_SUCCESS)
        throw std::runtime_error("LibRaw failed");
    benchmark::DoNotOptimize(raw->imgdata.rawdata.raw_image);
}

void ours(const std::filesystem::path& path) {
    const roughscope::image::LinearImage image = roughscope::image::read_image(path.string());
    benchmark::DoNotOptimize(image.values.data());
}

void BM_image_read_tiff(benchmark::State& state) {
    const auto rows = static_cast<std::size_t>(state.range(0));
    const auto& path = tiff_file(rows);
    for (auto _ : state) ours(path);
    const double t_ours = seconds_of([&] { ours(path); }, 3);
    const double t_cv = seconds_of([&] { cv_read(path); }, 3);
    state.counters["time_vs_opencv"] = t_ours / t_cv;
    state.counters["megapixels"] = static_cast<double>(width_for(rows) * rows) / 1e6;
}

void BM_image_cv_imread_tiff(benchmark::State& state) {
    const auto& path = tiff_file(static_cast<std::size_t>(state.range(0)));
    for (auto _ : state) cv_read(path);
}

void BM_image_read_dng(benchmark::State& state) {
    const auto rows = static_cast<std::size_t>(state.range(0));
    const auto& path = dng_file(rows);
    for (auto _ : state) ours(path);
    const double t_ours = seconds_of([&] { ours(path); }, 3);
    const double t_raw = seconds_of([&] { libraw_unpack(path); }, 3);
    state.counters["time_vs_libraw"] = t_ours / t_raw;
    state.counters["megapixels"] = static_cast<double>(width_for(rows) * rows) / 1e6;
}

void BM_image_libraw_unpack_dng(benchmark::State& state) {
    const auto& path = dng_file(static_cast<std::size_t>(state.range(0)));
    for (auto _ : state) libraw_unpack(path);
}

BENCHMARK(BM_image_read_tiff)
    ->Name("image/read_tiff")
    ->Arg(256)
    ->Arg(4096)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_image_cv_imread_tiff)
    ->Name("image/cv_imread_tiff")
    ->Arg(256)
    ->Arg(4096)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_image_read_dng)
    ->Name("image/read_dng")
    ->Arg(256)
    ->Arg(4096)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_image_libraw_unpack_dng)
    ->Name("image/libraw_unpack_dng")
    ->Arg(256)
    ->Arg(4096)
    ->Unit(benchmark::kMillisecond);

}  // namespace
