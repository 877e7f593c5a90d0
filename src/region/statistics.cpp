#include "roughscope/region/statistics.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <span>
#include <vector>

#include "robust_location.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/memory.hpp"
#include "roughscope/core/text.hpp"

// The sums below run twice as wide with AVX2 (one clone per instruction set, chosen when the
// program loads). No FMA: the clones round exactly as the default code does.
#if defined(__x86_64__) && defined(__linux__) && (defined(__GNUC__) || defined(__clang__))
#define ROUGHSCOPE_VECTOR_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define ROUGHSCOPE_VECTOR_CLONES
#endif

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

// Σ (p[i] − c) and Σ (p[i] − c)² in double, four partial sums each (no chain of additions
// through one register). With the shift c near the mean, Σ (v − m)² = Σ (v − c)² − n (m − c)²
// loses nothing to cancellation, so one read of the values gives both the sums and the spread.
struct ShiftedSums {
    double sum = 0.0;      // Σ (v − c)
    double squares = 0.0;  // Σ (v − c)²
};

// Four doubles as one value (GCC/Clang vector extension: four lanes, one AVX2 register or two
// SSE2 ones); lane j sums the values i ≡ j (mod 4), as four scalar partial sums would.
using Double4 = double __attribute__((vector_size(32)));
using Float4 = float __attribute__((vector_size(16)));

// (Vectors by reference: passed by value they would change the calling convention with the
// instruction set, which GCC warns about.)
void load4(const float* p, Double4& out) {
    Float4 f;
    std::memcpy(&f, p, sizeof f);
    out = __builtin_convertvector(f, Double4);
}

double lanes_sum(const Double4& v) { return (v[0] + v[1]) + (v[2] + v[3]); }

ROUGHSCOPE_VECTOR_CLONES ShiftedSums shifted_sums(const float* p, std::size_t n, double c) {
    const Double4 shift = {c, c, c, c};
    Double4 acc{};
    Double4 acc2{};
    std::size_t i = 0;
    for (; i + 4 <= n; i += 4) {
        Double4 d;
        load4(p + i, d);
        d -= shift;
        acc += d;
        acc2 += d * d;
    }
    for (; i < n; ++i) {
        const double d = static_cast<double>(p[i]) - c;
        acc[0] += d;
        acc2[0] += d * d;
    }
    return {lanes_sum(acc), lanes_sum(acc2)};
}

// shifted_sums of three planes at once, and of their per-pixel average (v₀ + v₁ + v₂) / 3 in
// double about its own shift.
struct RgbShiftedSums {
    std::array<ShiftedSums, 3> plane;
    ShiftedSums average;
};

ROUGHSCOPE_VECTOR_CLONES RgbShiftedSums shifted_sums_rgb(const std::array<const float*, 3>& p,
                                                         std::size_t n,
                                                         const std::array<double, 3>& c,
                                                         double c_average) {
    std::array<Double4, 3> shift{};
    std::array<Double4, 3> acc{};
    std::array<Double4, 3> acc2{};
    for (std::size_t k = 0; k < 3; ++k) shift[k] = Double4{c[k], c[k], c[k], c[k]};
    const Double4 shift_average = {c_average, c_average, c_average, c_average};
    const Double4 third = {3.0, 3.0, 3.0, 3.0};
    Double4 acc_average{};
    Double4 acc2_average{};
    std::size_t i = 0;
    for (; i + 4 <= n; i += 4) {
        Double4 v0;
        Double4 v1;
        Double4 v2;
        load4(p[0] + i, v0);
        load4(p[1] + i, v1);
        load4(p[2] + i, v2);
        const std::array<Double4, 3> d = {v0 - shift[0], v1 - shift[1], v2 - shift[2]};
        for (std::size_t k = 0; k < 3; ++k) {
            acc[k] += d[k];
            acc2[k] += d[k] * d[k];
        }
        const Double4 da = (v0 + v1 + v2) / third - shift_average;
        acc_average += da;
        acc2_average += da * da;
    }
    for (; i < n; ++i) {
        const double v0 = p[0][i];
        const double v1 = p[1][i];
        const double v2 = p[2][i];
        const double d[3] = {v0 - c[0], v1 - c[1], v2 - c[2]};
        for (std::size_t k = 0; k < 3; ++k) {
            acc[k][0] += d[k];
            acc2[k][0] += d[k] * d[k];
        }
        const double da = (v0 + v1 + v2) / 3.0 - c_average;
        acc_average[0] += da;
        acc2_average[0] += da * da;
    }
    RgbShiftedSums out;
    for (std::size_t k = 0; k < 3; ++k) out.plane[k] = {lanes_sum(acc[k]), lanes_sum(acc2[k])};
    out.average = {lanes_sum(acc_average), lanes_sum(acc2_average)};
    return out;
}

