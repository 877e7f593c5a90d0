#include "roughscope/image/statistics.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <limits>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"

namespace roughscope::image {
namespace {

constexpr double kHuberK = 1.345;              // 95 % efficiency at the normal distribution
constexpr double kMadToSigma = 1.4826;         // 1 / Φ⁻¹(3/4): MAD → σ for normal data
constexpr double kMeanAbsToSigma = 1.2533141;  // √(π/2): mean |v − median| → σ for normal data
constexpr int kHuberMaxIterations = 100;
constexpr std::size_t kMinTileSizePx = 4;
constexpr std::size_t kTargetTiles = 32;  // t0 = ⌊√(n / 32)⌋
constexpr std::size_t kMinAutoTiles = 16;

// Pixel indices are 32-bit (region_statistics).
constexpr std::size_t kMaxImagePixelsForStatistics = std::numeric_limits<std::uint32_t>::max();

std::string image_name(const LinearImage& image) {
    return image.info.source.empty() ? std::string("image") : image.info.source;
}

std::string fraction_text(double f) { return check::format_number(f); }

// Median of `v` (reorders it); v not empty.
double median_of(std::vector<float>& v) {
    assert(!v.empty());
    const std::size_t mid = v.size() / 2;
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
    const double upper = v[mid];
    if (v.size() % 2 == 1) return upper;
    const double lower = *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid));
    return 0.5 * (lower + upper);
}

// Huber M-estimate of location with a fixed scale s = 1.4826 · MAD (iteratively reweighted mean,
// w = min(1, k s / |v − μ|), from the median). MAD = 0 (more than half the values equal): s from
// the mean absolute deviation √(π/2) · mean |v − median|; all values equal: the median.
double huber_mean(const std::vector<float>& values) {
    std::vector<float> work = values;
    const double med = median_of(work);
    double mean_abs = 0.0;
    for (std::size_t i = 0; i < values.size(); ++i) {
        const double d = std::abs(static_cast<double>(values[i]) - med);
        work[i] = static_cast<float>(d);
        mean_abs += d;
    }
    mean_abs /= static_cast<double>(values.size());
    double scale = kMadToSigma * median_of(work);
    if (!(scale > 0.0)) scale = kMeanAbsToSigma * mean_abs;
    if (!(scale > 0.0)) return med;
    const double cut = kHuberK * scale;
    double mu = med;
    for (int iteration = 0; iteration < kHuberMaxIterations; ++iteration) {
        double sum_w = 0.0, sum_wv = 0.0;
        for (const float value : values) {
            const double v = value;
            const double d = std::abs(v - mu);
            const double w = d <= cut ? 1.0 : cut / d;
            sum_w += w;
            sum_wv += w * v;
        }
        const double next = sum_wv / sum_w;
        const bool done = std::abs(next - mu) <= 1e-12 * scale;
        mu = next;
        if (done) break;
    }
    return mu;
}

ChannelStatistics series_statistics(const std::vector<float>& values) {
    ChannelStatistics s;
    s.count = values.size();
    assert(s.count > 0);
    double sum = 0.0;
    for (const float v : values) sum += v;
    s.mean = sum / static_cast<double>(s.count);
    if (s.count > 1) {
        double ss = 0.0;
        for (const float v : values) ss += (v - s.mean) * (v - s.mean);
        s.std_dev = std::sqrt(ss / static_cast<double>(s.count - 1));
    }
    s.stderr_pixel = s.std_dev / std::sqrt(static_cast<double>(s.count));
    s.robust_mean = huber_mean(values);
    return s;
}

struct Box {
    std::size_t x0, y0, x1, y1;  // half-open
};

// Tiles of side t over the box (image grid): the used-pixel count of each.
struct TileGrid {
    std::size_t t, tx0, ty0, ntx, nty;
    std::size_t index(std::size_t x, std::size_t y) const {
        return (y / t - ty0) * ntx + (x / t - tx0);
    }
};

TileGrid tile_grid(const Box& box, std::size_t t) {
    TileGrid g{t, box.x0 / t, box.y0 / t, 0, 0};
    g.ntx = (box.x1 - 1) / t - g.tx0 + 1;
    g.nty = (box.y1 - 1) / t - g.ty0 + 1;
    return g;
}

bool tile_counts(std::size_t used, std::size_t t) { return 2 * used >= t * t; }

std::size_t counting_tiles(const std::vector<std::uint32_t>& used, const Box& box,
                           std::size_t width, std::size_t t) {
    const TileGrid g = tile_grid(box, t);
    std::vector<std::size_t> n(g.ntx * g.nty, 0);
    for (const std::uint32_t k : used) ++n[g.index(k % width, k / width)];
    return static_cast<std::size_t>(
        std::count_if(n.begin(), n.end(), [t](std::size_t c) { return tile_counts(c, t); }));
}

std::size_t choose_tile_size(const std::vector<std::uint32_t>& used, const Box& box,
                             std::size_t width) {
    const auto t0 = static_cast<std::size_t>(
        std::floor(std::sqrt(static_cast<double>(used.size()) / kTargetTiles)));
    std::size_t t = std::max(kMinTileSizePx, t0);
    while (t > kMinTileSizePx) {
        if (counting_tiles(used, box, width, t) >= kMinAutoTiles) return t;
        t = std::max(kMinTileSizePx,
                     static_cast<std::size_t>(std::floor(0.8 * static_cast<double>(t))));
    }
    return kMinTileSizePx;
}

