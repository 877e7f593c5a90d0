#include "roughscope/image/statistics.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "robust_location.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/memory.hpp"
#include "roughscope/core/text.hpp"

namespace roughscope::image {
namespace {

constexpr std::size_t kMinTileSizePx = 4;
constexpr std::size_t kTargetTiles = 32;  // t0 = ⌊√(n / 32)⌋
constexpr std::size_t kMinAutoTiles = 16;

// Pixel indices are 32-bit (region_statistics).
constexpr std::size_t kMaxImagePixelsForStatistics = std::numeric_limits<std::uint32_t>::max();

std::string image_name(const LinearImage& image) {
    return image.info.source.empty() ? std::string("image") : image.info.source;
}

std::string fraction_text(double f) { return check::format_number(f); }

// Σ p[0..n) in double, four partial sums (no chain of additions through one register).
double sum_of(const float* p, std::size_t n) {
    std::array<double, 4> acc{};
    std::size_t i = 0;
    for (; i + 4 <= n; i += 4)
        for (std::size_t j = 0; j < 4; ++j) acc[j] += p[i + j];
    for (; i < n; ++i) acc[0] += p[i];
    return (acc[0] + acc[1]) + (acc[2] + acc[3]);
}

// Σ (p[i] − m)² in double.
double squares_about(const float* p, std::size_t n, double m) {
    std::array<double, 4> acc{};
    std::size_t i = 0;
    for (; i + 4 <= n; i += 4)
        for (std::size_t j = 0; j < 4; ++j) {
            const double d = static_cast<double>(p[i + j]) - m;
            acc[j] += d * d;
        }
    for (; i < n; ++i) {
        const double d = static_cast<double>(p[i]) - m;
        acc[0] += d * d;
    }
    return (acc[0] + acc[1]) + (acc[2] + acc[3]);
}

struct Box {
    std::size_t x0, y0, x1, y1;  // half-open
};

// Tiles of side t over the box (image grid).
struct TileGrid {
    std::size_t t, tx0, ty0, ntx, nty;
    std::size_t cells() const { return ntx * nty; }
};

TileGrid tile_grid(const Box& box, std::size_t t) {
    TileGrid g{t, box.x0 / t, box.y0 / t, 0, 0};
    g.ntx = (box.x1 - 1) / t - g.tx0 + 1;
    g.nty = (box.y1 - 1) / t - g.ty0 + 1;
    return g;
}

bool tile_counts(std::size_t used, std::size_t t) { return 2 * used >= t * t; }

// Calls f(cell, first index, length) for the pieces of the runs (each within one image row) cut
// at the tile borders.
template <class F>
void for_each_tile_piece(const std::vector<ValueRun>& runs, const TileGrid& g, std::size_t width,
                         F&& f) {
    for (const ValueRun& r : runs) {
        const std::size_t y = r.start / width;
        std::size_t x = r.start - y * width;
        const std::size_t x_end = x + r.length;
        const std::size_t row = (y / g.t - g.ty0) * g.ntx;
        while (x < x_end) {
            const std::size_t tile_x = x / g.t;
            const std::size_t piece_end = std::min(x_end, (tile_x + 1) * g.t);
            f(row + tile_x - g.tx0, y * width + x, piece_end - x);
            x = piece_end;
        }
    }
}

// Used pixels per tile.
std::vector<std::uint32_t> tile_pixel_counts(const std::vector<ValueRun>& runs, const TileGrid& g,
                                             std::size_t width) {
    std::vector<std::uint32_t> n(g.cells(), 0);
    for_each_tile_piece(runs, g, width, [&](std::size_t cell, std::size_t, std::size_t length) {
        n[cell] += static_cast<std::uint32_t>(length);
    });
    return n;
}

std::size_t counting_tiles(const std::vector<ValueRun>& runs, const Box& box, std::size_t width,
                           std::size_t t) {
    const std::vector<std::uint32_t> n = tile_pixel_counts(runs, tile_grid(box, t), width);
    return static_cast<std::size_t>(
        std::count_if(n.begin(), n.end(), [t](std::size_t c) { return tile_counts(c, t); }));
}

std::size_t choose_tile_size(const std::vector<ValueRun>& runs, std::size_t used, const Box& box,
                             std::size_t width) {
    const auto t0 =
        static_cast<std::size_t>(std::floor(std::sqrt(static_cast<double>(used) / kTargetTiles)));
    std::size_t t = std::max(kMinTileSizePx, t0);
    while (t > kMinTileSizePx) {
        if (counting_tiles(runs, box, width, t) >= kMinAutoTiles) return t;
        t = std::max(kMinTileSizePx,
                     static_cast<std::size_t>(std::floor(0.8 * static_cast<double>(t))));
    }
    return kMinTileSizePx;
}

// stderr_tiles and tiles from the sums of the used values per tile.
void set_tile_error(const std::vector<double>& sums, const std::vector<std::uint32_t>& n,
                    std::size_t t, ChannelStatistics& target) {
    std::vector<double> means;
    for (std::size_t cell = 0; cell < n.size(); ++cell)
        if (tile_counts(n[cell], t)) means.push_back(sums[cell] / static_cast<double>(n[cell]));
    target.tiles = means.size();
    if (means.size() < 2) return;
    double mean = 0.0;
    for (const double m : means) mean += m;
    mean /= static_cast<double>(means.size());
    double ss = 0.0;
    for (const double m : means) ss += (m - mean) * (m - mean);
    const double sd = std::sqrt(ss / static_cast<double>(means.size() - 1));
    target.stderr_tiles = sd / std::sqrt(static_cast<double>(means.size()));
}

// The robust mean is a summary beside the mean (the estimates use the mean): above
// kRobustMaxSamples used pixels it is the Huber estimate of a regular subsample (every
// ⌈n / kRobustMaxSamples⌉-th pixel in scan order), which keeps a 24-MP RGB region to a fraction
// of its decoding time; its statistical error is then ~√(n/m) times that of the full series,
// still far below stderr_tiles for any textured sample.
constexpr std::size_t kRobustMaxSamples = std::size_t{1} << 20;

double robust_location(const ValueSeries& series) {
    if (series.count <= kRobustMaxSamples) return huber_location(series).location;
    const std::size_t stride = (series.count + kRobustMaxSamples - 1) / kRobustMaxSamples;
    std::vector<float> sample;
    sample.reserve(series.count / stride + 1);
    std::size_t index = 0;
    for_each_span(series, [&](const float* p, std::size_t n) {
        for (std::size_t k = 0; k < n; ++k, ++index)
            if (index % stride == 0) sample.push_back(p[k]);
    });
    return huber_location(std::span<const float>(sample)).location;
}

double robust_location(std::span<const float> values) {
    if (values.size() <= kRobustMaxSamples) return huber_location(values).location;
    const std::size_t stride = (values.size() + kRobustMaxSamples - 1) / kRobustMaxSamples;
    std::vector<float> sample;
    sample.reserve(values.size() / stride + 1);
    for (std::size_t k = 0; k < values.size(); k += stride) sample.push_back(values[k]);
    return huber_location(std::span<const float>(sample)).location;
}

// Mean, spread and robust mean of a series whose Σ is known.
void set_spread_and_robust_mean(const ValueSeries& series, double sum, ChannelStatistics& s) {
    s.count = series.count;
    assert(s.count > 0);
    s.mean = sum / static_cast<double>(s.count);
    if (s.count > 1) {
        double ss = 0.0;
        for_each_span(series,
                      [&](const float* p, std::size_t n) { ss += squares_about(p, n, s.mean); });
        s.std_dev = std::sqrt(ss / static_cast<double>(s.count - 1));
    }
    s.stderr_pixel = s.std_dev / std::sqrt(static_cast<double>(s.count));
    s.robust_mean = robust_location(series);
}

}  // namespace

void check_region_statistics_options(const RegionStatisticsOptions& options) {
    const auto fraction = [](const char* name, double value) {
        if (!(std::isfinite(value) && value >= 0.0 && value <= 1.0))
            throw InvalidArgument(concat("region statistics: ", name, " = ",
                                         check::format_number(value), " must be in [0, 1]"));
    };
    fraction("max_excluded_fraction", options.max_excluded_fraction);
    fraction("warn_excluded_fraction", options.warn_excluded_fraction);
}

RegionStatistics region_statistics(const LinearImage& image, const std::vector<std::uint8_t>& mask,
                                   const RegionStatisticsOptions& options) {
    check_linear_image(image);
    check_region_statistics_options(options);
    const std::string name = image_name(image);
    const std::size_t pixels = image.pixel_count();
    if (mask.size() != pixels)
        throw InvalidArgument(concat(name, ": region mask of ", std::to_string(mask.size()),
                                     " pixels for an image of ", std::to_string(image.width), " x ",
                                     std::to_string(image.height), " = ", std::to_string(pixels),
                                     " pixels; the sizes must be equal"));

    RegionStatistics out;
    // Pixel indices as 32 bits and the series as float (the image's own precision; sums are
    // double): the memory of a measurement stays a few times one decoded image.
    static_assert(kMaxImagePixelsForStatistics <= std::numeric_limits<std::uint32_t>::max());
    if (pixels > kMaxImagePixelsForStatistics)
        throw InvalidArgument(concat(name, ": ", std::to_string(pixels), " pixels, more than the ",
                                     std::to_string(kMaxImagePixelsForStatistics),
                                     " region statistics handle"));
    // One read of mask and flags: the used pixels as runs within rows (a rectangle: one run per
    // row), the counts and the bounding box.
    std::vector<ValueRun> runs;
    Box box{image.width, image.height, 0, 0};
    std::size_t other = 0;  // flagged for another reason (e.g. no flat field)
    const std::uint8_t* m = mask.data();
    const std::uint8_t* flags = image.flags.data();
    constexpr std::uint8_t kKnownFlags = kPixelSaturated | kPixelClippedLow;
    for (std::size_t y = 0; y < image.height; ++y) {
        const std::size_t row = y * image.width;
        std::size_t x = 0;
        while (x < image.width) {
            for (; x < image.width && (m[row + x] == 0 || flags[row + x] != 0); ++x) {
                if (m[row + x] == 0) continue;
                const std::uint8_t f = flags[row + x];
                ++out.pixels_in_region;
                if (f & kPixelSaturated) ++out.pixels_saturated;
                if (f & kPixelClippedLow) ++out.pixels_clipped_low;
                if (f & ~kKnownFlags) ++other;
            }
            const std::size_t start = x;
            while (x < image.width && m[row + x] != 0 && flags[row + x] == 0) ++x;
            if (x == start) continue;
            runs.push_back(
                {static_cast<std::uint32_t>(row + start), static_cast<std::uint32_t>(x - start)});
            out.pixels_in_region += x - start;
            out.pixels_used += x - start;
            box.x0 = std::min(box.x0, start);
            box.x1 = std::max(box.x1, x);
            box.y0 = std::min(box.y0, y);
            box.y1 = y + 1;
        }
    }
    if (out.pixels_in_region == 0)
        throw InvalidArgument(concat(name, ": the region holds no pixel"));

    const std::size_t excluded = out.pixels_in_region - out.pixels_used;
    const double excluded_fraction =
        static_cast<double>(excluded) / static_cast<double>(out.pixels_in_region);
    const std::string counts = concat(
        std::to_string(excluded), " of ", std::to_string(out.pixels_in_region),
        " pixels of the region are flagged (", std::to_string(out.pixels_saturated), " saturated, ",
        std::to_string(out.pixels_clipped_low), " clipped low, ", std::to_string(other), " other)");
    if (out.pixels_used == 0 || excluded_fraction > options.max_excluded_fraction)
        throw InvalidArgument(concat(
            name, ": ", counts, ", more than max_excluded_fraction ",
            fraction_text(options.max_excluded_fraction),
            ": the region is mostly saturated or clipped; choose another region or exposure"));
    if (excluded_fraction > options.warn_excluded_fraction)
        out.warnings.push_back(concat(counts, " and left out"));

    out.tile_size_px = options.tile_size_px > 0
                           ? options.tile_size_px
                           : choose_tile_size(runs, out.pixels_used, box, image.width);
    const TileGrid grid = tile_grid(box, out.tile_size_px);
    const std::vector<std::uint32_t> tile_n = tile_pixel_counts(runs, grid, image.width);

    // Per plane: one read for the tile sums (their total is Σ v), one for Σ (v − v̄)², then the
    // reads of the robust mean (robust_location.hpp). The planes are read in place.
    const std::size_t planes = image.channels;
    std::vector<double> tile_sums(grid.cells());
    std::vector<double> average_tile_sums(planes > 1 ? grid.cells() : 0, 0.0);
    double average_sum = 0.0;
    for (std::size_t c = 0; c < planes; ++c) {
        const float* plane = image.plane(c);
        std::fill(tile_sums.begin(), tile_sums.end(), 0.0);
        for_each_tile_piece(runs, grid, image.width,
                            [&](std::size_t cell, std::size_t first, std::size_t length) {
                                tile_sums[cell] += sum_of(plane + first, length);
                            });
        double sum = 0.0;
        for (const double t : tile_sums) sum += t;
        ChannelStatistics s;
        set_spread_and_robust_mean({plane, runs, out.pixels_used}, sum, s);
        set_tile_error(tile_sums, tile_n, out.tile_size_px, s);
        out.channels.push_back(s);
        if (planes > 1) {
            for (std::size_t cell = 0; cell < tile_sums.size(); ++cell)
                average_tile_sums[cell] += tile_sums[cell] / static_cast<double>(planes);
            average_sum += sum / static_cast<double>(planes);
        }
    }
    if (planes == 1) {
        out.average = out.channels[0];
    } else {
        // The per-pixel average in double for mean and spread; rounded to float, the series of
        // the robust mean (one contiguous array).
        ChannelStatistics& a = out.average;
        a.count = out.pixels_used;
        a.mean = average_sum / static_cast<double>(a.count);
        std::vector<float> series;
        assign_large(series, out.pixels_used, 0.0F);
        std::size_t i = 0;
        double ss = 0.0;
        for (const ValueRun& r : runs)
            for (std::size_t k = r.start; k < std::size_t{r.start} + r.length; ++k, ++i) {
                double v = 0.0;
                for (std::size_t c = 0; c < planes; ++c) v += image.plane(c)[k];
                v /= static_cast<double>(planes);
                series[i] = static_cast<float>(v);
                ss += (v - a.mean) * (v - a.mean);
            }
        if (a.count > 1) a.std_dev = std::sqrt(ss / static_cast<double>(a.count - 1));
        a.stderr_pixel = a.std_dev / std::sqrt(static_cast<double>(a.count));
        a.robust_mean = robust_location(std::span<const float>(series));
        set_tile_error(average_tile_sums, tile_n, out.tile_size_px, a);
    }
    if (out.average.tiles < 2)
        out.warnings.push_back(concat(
            std::to_string(out.average.tiles), " tile(s) of ", std::to_string(out.tile_size_px),
            " x ", std::to_string(out.tile_size_px),
            " px hold at least half used pixels: stderr_tiles not estimated (0); texture and "
            "shading are not in the error"));
    return out;
}

}  // namespace roughscope::image
