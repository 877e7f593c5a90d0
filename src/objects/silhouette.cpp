#include "roughscope/objects/silhouette.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "object_profile.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/memory.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/scattering/geometry.hpp"

namespace roughscope::image {
namespace {

using check::format_number;

std::string image_name(const LinearImage& image) {
    return image.info.source.empty() ? std::string("image") : image.info.source;
}

// The per-pixel channel average (R + G + B)/3, row-major, read where it is needed: the plane
// itself for a grey image, else computed per pixel or per row (no image-sized copy).
class ChannelAverage {
  public:
    explicit ChannelAverage(const LinearImage& image)
        : w_(image.width),
          r_(image.plane(0)),
          g_(image.channels == 3 ? image.plane(1) : nullptr),
          b_(image.channels == 3 ? image.plane(2) : nullptr) {
        if (g_) row_.resize(w_);
    }
    float operator()(std::size_t i) const { return g_ ? (r_[i] + g_[i] + b_[i]) * kThird : r_[i]; }
    // Row r (valid until the next call).
    const float* row(std::size_t r) {
        const std::size_t i0 = r * w_;
        if (!g_) return r_ + i0;
        for (std::size_t c = 0; c < w_; ++c)
            row_[c] = (r_[i0 + c] + g_[i0 + c] + b_[i0 + c]) * kThird;
        return row_.data();
    }

