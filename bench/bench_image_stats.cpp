// region_statistics of a grey image with a rectangle region against one memory pass over the same
// image (the baseline, timed in the same run): the sum of its values in double with eight
// accumulators (bound by memory bandwidth, not by the latency of one addition chain).
//
//   build*/bin/roughscope_bench --benchmark_filter='image_stats'
//
// Names: image_stats/region/<rows>  image::region_statistics, the region the whole image but a
//                                   5 % margin (a rectangle as spans, as `roughscope measure`
//                                   passes it; counter mask_time_vs_sum: given as a mask)
//        image_stats/sum/<rows>     baseline: Σ v over all pixels of the plane
// <rows> = 4096 is the 24-MP image (5859 x 4096); 256 a small one (the smoke run skips /4096).
// The counter time_vs_sum of region is its ratio to the baseline.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <random>
#include <span>
#include <vector>

#include <benchmark/benchmark.h>

#include "bench_timing.hpp"
#include "roughscope/region/region.hpp"
#include "roughscope/region/statistics.hpp"

namespace {

namespace img = roughscope::image;

struct Scene {
    img::LinearImage image;
    std::vector<std::uint8_t> mask;
    img::RegionSpans spans;  // the same region as spans (what `measure` passes)
};

// A shaded grey level with pixel noise of 16-bit data (values on a 1/65535 grid), a few hot
// pixels and a few saturated (flagged) ones.
Scene make_scene(std::size_t rows) {
    Scene s;
    const std::size_t width = (24'000'000 / 4096) * rows / 4096;
    img::LinearImage& image = s.image;
    image.width = width;
    image.height = rows;
    image.channels = 1;
    image.values.resize(width * rows);
    image.flags.assign(width * rows, 0);
    image.info.source = "bench.tif";
    std::mt19937 rng(7);
    std::normal_distribution<float> noise(0.0F, 0.01F);
    for (std::size_t y = 0; y < rows; ++y)
        for (std::size_t x = 0; x < width; ++x) {
            const float level = 0.3F + 0.1F * static_cast<float>(x) / static_cast<float>(width);
            const float v = std::clamp(level + noise(rng), 0.0F, 1.0F);
            image.values[y * width + x] = std::round(v * 65535.0F) / 65535.0F;
        }
    for (std::size_t k = 0; k < image.values.size(); k += 997) image.values[k] = 0.95F;
    for (std::size_t k = 13; k < image.values.size(); k += 4999) {
        image.values[k] = 1.0F;
        image.flags[k] = img::kPixelSaturated;
    }
    const double mx = 0.05 * static_cast<double>(width), my = 0.05 * static_cast<double>(rows);
    s.spans = img::region_spans(img::RectangleRegion{mx, my, static_cast<double>(width) - 2 * mx,
                                                     static_cast<double>(rows) - 2 * my},
                                width, rows);
    s.mask = img::rasterize(s.spans);
    return s;
}

double sum_of(std::span<const float> values) {
    std::array<double, 8> acc{};
    std::size_t k = 0;
    for (; k + 8 <= values.size(); k += 8)
        for (std::size_t j = 0; j < 8; ++j) acc[j] += values[k + j];
    for (; k < values.size(); ++k) acc[0] += values[k];
    double sum = 0.0;
    for (const double a : acc) sum += a;
    return sum;
}

using roughscope::bench::seconds_of;

void bench_region(benchmark::State& state) {
    const Scene s = make_scene(static_cast<std::size_t>(state.range(0)));
    for (auto _ : state) benchmark::DoNotOptimize(img::region_statistics(s.image, s.spans));
    const double t_sum = seconds_of([&] { benchmark::DoNotOptimize(sum_of(s.image.values)); }, 5);
    const double t_region = seconds_of([&] { (void)img::region_statistics(s.image, s.spans); }, 3);
    const double t_mask = seconds_of([&] { (void)img::region_statistics(s.image, s.mask); }, 3);
    state.counters["time_vs_sum"] = t_region / t_sum;
    state.counters["mask_time_vs_sum"] = t_mask / t_sum;
}

void bench_sum(benchmark::State& state) {
    const Scene s = make_scene(static_cast<std::size_t>(state.range(0)));
    for (auto _ : state) benchmark::DoNotOptimize(sum_of(s.image.values));
}

BENCHMARK(bench_region)
    ->Name("image_stats/region")
    ->Arg(256)
    ->Arg(4096)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(bench_sum)->Name("image_stats/sum")->Arg(256)->Arg(4096)->Unit(benchmark::kMillisecond);

}  // namespace