// std of the tile means / √tiles for each series (the planes, then the average).
void tile_errors(const LinearImage& image, const std::vector<std::uint32_t>& used, const Box& box,
                 std::size_t t, RegionStatistics& out) {
    const std::size_t planes = image.channels;
    const std::size_t pixels = image.pixel_count();
    const TileGrid g = tile_grid(box, t);
    const std::size_t cells = g.ntx * g.nty;
    std::vector<std::size_t> n(cells, 0);
    std::vector<double> sums(cells * (planes + 1), 0.0);  // per tile: planes, then the average
    for (const std::uint32_t k : used) {
        const std::size_t cell = g.index(k % image.width, k / image.width);
        ++n[cell];
        double average = 0.0;
        for (std::size_t c = 0; c < planes; ++c) {
            const double v = image.values[c * pixels + k];
            sums[cell * (planes + 1) + c] += v;
            average += v;
        }
        sums[cell * (planes + 1) + planes] += average / static_cast<double>(planes);
    }
    std::vector<std::vector<double>> means(planes + 1);
    for (std::size_t cell = 0; cell < cells; ++cell) {
        if (!tile_counts(n[cell], t)) continue;
        for (std::size_t s = 0; s <= planes; ++s)
            means[s].push_back(sums[cell * (planes + 1) + s] / static_cast<double>(n[cell]));
    }
    const std::size_t tiles = means[0].size();
    for (std::size_t s = 0; s <= planes; ++s) {
        ChannelStatistics& target = s < planes ? out.channels[s] : out.average;
        target.tiles = tiles;
        if (tiles < 2) continue;
        double mean = 0.0;
        for (const double m : means[s]) mean += m;
        mean /= static_cast<double>(tiles);
        double ss = 0.0;
        for (const double m : means[s]) ss += (m - mean) * (m - mean);
        const double sd = std::sqrt(ss / static_cast<double>(tiles - 1));
        target.stderr_tiles = sd / std::sqrt(static_cast<double>(tiles));
    }
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
    std::vector<std::uint32_t> used;
    Box box{image.width, image.height, 0, 0};
    for (std::size_t k = 0; k < pixels; ++k) {
        if (mask[k] == 0) continue;
        ++out.pixels_in_region;
        const std::uint8_t f = image.flags[k];
        if (f & kPixelSaturated) ++out.pixels_saturated;
        if (f & kPixelClippedLow) ++out.pixels_clipped_low;
        if (f != 0) continue;
        used.push_back(static_cast<std::uint32_t>(k));
        const std::size_t x = k % image.width, y = k / image.width;
        box.x0 = std::min(box.x0, x);
        box.y0 = std::min(box.y0, y);
        box.x1 = std::max(box.x1, x + 1);
        box.y1 = std::max(box.y1, y + 1);
    }
    out.pixels_used = used.size();
    if (out.pixels_in_region == 0)
        throw InvalidArgument(concat(name, ": the region holds no pixel"));

    const std::size_t excluded = out.pixels_in_region - out.pixels_used;
    const double excluded_fraction =
        static_cast<double>(excluded) / static_cast<double>(out.pixels_in_region);
    std::size_t other = 0;  // flagged for another reason (e.g. no flat field)
    for (std::size_t k = 0; k < pixels; ++k)
        if (mask[k] != 0 && (image.flags[k] & ~(kPixelSaturated | kPixelClippedLow)) != 0) ++other;
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

    // Per plane and for the per-pixel channel average.
    std::vector<float> series(used.size());
    for (std::size_t c = 0; c < image.channels; ++c) {
        const float* plane = image.plane(c);
        for (std::size_t i = 0; i < used.size(); ++i) series[i] = plane[used[i]];
        out.channels.push_back(series_statistics(series));
    }
    if (image.channels == 1) {
        out.average = out.channels[0];
    } else {
        for (std::size_t i = 0; i < used.size(); ++i) {
            double sum = 0.0;
            for (std::size_t c = 0; c < image.channels; ++c) sum += image.plane(c)[used[i]];
            series[i] = static_cast<float>(sum / static_cast<double>(image.channels));
        }
        out.average = series_statistics(series);
        // Mean and spread of the average in double from the planes (the float series above,
        // rounded per pixel, serves the robust mean only).
        const auto average_of = [&](std::size_t i) {
            double sum = 0.0;
            for (std::size_t c = 0; c < image.channels; ++c) sum += image.plane(c)[used[i]];
            return sum / static_cast<double>(image.channels);
        };
        double sum = 0.0;
        for (std::size_t i = 0; i < used.size(); ++i) sum += average_of(i);
        out.average.mean = sum / static_cast<double>(used.size());
        if (used.size() > 1) {
            double ss = 0.0;
            for (std::size_t i = 0; i < used.size(); ++i) {
                const double d = average_of(i) - out.average.mean;
                ss += d * d;
            }
            out.average.std_dev = std::sqrt(ss / static_cast<double>(used.size() - 1));
        }
        out.average.stderr_pixel =
            out.average.std_dev / std::sqrt(static_cast<double>(used.size()));
    }

    out.tile_size_px =
        options.tile_size_px > 0 ? options.tile_size_px : choose_tile_size(used, box, image.width);
    tile_errors(image, used, box, out.tile_size_px, out);
    if (out.average.tiles < 2)
        out.warnings.push_back(concat(
            std::to_string(out.average.tiles), " tile(s) of ", std::to_string(out.tile_size_px),
            " x ", std::to_string(out.tile_size_px),
            " px hold at least half used pixels: stderr_tiles not estimated (0); texture and "
            "shading are not in the error"));
    return out;
}

}  // namespace roughscope::image