  private:
    static constexpr float kThird = 1.0F / 3.0F;
    std::size_t w_;
    const float *r_, *g_, *b_;
    std::vector<float> row_;
};

void check_fraction(std::string_view name, double value) {
    if (!(value > 0.0 && value < 1.0))
        throw InvalidArgument(
            concat(name, " = ", format_number(value), " is outside the valid range (0, 1)"));
}

// Bands of the passes over the image (threads: SilhouetteOptions; the results do not depend on
// them).
constexpr std::size_t kBands = 16;

// Membership of the object given as one run of columns per row (detail::RowRun).
struct RunMask {
    const std::vector<detail::RowRun>& rows;
    std::size_t w, h;
    bool in(std::size_t c, std::size_t r) const { return rows[r].begin <= c && c < rows[r].end; }
    // Clamped at the image edge (the Sobel gradient below).
    int at(std::ptrdiff_t c, std::ptrdiff_t r) const {
        c = std::clamp<std::ptrdiff_t>(c, 0, static_cast<std::ptrdiff_t>(w) - 1);
        r = std::clamp<std::ptrdiff_t>(r, 0, static_cast<std::ptrdiff_t>(h) - 1);
        return in(static_cast<std::size_t>(c), static_cast<std::size_t>(r)) ? 1 : 0;
    }
};

// Sobel gradient of the 0/1 mask at (c, r), clamped at the image edge.
std::array<int, 2> mask_gradient(const RunMask& m, std::size_t c, std::size_t r) {
    const auto x = static_cast<std::ptrdiff_t>(c), y = static_cast<std::ptrdiff_t>(r);
    const int gx = (m.at(x + 1, y - 1) + 2 * m.at(x + 1, y) + m.at(x + 1, y + 1)) -
                   (m.at(x - 1, y - 1) + 2 * m.at(x - 1, y) + m.at(x - 1, y + 1));
    const int gy = (m.at(x - 1, y + 1) + 2 * m.at(x, y + 1) + m.at(x + 1, y + 1)) -
                   (m.at(x - 1, y - 1) + 2 * m.at(x, y - 1) + m.at(x + 1, y - 1));
    return {gx, gy};
}

// The sub-pixel crossing between inside pixel i and outside pixel o (neighbours along a row or
// a column), with i2, o2 the next pixels further in and out. The midpoint of i and o — unbiased
// for a sharp edge sampled at pixel centres, whatever the brightness does towards a darkening
// limb — unless the object is flat up to the edge (A_i ≥ 0.9 A_i2) and the level halfway
// between the object's and the background's values, (A_i2 + A_o2)/2, lies between A_o and A_i:
// then where that level is crossed, interpolated linearly between i and o (a blurred step).
// Returns the fraction of the way from i to o.
double crossing_fraction(float ai, float ao, float ai2, float ao2) {
    const double level = 0.5 * (static_cast<double>(ai2) + static_cast<double>(ao2));
    const double step = static_cast<double>(ai) - static_cast<double>(ao);
    if (!(step > 0.0) || ai < 0.9 * ai2 || level > ai || level < ao) return 0.5;
    return (static_cast<double>(ai) - level) / step;
}

// The regular subsample of the automatic level: every step-th pixel, step = ⌊n / 2^18⌋ (at least
// 1): about 2^18 pixels, fewer than 2^19.
std::size_t sample_step(std::size_t n) { return std::max<std::size_t>(1, n >> 18); }

// The level t of SilhouetteOptions::threshold when it is automatic, from the subsample
// (silhouette.hpp); sets s.otsu_threshold.
double automatic_level(const LinearImage& image, std::vector<float> sample,
                       const SilhouetteOptions& options, Silhouette& s) {
    // A non-finite value is refused, naming its sample, by the silhouette's pass over every
    // value; here it is left out (its cast to 8 bits would be undefined).
    std::erase_if(sample, [](float v) { return !std::isfinite(v); });
    if (sample.empty()) return 0.0;
    const auto [lo_it, hi_it] = std::minmax_element(sample.begin(), sample.end());
    const double lo = *lo_it, hi = *hi_it;
    if (!(hi > lo))
        throw DataError(concat(image_name(image), ": no object found (the image is uniform, ",
                               format_number(lo), ")"));
    // Otsu on the subsample scaled to 8 bits between its extremes.
    cv::Mat u8(1, static_cast<int>(sample.size()), CV_8UC1);
    const double scale = 255.0 / (hi - lo);
    for (std::size_t k = 0; k < sample.size(); ++k) {
        // std::lround of x ∈ [0, 255] (halves away from zero), inline: x − ⌊x⌋ is exact.
        const double x = (static_cast<double>(sample[k]) - lo) * scale;
        const auto whole = static_cast<unsigned>(x);
        u8.data[k] = static_cast<std::uint8_t>(whole + (x - whole >= 0.5 ? 1U : 0U));
    }
    cv::Mat unused;
    const double t8 = cv::threshold(u8, unused, 0, 255, cv::THRESH_BINARY | cv::THRESH_OTSU);
    const double t_otsu = lo + (t8 + 0.5) / scale;
    s.otsu_threshold = t_otsu;
    // Background level and noise: median and 1.4826 · MAD of the pixels below t_O (robust
    // to the dark limb of the object, which falls below t_O too); object level: mean of the
    // pixels above t_O.
    std::vector<float> below;
    below.reserve(sample.size());
    double so = 0;
    std::size_t no = 0;
    for (const float v : sample) {
        if (v <= t_otsu) {
            below.push_back(v);
        } else {
            so += v;
            ++no;
        }
    }
    if (below.empty() || no == 0)
        throw DataError(concat(image_name(image), ": no object found (no background)"));
    auto median = [](std::vector<float>& x) {
        const auto mid = x.begin() + static_cast<std::ptrdiff_t>(x.size() / 2);
        std::nth_element(x.begin(), mid, x.end());
        return static_cast<double>(*mid);
    };
    const double mb = median(below);
    for (float& v : below) v = static_cast<float>(std::abs(v - mb));
    const double sdb = 1.4826 * median(below);
    const double mo = so / static_cast<double>(no);
    return std::min(t_otsu, mb + std::max(6.0 * sdb, options.edge_fraction * (mo - mb)));
}

// One pass over the image for the object's mask: the maximum of A over each f × f block (the
// mask reduced by blocks is then max > t: a block is on when any of its pixels is) and, when
// asked, the automatic level's subsample, read from the rows while they are in cache.
struct ImageSummary {
    std::size_t blocks_wide = 0, blocks_high = 0;
    std::vector<float> block_max;  // blocks_high · blocks_wide, row-major
    std::vector<float> sample;     // pixels 0, step, 2 step, ... (sample_step)
    // Per block row: 1 when an averaged value read was not finite (a non-finite sample, or an
    // average of huge ones that overflowed: check_linear_image decides).
    std::vector<std::uint8_t> non_finite;
};

// 1 when the float is ±inf or NaN (exponent bits all ones), as an integer a loop can OR.
inline std::uint32_t non_finite_bit(float v) {
    constexpr std::uint32_t kExponent = 0x7f800000U;
    return static_cast<std::uint32_t>((std::bit_cast<std::uint32_t>(v) & kExponent) == kExponent);
}

// Block rows [br0, br1) of summarise_image: the element-wise maximum of a block's f rows, then
// of its f columns (vectorisable).
void summarise_block_rows(const LinearImage& image, std::size_t f, std::size_t br0, std::size_t br1,
                          ImageSummary& out) {
    const std::size_t w = image.width, h = image.height, sw = out.blocks_wide;
    ChannelAverage avg(image);
    std::vector<float> column_max(w);
    for (std::size_t br = br0; br < br1; ++br) {
        const std::size_t r0 = br * f, r1 = std::min(h, r0 + f);
        float* m = column_max.data();
        const float* a0 = avg.row(r0);
        std::uint32_t bad = 0;
        for (std::size_t c = 0; c < w; ++c) {
            m[c] = a0[c];
            bad |= non_finite_bit(a0[c]);
        }
        for (std::size_t r = r0 + 1; r < r1; ++r) {
            const float* a = avg.row(r);
            for (std::size_t c = 0; c < w; ++c) {
                m[c] = m[c] < a[c] ? a[c] : m[c];
                bad |= non_finite_bit(a[c]);
            }
        }
        out.non_finite[br] = bad != 0 ? 1 : 0;
        float* b = out.block_max.data() + br * sw;
        for (std::size_t bc = 0; bc < sw; ++bc) {
            const std::size_t c0 = bc * f, c1 = std::min(w, c0 + f);
            float mx = m[c0];
            for (std::size_t c = c0 + 1; c < c1; ++c) mx = mx < m[c] ? m[c] : mx;
            b[bc] = mx;
        }
        if (!out.sample.empty()) {  // the subsample's pixels in rows [r0, r1)
            const std::size_t step = sample_step(image.pixel_count());
            const std::size_t k1 = (r1 * w + step - 1) / step;
            for (std::size_t k = (r0 * w + step - 1) / step; k < k1; ++k)
                out.sample[k] = avg(k * step);
        }
    }
}

ImageSummary summarise_image(const LinearImage& image, std::size_t f, bool with_sample,
                             std::size_t threads) {
    ImageSummary out;
    out.blocks_wide = (image.width + f - 1) / f;
    out.blocks_high = (image.height + f - 1) / f;
    out.block_max.resize(out.blocks_wide * out.blocks_high);
    out.non_finite.assign(out.blocks_high, 0);
    const std::size_t n = image.pixel_count(), step = sample_step(n);
    if (with_sample) out.sample.resize((n + step - 1) / step);
    const std::size_t sh = out.blocks_high, bands = std::min(kBands, sh);
    detail::run_bands(bands, threads, [&](std::size_t band) {
        summarise_block_rows(image, f, sh * band / bands, sh * (band + 1) / bands, out);
    });
    return out;
}

// The mask A > t reduced by f × f blocks.
cv::Mat reduced_mask(const ImageSummary& summary, float t) {
    cv::Mat small(static_cast<int>(summary.blocks_high), static_cast<int>(summary.blocks_wide),
                  CV_8UC1);
    for (std::size_t k = 0; k < summary.block_max.size(); ++k)
        small.data[k] = summary.block_max[k] > t ? 1 : 0;
    return small;
}

// Per row, the object's first and last pixel above t in the blocks of component `best` (labels of
// the f × f reduced mask, sw blocks a row), as the run [first, last + 1); the blocks of other
// labels are skipped whole, so only the background beside the object's blocks is read.
std::vector<detail::RowRun> object_runs(const ChannelAverage& avg, const cv::Mat& labels,
                                        const cv::Mat& stats, int best, std::size_t w,
                                        std::size_t h, std::size_t f, float t) {
    std::vector<detail::RowRun> runs(h);
    const auto left = static_cast<std::size_t>(stats.at<int>(best, cv::CC_STAT_LEFT));
    const auto top = static_cast<std::size_t>(stats.at<int>(best, cv::CC_STAT_TOP));
    const std::size_t right =
        left + static_cast<std::size_t>(stats.at<int>(best, cv::CC_STAT_WIDTH));
    const std::size_t bottom =
        top + static_cast<std::size_t>(stats.at<int>(best, cv::CC_STAT_HEIGHT));
    const auto best_label = static_cast<std::int32_t>(best);
    for (std::size_t r = top * f; r < std::min(h, bottom * f); ++r) {
        const std::int32_t* lr = labels.ptr<std::int32_t>(static_cast<int>(r / f));
        const auto above = [&](std::size_t c) { return avg(r * w + c) > t; };
        std::size_t first = w;
        for (std::size_t bc = left; bc < right && first == w; ++bc) {
            if (lr[bc] != best_label) continue;
            for (std::size_t c = bc * f; c < std::min(w, bc * f + f); ++c)
                if (above(c)) {
                    first = c;
                    break;
                }
        }
        if (first == w) continue;
        std::size_t last = first;  // found again by the scan from the right at the latest
        bool found = false;
        for (std::size_t bc = right; bc-- > first / f && !found;) {
            if (lr[bc] != best_label) continue;
            for (std::size_t c = std::min(w, bc * f + f); c-- > bc * f;)
                if (above(c)) {
                    last = c;
                    found = true;
                    break;
                }
        }
        runs[r] = {first, last + 1};
    }
    return runs;
}

// Sub-pixel boundary points of the object (Silhouette::boundary): along rows where the outline
// is more vertical than horizontal, along columns elsewhere. Found from the rows' runs: a row
// has its transitions at the two ends of its run, two rows differ where exactly one run holds
// the column, so only the outline is visited.
void add_boundary_points(const ChannelAverage& avg, const RunMask& m, Silhouette& s) {
    const std::size_t w = m.w, h = m.h;
    auto add_point = [&](std::size_t ci, std::size_t ri, std::size_t co, std::size_t ro,
                         double frac) {
        std::array<int, 2> g = mask_gradient(m, ci, ri);
        const std::array<int, 2> g2 = mask_gradient(m, co, ro);
        g[0] += g2[0];
        g[1] += g2[1];
        const bool along_row = ri == ro;
        if (along_row ? std::abs(g[0]) < std::abs(g[1]) : std::abs(g[1]) <= std::abs(g[0])) return;
        EdgePoint p;
        p.x_px = static_cast<double>(ci) + 0.5 +
                 frac * (static_cast<double>(co) - static_cast<double>(ci));
        p.y_px = static_cast<double>(ri) + 0.5 +
                 frac * (static_cast<double>(ro) - static_cast<double>(ri));
        const double norm = std::hypot(static_cast<double>(g[0]), static_cast<double>(g[1]));
        if (norm > 0) {  // the mask gradient points inwards
            p.normal_x = -g[0] / norm;
            p.normal_y = -g[1] / norm;
        }
        s.boundary.push_back(p);
    };
    // Along rows: inside pixel i next to outside pixel o; i2 and o2 one further in and out.
    for (std::size_t r = s.row_min; r < s.row_max; ++r) {
        const detail::RowRun run = m.rows[r];
        if (run.begin == run.end) continue;
        const std::size_t row = r * w;
        if (run.begin > 0) {  // object on the right of the transition
            const std::size_t i = run.begin, o = i - 1;
            const std::size_t i2 = i + 1 < run.end ? i + 1 : i;
            const std::size_t o2 = o > 0 ? o - 1 : o;
            add_point(i, r, o, r,
                      crossing_fraction(avg(row + i), avg(row + o), avg(row + i2), avg(row + o2)));
        }
        if (run.end < w) {  // object on the left
            const std::size_t i = run.end - 1, o = run.end;
            const std::size_t i2 = i > run.begin ? i - 1 : i;
            const std::size_t o2 = o + 1 < w ? o + 1 : o;
            add_point(i, r, o, r,
                      crossing_fraction(avg(row + i), avg(row + o), avg(row + i2), avg(row + o2)));
        }
    }
    // Along columns, between rows r and r + 1, by increasing column.
    const std::size_t rr0 = s.row_min > 0 ? s.row_min - 1 : 0, rr1 = std::min(h, s.row_max + 1);
    for (std::size_t r = rr0; r + 1 < rr1; ++r) {
        const detail::RowRun a = m.rows[r], b = m.rows[r + 1];
        std::array<std::size_t, 4> ends = {a.begin, a.end, b.begin, b.end};
        std::sort(ends.begin(), ends.end());
        for (std::size_t k = 0; k + 1 < ends.size(); ++k) {
            if (ends[k] == ends[k + 1]) continue;
            const bool inside_top = m.in(ends[k], r);
            if (inside_top == m.in(ends[k], r + 1)) continue;
            for (std::size_t c = ends[k]; c < ends[k + 1]; ++c) {
                const std::size_t ri = inside_top ? r : r + 1, ro = inside_top ? r + 1 : r;
                std::size_t ri2 = ri, ro2 = ro;
                if (inside_top) {
                    if (ri > 0 && m.in(c, ri - 1)) ri2 = ri - 1;
                    if (ro + 1 < h && !m.in(c, ro + 1)) ro2 = ro + 1;
                } else {
                    if (ri + 1 < h && m.in(c, ri + 1)) ri2 = ri + 1;
                    if (ro > 0 && !m.in(c, ro - 1)) ro2 = ro - 1;
                }
                add_point(c, ri, c, ro,
                          crossing_fraction(avg(ri * w + c), avg(ro * w + c), avg(ri2 * w + c),
                                            avg(ro2 * w + c)));
            }
        }
    }
}

}  // namespace

Silhouette find_silhouette(const LinearImage& image, const SilhouetteOptions& options) {
    detail::Outline outline = detail::find_outline(image, options, 0);
    const Silhouette& s = outline.silhouette;
    assign_large(outline.silhouette.mask, image.pixel_count(), std::uint8_t{0});
    for (std::size_t r = 0; r < outline.rows.size(); ++r) {
        const detail::RowRun run = outline.rows[r];
        std::uint8_t* m = outline.silhouette.mask.data() + r * s.width;
        std::fill(m + run.begin, m + run.end, std::uint8_t{1});
    }
    return std::move(outline.silhouette);
}

detail::Outline detail::find_outline(const LinearImage& image, const SilhouetteOptions& options,
                                     std::size_t threads) {
    check_linear_image_layout(image);  // the values: as the summary reads them
    check_fraction("silhouette edge_fraction", options.edge_fraction);
    check_fraction("silhouette min_object_fraction", options.min_object_fraction);
    if (options.threshold && !std::isfinite(*options.threshold))
        throw InvalidArgument("silhouette threshold must be finite");
    const std::size_t w = image.width, h = image.height, n = image.pixel_count();
    if (n > static_cast<std::size_t>(std::numeric_limits<int>::max()) || w < 3 || h < 3)
        throw InvalidArgument(concat(image_name(image),
                                     ": a silhouette needs an image of at least "
                                     "3 x 3 and below 2^31 pixels"));
    ChannelAverage avg(image);

    Outline outline;
    Silhouette& s = outline.silhouette;
    s.width = w;
    s.height = h;
    // Largest 8-connected component above the level, found on the mask reduced by f × f blocks
    // (a block is on when any of its pixels is; f = ⌊√(n / 2^18)⌋, 1 below 2^20 pixels): the
    // object's mask is then its pixels above the level in the blocks of that component.
    const std::size_t f =
        std::max<std::size_t>(1, static_cast<std::size_t>(std::sqrt(static_cast<double>(n >> 18))));
    ImageSummary summary = summarise_image(image, f, !options.threshold, threads);
    if (std::find(summary.non_finite.begin(), summary.non_finite.end(), 1) !=
        summary.non_finite.end())
        check_linear_image(image);  // throws for the first non-finite value (if not an overflow)
    s.threshold = options.threshold ? *options.threshold
                                    : automatic_level(image, std::move(summary.sample), options, s);

    const auto t = static_cast<float>(s.threshold);
    const cv::Mat small = reduced_mask(summary, t);
    cv::Mat labels, stats, centroids;
    const int count = cv::connectedComponentsWithStats(small, labels, stats, centroids, 8, CV_32S);
    int best = 0, best_area = 0;
    for (int k = 1; k < count; ++k) {
        const int area = stats.at<int>(k, cv::CC_STAT_AREA);
        if (area > best_area) {
            best_area = area;
            best = k;
        }
    }
    std::size_t object_pixels = 0;
    double sx = 0, sy = 0;
    s.col_min = w;
    s.row_min = h;
    if (best != 0) {
        // The mask is each row's run from its first to its last pixel (the gaps between them
        // filled: the objects measured here — a cylinder or a sphere seen whole — are convex
        // along rows).
        outline.rows = object_runs(avg, labels, stats, best, w, h, f, t);
        for (std::size_t r = 0; r < h; ++r) {
            const RowRun run = outline.rows[r];
            if (run.begin == run.end) continue;
            const std::size_t first = run.begin, last = run.end - 1, length = run.end - run.begin;
            object_pixels += length;
            // Counts, centroid, bounding box of the filled rows.
            sx += 0.5 * static_cast<double>(first + last) * static_cast<double>(length);
            sy += static_cast<double>(r) * static_cast<double>(length);
            s.col_min = std::min(s.col_min, first);
            s.col_max = std::max(s.col_max, last + 1);
            s.row_min = std::min(s.row_min, r);
            s.row_max = r + 1;
        }
    }
    if (best == 0 ||
        static_cast<double>(object_pixels) < options.min_object_fraction * static_cast<double>(n))
        throw DataError(
            concat(image_name(image), ": no object found: the largest region brighter than ",
                   format_number(s.threshold), " covers ", std::to_string(object_pixels), " of ",
                   std::to_string(n), " pixels, below the minimum object fraction ",
                   format_number(options.min_object_fraction)));

    s.pixel_count = object_pixels;
    const auto np = static_cast<double>(s.pixel_count);
    s.centroid_x_px = sx / np + 0.5;
    s.centroid_y_px = sy / np + 0.5;
    s.touches_left = s.col_min == 0;
    s.touches_right = s.col_max == w;
    s.touches_top = s.row_min == 0;
    s.touches_bottom = s.row_max == h;
    add_boundary_points(avg, RunMask{outline.rows, w, h}, s);
    return outline;
}

// ---------------------------------------------------------------------------------------------

CircleFit fit_circle(const std::vector<EdgePoint>& points) {
    const std::size_t n = points.size();
    if (n < 3)
        throw InvalidArgument(
            concat("a circle fit needs at least 3 points, got ", std::to_string(n)));
    double mx = 0, my = 0;
    for (const EdgePoint& p : points) {
        if (!std::isfinite(p.x_px) || !std::isfinite(p.y_px))
            throw InvalidArgument("circle fit: a point has a non-finite coordinate");
        mx += p.x_px;
        my += p.y_px;
    }
    mx /= static_cast<double>(n);
    my /= static_cast<double>(n);
    // Kåsa: x² + y² + D x + E y + F = 0 in least squares (coordinates about the mean).
    Eigen::MatrixXd A(static_cast<Eigen::Index>(n), 3);
    Eigen::VectorXd b(static_cast<Eigen::Index>(n));
    double spread = 0;
    for (std::size_t k = 0; k < n; ++k) {
        const double x = points[k].x_px - mx, y = points[k].y_px - my;
        const auto i = static_cast<Eigen::Index>(k);
        A(i, 0) = x;
        A(i, 1) = y;
        A(i, 2) = 1.0;
        b(i) = -(x * x + y * y);
        spread = std::max(spread, std::hypot(x, y));
    }
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
    const auto no_circle = [] {
        return DataError("circle fit: the points are collinear or coincide (no circle)");
    };
    if (qr.rank() < 3 || !(spread > 0)) throw no_circle();
    const Eigen::Vector3d sol = qr.solve(b);
    double cx = -0.5 * sol(0), cy = -0.5 * sol(1);
    double R2 = cx * cx + cy * cy - sol(2);
    if (!(R2 > 0) || std::sqrt(R2) > 1e6 * spread) throw no_circle();
    double R = std::sqrt(R2);
    // Gauss–Newton on the geometric residuals |p − c| − R.
    for (int it = 0; it < 50; ++it) {
        Eigen::Matrix3d JtJ = Eigen::Matrix3d::Zero();
        Eigen::Vector3d Jtr = Eigen::Vector3d::Zero();
        for (const EdgePoint& p : points) {
            const double dx = p.x_px - mx - cx, dy = p.y_px - my - cy;
            const double rho = std::hypot(dx, dy);
            if (!(rho > 0)) continue;
            const Eigen::Vector3d J(-dx / rho, -dy / rho, -1.0);
            JtJ += J * J.transpose();
            Jtr += J * (rho - R);
        }
        const Eigen::Vector3d step = JtJ.ldlt().solve(-Jtr);
        if (!step.allFinite()) break;
        cx += step(0);
        cy += step(1);
        R += step(2);
        if (step.norm() < 1e-12 * (1.0 + R)) break;
    }
    if (!(R > 0) || !std::isfinite(R)) throw no_circle();
    double ss = 0;
    for (const EdgePoint& p : points) {
        const double e = std::hypot(p.x_px - mx - cx, p.y_px - my - cy) - R;
        ss += e * e;
    }
    CircleFit fit;
    fit.centre_x_px = cx + mx;
    fit.centre_y_px = cy + my;
    fit.radius_px = R;
    fit.rms_residual_px = std::sqrt(ss / static_cast<double>(n));
    fit.points = n;
    return fit;
}

CircleFit fit_sphere_circle(const Silhouette& silhouette, const CircleFitOptions& options) {
    check::non_negative("circle max_rms_px", options.max_rms_px);
    check::non_negative("circle max_rms_fraction", options.max_rms_fraction);
    if (silhouette.touches_border())
        throw DataError(
            concat("the object touches the image border (", silhouette.touches_left ? "left " : "",
                   silhouette.touches_right ? "right " : "", silhouette.touches_top ? "top " : "",
                   silhouette.touches_bottom ? "bottom " : "",
                   "): part of the sphere's outline is missing; frame the whole sphere or give the "
                   "circle"));
    if (silhouette.boundary.size() < 8)
        throw DataError(concat("the silhouette has ", std::to_string(silhouette.boundary.size()),
                               " edge points, too few for a circle (at least 8)"));
    const CircleFit fit = fit_circle(silhouette.boundary);
    const double limit = std::max(options.max_rms_px, options.max_rms_fraction * fit.radius_px);
    if (fit.rms_residual_px > limit)
        throw DataError(concat(
            "the silhouette is not circular: the RMS distance of its edge from "
            "the best circle is ",
            format_number(fit.rms_residual_px), " px, above the limit ", format_number(limit),
            " px (", format_number(fit.rms_residual_px / limit), " times)"));
    return fit;
}

// ---------------------------------------------------------------------------------------------

double CylinderAxis::across_x() const {
    double ux = -direction_y, uy = direction_x;
    if (ux < -1e-12 || (std::abs(ux) <= 1e-12 && uy > 0)) {
        ux = -ux;
        uy = -uy;
    }
    (void)uy;
    return ux;
}

double CylinderAxis::across_y() const {
    double ux = -direction_y, uy = direction_x;
    if (ux < -1e-12 || (std::abs(ux) <= 1e-12 && uy > 0)) uy = -uy;
    return uy;
}

double CylinderAxis::across_distance_px(double x_px, double y_px) const {
    return (x_px - point_x_px) * across_x() + (y_px - point_y_px) * across_y();
}

CylinderAxis cylinder_axis_from_line(double point_x_px, double point_y_px, double direction_x,
                                     double direction_y, double radius_px) {
    check::finite("cylinder axis point x", point_x_px);
    check::finite("cylinder axis point y", point_y_px);
    check::positive("cylinder radius", radius_px, " px");
    const double norm = std::hypot(direction_x, direction_y);
    if (!(norm > 0) || !std::isfinite(norm))
        throw InvalidArgument(concat("cylinder axis direction (", format_number(direction_x), ", ",
                                     format_number(direction_y), ") must be finite and not zero"));
    CylinderAxis axis;
    axis.point_x_px = point_x_px;
    axis.point_y_px = point_y_px;
    axis.direction_x = direction_x / norm;
    axis.direction_y = direction_y / norm;
    axis.radius_px = radius_px;
    return axis;
}

CylinderAxis cylinder_axis_from_edges(const EdgePoint& a0, const EdgePoint& a1, const EdgePoint& b0,
                                      const EdgePoint& b1) {
    for (const EdgePoint* p : {&a0, &a1, &b0, &b1})
        if (!std::isfinite(p->x_px) || !std::isfinite(p->y_px))
            throw InvalidArgument("cylinder edge: a point has a non-finite coordinate");
    const Eigen::Vector2d pa0(a0.x_px, a0.y_px), pa1(a1.x_px, a1.y_px);
    const Eigen::Vector2d pb0(b0.x_px, b0.y_px), pb1(b1.x_px, b1.y_px);
    Eigen::Vector2d da = pa1 - pa0, db = pb1 - pb0;
    if (!(da.norm() > 0) || !(db.norm() > 0))
        throw InvalidArgument("cylinder edge: the two points of an edge coincide");
    da.normalize();
    db.normalize();
    if (da.dot(db) < 0) db = -db;
    const double angle = std::asin(std::min(1.0, std::abs(da.x() * db.y() - da.y() * db.x())));
    if (angle > deg_to_rad(1.0))
        throw InvalidArgument(concat("cylinder edges are not parallel: they differ by ",
                                     format_number(rad_to_deg(angle)),
                                     " deg, more than the 1 deg allowed"));
    const Eigen::Vector2d dir = (da + db).normalized();
    const Eigen::Vector2d u(-dir.y(), dir.x());
    const double ca = 0.5 * (pa0 + pa1).dot(u), cb = 0.5 * (pb0 + pb1).dot(u);
    if (!(std::abs(ca - cb) > 0)) throw InvalidArgument("cylinder edges coincide (zero radius)");
    const Eigen::Vector2d mid = 0.25 * (pa0 + pa1 + pb0 + pb1);
    return cylinder_axis_from_line(mid.x(), mid.y(), dir.x(), dir.y(), 0.5 * std::abs(ca - cb));
}

CylinderAxis fit_cylinder_axis(const Silhouette& silhouette, const CylinderAxisOptions& options) {
    check::positive("cylinder axis outlier_px", options.outlier_px);
    check::non_negative("cylinder axis max_rms_px", options.max_rms_px);
    check::non_negative("cylinder axis max_rms_fraction", options.max_rms_fraction);
    check::positive("cylinder axis max_angle_deg", options.max_angle_deg);
    const std::vector<EdgePoint>& pts = silhouette.boundary;
    if (pts.size() < 8)
        throw DataError(concat("the silhouette has ", std::to_string(pts.size()),
                               " edge points, too few for a cylinder's two edges"));
    // Edge orientation: doubled-angle mean of the outward normals.
    double c2 = 0, s2 = 0;
    for (const EdgePoint& p : pts) {
        c2 += p.normal_x * p.normal_x - p.normal_y * p.normal_y;
        s2 += 2.0 * p.normal_x * p.normal_y;
    }
    if (!(std::hypot(c2, s2) > 0.5 * static_cast<double>(pts.size())))
        throw DataError(
            "the silhouette is not cylinder-like: its outline has no dominant "
            "direction (two straight parallel edges)");
    const double phi_n = 0.5 * std::atan2(s2, c2);  // normal direction
    Eigen::Vector2d u(std::cos(phi_n), std::sin(phi_n));
    Eigen::Vector2d a(-u.y(), u.x());
    const Eigen::Vector2d centroid(silhouette.centroid_x_px, silhouette.centroid_y_px);

    // Per side: line d = α + β t in the (a, u) frame about the centroid; outliers dropped.
    struct Side {
        std::vector<Eigen::Vector2d> tv;  // (t, d)
        double alpha = 0, beta = 0, rms = 0;
        std::size_t used = 0;
    };
    std::array<Side, 2> sides;
    for (const EdgePoint& p : pts) {
        const Eigen::Vector2d q = Eigen::Vector2d(p.x_px, p.y_px) - centroid;
        const double d = q.dot(u);
        sides[d > 0 ? 1 : 0].tv.emplace_back(q.dot(a), d);
    }
    const std::size_t most = std::max(sides[0].tv.size(), sides[1].tv.size());
    for (std::size_t k = 0; k < 2; ++k)
        if (sides[k].tv.size() < std::max<std::size_t>(4, most / 4))
            throw DataError(concat(
                "the cylinder's ", k == 0 ? "first" : "second", " edge is missing (",
                std::to_string(sides[k].tv.size()), " edge points against ", std::to_string(most),
                " on the other side): the object touches the image border along its side or is "
                "not a cylinder seen side-on; frame both edges or give the axis"));
    auto fit_side = [&](Side& side) {
        // First pass: median of d (robust start), then least squares on the inliers twice.
        std::vector<double> ds;
        ds.reserve(side.tv.size());
        for (const auto& v : side.tv) ds.push_back(v.y());
        std::nth_element(ds.begin(), ds.begin() + static_cast<std::ptrdiff_t>(ds.size() / 2),
                         ds.end());
        side.alpha = ds[ds.size() / 2];
        side.beta = 0;
        for (int pass = 0; pass < 3; ++pass) {
            double St = 0, Sd = 0, Stt = 0, Std = 0, N = 0;
            for (std::size_t i = 0; i < side.tv.size(); ++i) {
                const double t = side.tv[i].x(), d = side.tv[i].y();
                if (std::abs(d - side.alpha - side.beta * t) > options.outlier_px) continue;
                St += t;
                Sd += d;
                Stt += t * t;
                Std += t * d;
                N += 1;
            }
            const double det = N * Stt - St * St;
            if (N < 3 || !(det > 0)) break;
            side.beta = (N * Std - St * Sd) / det;
            side.alpha = (Sd - side.beta * St) / N;
        }
        double ss = 0;
        side.used = 0;
        for (std::size_t i = 0; i < side.tv.size(); ++i) {
            const double e = side.tv[i].y() - side.alpha - side.beta * side.tv[i].x();
            if (std::abs(e) > options.outlier_px) continue;
            ss += e * e;
            ++side.used;
        }
        side.rms = side.used ? std::sqrt(ss / static_cast<double>(side.used)) : 0.0;
    };
    fit_side(sides[0]);
    fit_side(sides[1]);
    for (std::size_t k = 0; k < 2; ++k)
        if (sides[k].used < 4)
            throw DataError(
                "the silhouette is not cylinder-like: an edge has fewer than 4 points "
                "on a straight line");
    const double angle = std::abs(std::atan(sides[1].beta) - std::atan(sides[0].beta));
    if (angle > deg_to_rad(options.max_angle_deg))
        throw DataError(
            concat("the silhouette is not cylinder-like: its edges differ in direction "
                   "by ",
                   format_number(rad_to_deg(angle)), " deg, more than the ",
                   format_number(options.max_angle_deg), " deg allowed"));
    const double beta = 0.5 * (sides[0].beta + sides[1].beta);
    const double alpha = 0.5 * (sides[0].alpha + sides[1].alpha);
    const double cosb = 1.0 / std::sqrt(1.0 + beta * beta);
    const double radius = 0.5 * (sides[1].alpha - sides[0].alpha) * cosb;
    const Eigen::Vector2d dir = (a + beta * u).normalized();
    const Eigen::Vector2d point = centroid + alpha * u;
    CylinderAxis axis = cylinder_axis_from_line(point.x(), point.y(), dir.x(), dir.y(), radius);
    axis.detected = true;
    axis.points = sides[0].used + sides[1].used;
    const double n0 = static_cast<double>(sides[0].used), n1 = static_cast<double>(sides[1].used);
    axis.rms_residual_px =
        std::sqrt((sides[0].rms * sides[0].rms * n0 + sides[1].rms * sides[1].rms * n1) /
                  (n0 + n1)) *
        cosb;
    const double limit = std::max(options.max_rms_px, options.max_rms_fraction * radius);
    if (axis.rms_residual_px > limit)
        throw DataError(concat(
            "the silhouette is not cylinder-like: the RMS distance of its edges "
            "from two straight lines is ",
            format_number(axis.rms_residual_px), " px, above the limit ", format_number(limit),
            " px (", format_number(axis.rms_residual_px / limit), " times)"));
    // Outliers beyond outlier_px are allowed (a cylinder ending inside the image) but not most.
    const std::size_t total = sides[0].tv.size() + sides[1].tv.size();
    if (static_cast<double>(axis.points) < 0.5 * static_cast<double>(total))
        throw DataError(concat("the silhouette is not cylinder-like: only ",
                               std::to_string(axis.points), " of ", std::to_string(total),
                               " edge points lie within ", format_number(options.outlier_px),
                               " px of two straight lines"));
    return axis;
}

}  // namespace roughscope::image