// The 8 bytes at p as one word (any alignment).
std::uint64_t load_word(const std::uint8_t* p) {
    std::uint64_t w = 0;
    std::memcpy(&w, p, sizeof w);
    return w;
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
    // The offset of the next sample in the current span (scan-order index a multiple of stride).
    std::size_t next = 0;
    for_each_span(series, [&](const float* p, std::size_t n) {
        for (; next < n; next += stride) sample.push_back(p[next]);
        next -= n;
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

// Count, mean and spread of `count` values from their shifted sums about c.
void set_moments(std::size_t count, double c, const ShiftedSums& sums, ChannelStatistics& s) {
    s.count = count;
    assert(s.count > 0);
    const auto n = static_cast<double>(s.count);
    const double offset = sums.sum / n;  // m − c
    s.mean = c + offset;
    if (s.count > 1)
        s.std_dev = std::sqrt(std::max(0.0, sums.squares - n * offset * offset) / (n - 1.0));
    s.stderr_pixel = s.std_dev / std::sqrt(n);
}

// The InvalidArgument of check_linear_image for the first non-finite used value of plane c.
[[noreturn]] void throw_first_non_finite(const LinearImage& image, std::size_t c,
                                         const std::vector<ValueRun>& runs) {
    const std::size_t offset = c * image.pixel_count();
    for (const ValueRun& r : runs)
        for (std::size_t k = r.start; k < std::size_t{r.start} + r.length; ++k)
            if (!std::isfinite(image.values[offset + k])) throw_non_finite_value(image, offset + k);
    assert(false && "a non-finite sum of finite values");
    throw_non_finite_value(image, offset + runs.front().start);
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
    check_linear_image_layout(image);
    const std::size_t pixels = image.pixel_count();
    if (mask.size() != pixels)
        throw InvalidArgument(concat(image_name(image), ": region mask of ",
                                     std::to_string(mask.size()), " pixels for an image of ",
                                     std::to_string(image.width), " x ",
                                     std::to_string(image.height), " = ", std::to_string(pixels),
                                     " pixels; the sizes must be equal"));
    return region_statistics(image, region_spans(mask, image.width, image.height), options);
}

RegionStatistics region_statistics(const LinearImage& image, const RegionSpans& region,
                                   const RegionStatisticsOptions& options) {
    // The values are checked where they are read: a non-finite used value makes the plane's
    // shifted sums non-finite (finite floats cannot overflow them in double), and only then are
    // the used values searched for it.
    check_linear_image_layout(image);
    check_region_statistics_options(options);
    const std::string name = image_name(image);
    const std::size_t pixels = image.pixel_count();
    if (region.width != image.width || region.height != image.height)
        throw InvalidArgument(concat(
            name, ": region of an image of ", std::to_string(region.width), " x ",
            std::to_string(region.height), " pixels for an image of ", std::to_string(image.width),
            " x ", std::to_string(image.height), " pixels; the sizes must be equal"));

    RegionStatistics out;
    // Pixel indices as 32 bits and the series as float (the image's own precision; sums are
    // double): the memory of a measurement stays a few times one decoded image.
    static_assert(kMaxImagePixelsForStatistics <= std::numeric_limits<std::uint32_t>::max());
    if (pixels > kMaxImagePixelsForStatistics)
        throw InvalidArgument(concat(name, ": ", std::to_string(pixels), " pixels, more than the ",
                                     std::to_string(kMaxImagePixelsForStatistics),
                                     " region statistics handle"));
    // One read of the flags inside the region's spans: the used pixels as runs within rows (a
    // rectangle: one run per row), the counts and the bounding box.
    std::vector<ValueRun> runs;
    Box box{image.width, image.height, 0, 0};
    std::size_t other = 0;  // flagged for another reason (e.g. no flat field)
    const std::uint8_t* flags = image.flags.data();
    constexpr std::uint8_t kKnownFlags = kPixelSaturated | kPixelClippedLow;
    for (const PixelSpan& span : region.spans) {
        assert(span.x_begin < span.x_end && span.x_end <= image.width && span.row < image.height);
        const std::size_t y = span.row;
        const std::size_t row = y * image.width;
        const std::size_t end = span.x_end;
        std::size_t x = span.x_begin;
        out.pixels_in_region += end - x;
        while (x < end) {
            // Flagged pixels (not used), counted by reason.
            while (x < end && flags[row + x] != 0) {
                const std::uint8_t f = flags[row + x];
                if (f & kPixelSaturated) ++out.pixels_saturated;
                if (f & kPixelClippedLow) ++out.pixels_clipped_low;
                if (f & ~kKnownFlags) ++other;
                ++x;
            }
            // A run of unflagged pixels, eight at a time while the flags are a zero word.
            const std::size_t start = x;
            while (x + 8 <= end && load_word(flags + row + x) == 0) x += 8;
            while (x < end && flags[row + x] == 0) ++x;
            if (x == start) continue;
            runs.push_back(
                {static_cast<std::uint32_t>(row + start), static_cast<std::uint32_t>(x - start)});
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

    // One read of every plane: per plane the tile sums and Σ (v − c)², c the mean of the first
    // run (shifted_sums), and for RGB the same of the per-pixel average (in double); then the
    // reads of the robust means (robust_location.hpp). The planes are read in place.
    const std::size_t planes = image.channels;
    assert(planes == 1 || planes == 3);
    const ValueRun& first_run = runs.front();
    std::array<double, 3> shift{};
    for (std::size_t c = 0; c < planes; ++c)
        shift[c] = shifted_sums(image.plane(c) + first_run.start, first_run.length, 0.0).sum /
                   static_cast<double>(first_run.length);
    const double average_shift = (shift[0] + shift[1] + shift[2]) / 3.0;
    std::vector<std::vector<double>> tile_sums(planes, std::vector<double>(grid.cells(), 0.0));
    std::array<ShiftedSums, 3> total{};
    ShiftedSums average_total;
    for_each_tile_piece(
        runs, grid, image.width, [&](std::size_t cell, std::size_t first, std::size_t length) {
            const auto n = static_cast<double>(length);
            if (planes == 1) {
                const ShiftedSums piece = shifted_sums(image.plane(0) + first, length, shift[0]);
                tile_sums[0][cell] += piece.sum + n * shift[0];
                total[0].sum += piece.sum;
                total[0].squares += piece.squares;
                return;
            }
            const RgbShiftedSums piece = shifted_sums_rgb(
                {image.plane(0) + first, image.plane(1) + first, image.plane(2) + first}, length,
                shift, average_shift);
            for (std::size_t c = 0; c < 3; ++c) {
                tile_sums[c][cell] += piece.plane[c].sum + n * shift[c];
                total[c].sum += piece.plane[c].sum;
                total[c].squares += piece.plane[c].squares;
            }
            average_total.sum += piece.average.sum;
            average_total.squares += piece.average.squares;
        });
    for (std::size_t c = 0; c < planes; ++c) {
        if (!(std::isfinite(total[c].sum) && std::isfinite(total[c].squares)))
            throw_first_non_finite(image, c, runs);
        ChannelStatistics s;
        set_moments(out.pixels_used, shift[c], total[c], s);
        s.robust_mean = robust_location(ValueSeries{image.plane(c), runs, out.pixels_used});
        set_tile_error(tile_sums[c], tile_n, out.tile_size_px, s);
        out.channels.push_back(s);
    }
    if (planes == 1) {
        out.average = out.channels[0];
    } else {
        // The robust mean's series of the per-pixel average (rounded to float): every pixel up to
        // kRobustMaxSamples, else every stride-th in scan order (robust_location's subsample,
        // taken here without forming the rest).
        ChannelStatistics& a = out.average;
        const std::size_t stride =
            out.pixels_used <= kRobustMaxSamples
                ? 1
                : (out.pixels_used + kRobustMaxSamples - 1) / kRobustMaxSamples;
        std::vector<float> series;
        series.reserve(out.pixels_used / stride + 1);
        std::size_t next = 0;  // offset of the next sample in the current run
        for (const ValueRun& r : runs) {
            for (; next < r.length; next += stride) {
                const std::size_t k = std::size_t{r.start} + next;
                const double v = (static_cast<double>(image.plane(0)[k]) + image.plane(1)[k] +
                                  image.plane(2)[k]) /
                                 3.0;
                series.push_back(static_cast<float>(v));
            }
            next -= r.length;
        }
        set_moments(out.pixels_used, average_shift, average_total, a);
        a.robust_mean = robust_location(std::span<const float>(series));
        std::vector<double> average_tile_sums(grid.cells(), 0.0);
        for (std::size_t cell = 0; cell < average_tile_sums.size(); ++cell)
            average_tile_sums[cell] =
                (tile_sums[0][cell] + tile_sums[1][cell] + tile_sums[2][cell]) / 3.0;
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
