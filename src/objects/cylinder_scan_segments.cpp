// Step 2 of the cylinder profile (cylinder_steps.hpp): the band scan's segment paths, without a
// region. A row is cut into segments whose classification is evaluated at their ends only (found
// from the next edge along the row — d and t are linear along it — then checked), and a segment
// without a flagged pixel is summed without per-pixel tests. The per-pixel path
// (cylinder_scan.cpp) is their reference: they agree to rounding (docs/curved-objects.md,
// "Cylinder profile").
#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "cylinder_scan.hpp"

namespace roughscope::image::detail {
namespace {

// Σv, Σv² and Σ(v_{j+1} − v_j)² of n values, each in four interleaved lanes (vectorised).
struct RunMoments {
    double sum = 0, sum2 = 0, neighbour_diff2 = 0;
};
RunMoments run_moments(const float* v, std::size_t n) {
    double s[4] = {}, q[4] = {}, d[4] = {};
    std::size_t j = 0;
    for (; j + 4 <= n; j += 4)
        for (std::size_t k = 0; k < 4; ++k) {
            const double x = v[j + k];
            s[k] += x;
            q[k] += x * x;
        }
    for (; j < n; ++j) {
        const double x = v[j];
        s[0] += x;
        q[0] += x * x;
    }
    for (j = 0; j + 5 <= n; j += 4)
        for (std::size_t k = 0; k < 4; ++k) {
            const double dx = static_cast<double>(v[j + k + 1]) - static_cast<double>(v[j + k]);
            d[k] += dx * dx;
        }
    for (; j + 1 < n; ++j) {
        const double dx = static_cast<double>(v[j + 1]) - static_cast<double>(v[j]);
        d[0] += dx * dx;
    }
    return {(s[0] + s[1]) + (s[2] + s[3]), (q[0] + q[1]) + (q[2] + q[3]),
            (d[0] + d[1]) + (d[2] + d[3])};
}

// Along a steep axis: a row is cut into segments of one bin and one slice. A pixel's half-sub-bin
// is kept per column: the column's d moves by u_y a row, so its half-sub-bin is recomputed only
// at the rows where it can have changed (scheduled from the distance to the half-sub-bin's
// edges), and the column's count and Σd are added to the half-sub-bin when it changes. Noise from
// differences with the previous row.
class SteepScan {
  public:
    SteepScan(const ScanSetup& s, Band& band)
        : s_(s),
          band_(band),
          acc_(band.outputs()),
          col_hs_(s.width, kNone),
          col_n_(s.width, 0),
          col_d0_(s.width, 0.0),
          recheck_(band.r1 - band.r0),
          prev_bin_(s.width, -1),
          above_buffer_(s.p1 ? s.width : 0),
          row_buffer_(s.p1 ? s.width : 0) {}

    void run() {
        for (std::size_t c = 0; c < s_.width; ++c) set_column(band_.r0, c);
        if (band_.r0 > 0) {  // the row before the band: bins only (summed by the band above)
            const RowRun run = s_.mark_row_bins(band_.r0 - 1, prev_bin_.data());
            prev_begin_ = run.begin;
            prev_end_ = run.end;
            above_ = s_.values_of(band_.r0 - 1, run.begin, run.end, above_buffer_.data());
        }
        for (std::size_t r = band_.r0; r < band_.r1; ++r) scan_row(r);
        for (std::size_t c = 0; c < s_.width; ++c) flush(c);
    }

  private:
    static constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

    // The half-sub-bin at distance d, kNone outside the table, and the distance in d to its
    // nearest edge.
    std::uint32_t half_sub_bin(double d, double& room) const {
        const double R = s_.R;
        const double* const split_of = s_.binning.split.data();
        const double sf = d * kSubBinsPerPx + s_.sub_offset;
        if (!(sf >= 0.0 && sf < static_cast<double>(s_.n_sub))) {
            room = sf < 0.0 ? -R - d : d - (static_cast<double>(s_.n_sub) / kSubBinsPerPx - R);
            return kNone;
        }
        const auto k = static_cast<std::size_t>(sf);
        const double lo = static_cast<double>(k) / kSubBinsPerPx - R;
        const double hi = lo + 1.0 / kSubBinsPerPx;
        const bool upper = d >= split_of[k];
        room = upper ? std::min(d - split_of[k], hi - d)
                     : std::min(d - lo, std::min(split_of[k], hi) - d);
        return static_cast<std::uint32_t>(2 * k + (upper ? 1 : 0));
    }
    // The column's count and Σd to its half-sub-bin.
    void flush(std::size_t c) {
        if (col_n_[c] == 0) return;
        const std::uint32_t hs = col_hs_[c];
        assert(hs != kNone && hs >= acc_.sub_lo && hs < acc_.sub_lo + band_.n_subs);
        acc_.sub_count[hs - acc_.sub_lo] += col_n_[c];
        acc_.sub_d[hs - acc_.sub_lo] +=
            col_d0_[c] + static_cast<double>(col_n_[c]) * (static_cast<double>(c) * s_.ux);
        col_n_[c] = 0;
        col_d0_[c] = 0.0;
    }
    // Column c's half-sub-bin at row r; it is kept while its d, moving by |u_y| a row, stays
    // inside it.
    void set_column(std::size_t r, std::size_t c) {
        double room = 0.0;
        const std::uint32_t hs = half_sub_bin(s_.row_d0(r) + static_cast<double>(c) * s_.ux, room);
        if (hs != col_hs_[c]) {
            flush(c);
            col_hs_[c] = hs;
        }
        const std::size_t next = recheck_row(r, room, std::abs(s_.uy), band_.r1);
        if (next < band_.r1) recheck_[next - band_.r0].push_back(static_cast<std::uint32_t>(c));
    }
    void scan_row(std::size_t r);
    // The estimated end of the segment at column c: the next edge between bins (in d) and the
    // next slice boundary (in t), whichever comes first along the row.
    double segment_estimate(std::size_t c, double d0, double t0, std::size_t end,
                            std::vector<double>::const_iterator& above_d) const;
    // Segment [c, e) of bin b and slice `slice` of row r into the sums.
    void add_segment(std::int32_t b, std::size_t slice, std::size_t c, std::size_t e,
                     const float* vals, const std::uint8_t* row_flags, double d0);

    const ScanSetup& s_;
    Band& band_;
    const Band::Outputs acc_;
    std::vector<std::uint32_t> col_hs_, col_n_;
    std::vector<double> col_d0_;
    std::vector<std::vector<std::uint32_t>> recheck_;
    std::vector<std::int32_t> prev_bin_;
    std::size_t prev_begin_ = 0, prev_end_ = 0;
    std::vector<float> above_buffer_, row_buffer_;
    const float* above_ = nullptr;  // the previous row's values
};

double SteepScan::segment_estimate(std::size_t c, double d0, double t0, std::size_t end,
                                   std::vector<double>::const_iterator& above_d) const {
    const std::vector<double>& class_edges = s_.class_edges;
    const double ux = s_.ux, ax = s_.ax;
    const double d = d0 + static_cast<double>(c) * ux;
    double end_estimate = static_cast<double>(end);
    if (ux > 0) {
        while (above_d != class_edges.end() && *above_d <= d) ++above_d;
        if (above_d != class_edges.end())
            end_estimate = std::min(end_estimate, column_past(*above_d, d0, ux));
    } else {
        while (above_d != class_edges.begin() && *(above_d - 1) > d) --above_d;
        if (above_d != class_edges.begin())
            end_estimate = std::min(end_estimate, column_past(*(above_d - 1), d0, ux));
    }
    if (ax != 0.0) {
        const double t = t0 + static_cast<double>(c) * ax;
        end_estimate = std::min(end_estimate,
                                column_past(ax > 0 ? std::floor(t) + 1.0 : std::floor(t), t0, ax));
    }
    return end_estimate;
}

void SteepScan::scan_row(std::size_t r) {
    for (const std::uint32_t c : recheck_[r - band_.r0]) set_column(r, c);
    std::int32_t* const prev_b = prev_bin_.data();
    const RowRun run = s_.row_run(r);
    clear_outside(prev_b, prev_begin_, prev_end_, run);
    prev_begin_ = run.begin;
    prev_end_ = run.end;
    const double d0 = s_.row_d0(r), t0 = s_.row_t0(r);
    const double ux = s_.ux;
    const float* const vals = s_.values_of(r, run.begin, run.end, row_buffer_.data());
    const std::uint8_t* const row_flags = s_.image.flags.data() + r * s_.width;
    const auto class_at = [&](std::size_t c) {
        const double d = d0 + static_cast<double>(c) * ux;
        return std::pair(s_.unused_side(s_.pixel_bin(0, d).bin, d), s_.slice_at(t0, c));
    };
    // The first edge above d at the segment's start (it moves one way along the row).
    auto above_d = std::upper_bound(s_.class_edges.begin(), s_.class_edges.end(),
                                    d0 + static_cast<double>(run.begin) * ux);
    auto next_key = run.begin < run.end ? class_at(run.begin) : std::pair(-1, 0UL);
    for (std::size_t c = run.begin; c < run.end;) {
        const auto key = next_key;
        // The segment's end: estimated, then checked.
        const double end_estimate = segment_estimate(c, d0, t0, run.end, above_d);
        std::size_t e = static_cast<std::size_t>(
            std::clamp(end_estimate, static_cast<double>(c + 1), static_cast<double>(run.end)));
        e = segment_end(class_at, key, c, e, run.end);
        if (e < run.end) next_key = class_at(e);
        if (key.first < 0)
            std::fill(prev_b + c, prev_b + e, -1);
        else
            add_segment(key.first, key.second, c, e, vals, row_flags, d0);
        c = e;
    }
    if (s_.p1) std::swap(above_buffer_, row_buffer_);
    above_ = s_.p1 ? above_buffer_.data() : vals;
}

void SteepScan::add_segment(std::int32_t b, std::size_t slice, std::size_t c, std::size_t e,
                            const float* vals, const std::uint8_t* row_flags, double d0) {
    const Band::Outputs acc = acc_;
    std::int32_t* const prev_b = prev_bin_.data();
    std::uint32_t* const col_n = col_n_.data();
    double* const col_d0 = col_d0_.data();
    const float* const above = above_;
    assert(slice >= acc.slice_lo && slice < acc.slice_lo + acc.band_slices);
    const std::size_t si =
        (static_cast<std::size_t>(b) - acc.bin_lo) * acc.band_slices + (slice - acc.slice_lo);
    BinSums& bs = acc.bins[static_cast<std::size_t>(b)];
    double sum_a = 0, sum_b = 0, sum2_a = 0, sum2_b = 0, diff2 = 0;
    std::size_t count = 0, diffs = 0;
    unsigned flag_bits = 0;
    for (std::size_t j = c; j < e; ++j) flag_bits |= row_flags[j];
    if (flag_bits == 0) {
        std::size_t j = c;
        for (; j + 1 < e; j += 2) {
            const double va = vals[j], vb = vals[j + 1];
            sum_a += va;
            sum_b += vb;
            sum2_a += va * va;
            sum2_b += vb * vb;
        }
        if (j < e) {
            const double va = vals[j];
            sum_a += va;
            sum2_a += va * va;
        }
        for (j = c; j < e; ++j) {
            if (prev_b[j] == b) {
                const double diff = static_cast<double>(vals[j]) - above[j];
                diff2 += diff * diff;
                ++diffs;
            }
            prev_b[j] = b;
            ++col_n[j];
            col_d0[j] += d0;
        }
        count = e - c;
    } else {
        for (std::size_t j = c; j < e; ++j) {
            if (row_flags[j] != 0) {
                ++band_.flagged;
                ++bs.flagged;
                prev_b[j] = -1;
                continue;
            }
            const double v = vals[j];
            sum_a += v;
            sum2_a += v * v;
            ++count;
            if (prev_b[j] == b) {
                const double diff = v - above[j];
                diff2 += diff * diff;
                ++diffs;
            }
            prev_b[j] = b;
            ++col_n[j];
            col_d0[j] += d0;
        }
    }
    const double sum = sum_a + sum_b;
    bs.sum += sum;
    bs.sum2 += sum2_a + sum2_b;
    bs.diff2 += diff2;
    bs.count += count;
    bs.diffs += diffs;
    acc.slice_sum[si] += sum;
    acc.slice_count[si] += static_cast<std::uint32_t>(count);
}

// Along an axis closer to the image's rows. Along a row d moves by u_x a pixel (|u_x| < 0.71) and
// t by a_x: a row is cut into segments of one bin and one half-sub-bin (their pixels' count and
// Σd in closed form), and each column keeps the slice its sums belong to until the rows at which
// its t, moving by a_y a row, can have crossed a slice boundary (or its bin changes); noise from
// differences with the left neighbour, inside a flag-free segment without per-pixel tests.
class ShallowScan {
  public:
    ShallowScan(const ScanSetup& s, Band& band)
        : s_(s),
          band_(band),
          acc_(band.outputs()),
          col_bin_(s.width, -1),
          col_slice_(s.width, 0),
          col_n_(s.width, 0),
          col_sum_(s.width, 0.0),
          recheck_(band.r1 - band.r0),
          row_buffer_(s.p1 ? s.width : 0) {}

    void run() {
        for (std::size_t c = 0; c < s_.width; ++c) set_slice(band_.r0, c);
        for (std::size_t r = band_.r0; r < band_.r1; ++r) scan_row(r);
        for (std::size_t c = 0; c < s_.width; ++c) flush(c);
    }

  private:
    // The column's sums to its bin's slice.
    void flush(std::size_t c) {
        if (col_n_[c] == 0) return;
        assert(col_bin_[c] >= 0);
        const std::size_t b = static_cast<std::size_t>(col_bin_[c]);
        assert(col_slice_[c] >= acc_.slice_lo && col_slice_[c] < acc_.slice_lo + acc_.band_slices);
        const std::size_t si =
            (b - acc_.bin_lo) * acc_.band_slices + (col_slice_[c] - acc_.slice_lo);
        acc_.slice_sum[si] += col_sum_[c];
        acc_.slice_count[si] += col_n_[c];
        col_n_[c] = 0;
        col_sum_[c] = 0.0;
    }
    // A column's slice, and when it must be found again: t moves by |a_y| a row.
    void set_slice(std::size_t r, std::size_t c) {
        const std::size_t last_slice = s_.n_slices - 1;
        const double t0 = s_.row_t0(r);
        const double t = t0 + static_cast<double>(c) * s_.ax;
        const std::size_t sl = s_.slice_at(t0, c);
        const double below =
            sl == 0 ? -std::numeric_limits<double>::infinity() : static_cast<double>(sl);
        const double above = sl == last_slice ? std::numeric_limits<double>::infinity()
                                              : static_cast<double>(sl + 1);
        if (sl != col_slice_[c]) {
            flush(c);
            col_slice_[c] = sl;
        }
        const std::size_t next =
            recheck_row(r, std::min(t - below, above - t), std::abs(s_.ay), band_.r1);
        if (next < band_.r1) recheck_[next - band_.r0].push_back(static_cast<std::uint32_t>(c));
    }
    void scan_row(std::size_t r);
    // The estimated end of the segment of `key` (bin, half-sub-bin) at column c: the next edge of
    // its half-sub-bin (a used bin) or between bins (the class edges) along the row.
    double segment_estimate(std::pair<std::int32_t, std::size_t> key, std::size_t c, double d0,
                            std::size_t end, std::vector<double>::const_iterator& above_d) const;
    // Segment [c, e) of bin b and half-sub-bin `sub` of a row into the sums.
    void add_segment(std::int32_t b, std::size_t sub, std::size_t c, std::size_t e,
                     const float* vals, const std::uint8_t* row_flags, double d0);

    const ScanSetup& s_;
    Band& band_;
    const Band::Outputs acc_;
    std::vector<std::int32_t> col_bin_;
    std::vector<std::size_t> col_slice_;
    std::vector<std::uint32_t> col_n_;
    std::vector<double> col_sum_;
    std::vector<std::vector<std::uint32_t>> recheck_;
    std::vector<float> row_buffer_;
    float left_value_ = 0.0F;  // the last used pixel on the left in the row, and its bin
    std::int32_t left_bin_ = -1;
};

double ShallowScan::segment_estimate(std::pair<std::int32_t, std::size_t> key, std::size_t c,
                                     double d0, std::size_t end,
                                     std::vector<double>::const_iterator& above_d) const {
    const std::vector<double>& class_edges = s_.class_edges;
    const double ux = s_.ux, R = s_.R;
    const double* const split_of = s_.binning.split.data();
    const double d = d0 + static_cast<double>(c) * ux;
    double end_estimate = static_cast<double>(end);
    if (ux != 0.0) {
        if (ux > 0)
            while (above_d != class_edges.end() && *above_d <= d) ++above_d;
        else
            while (above_d != class_edges.begin() && *(above_d - 1) > d) --above_d;
        if (key.first >= 0) {
            const std::size_t k = key.second / 2;
            const double lo = static_cast<double>(k) / kSubBinsPerPx - R;
            const double hi = lo + 1.0 / kSubBinsPerPx;
            const bool upper = key.second % 2 == 1;
            const double edge =
                ux > 0 ? (upper ? hi : std::min(split_of[k], hi)) : (upper ? split_of[k] : lo);
            end_estimate = std::min(end_estimate, column_past(edge, d0, ux));
        } else if (ux > 0 && above_d != class_edges.end()) {
            end_estimate = std::min(end_estimate, column_past(*above_d, d0, ux));
        } else if (ux < 0 && above_d != class_edges.begin()) {
            end_estimate = std::min(end_estimate, column_past(*(above_d - 1), d0, ux));
        }
    }
    return end_estimate;
}

void ShallowScan::scan_row(std::size_t r) {
    for (const std::uint32_t c : recheck_[r - band_.r0]) set_slice(r, c);
    const RowRun run = s_.row_run(r);
    const double d0 = s_.row_d0(r);
    const double ux = s_.ux;
    const float* const vals = s_.values_of(r, run.begin, run.end, row_buffer_.data());
    const std::uint8_t* const row_flags = s_.image.flags.data() + r * s_.width;
    // The key of a pixel: its bin and (for a used bin) its half-sub-bin.
    const auto key_at = [&](std::size_t c) {
        const double d = d0 + static_cast<double>(c) * ux;
        const PixelBin pb = s_.pixel_bin(0, d);
        return std::pair(s_.unused_side(pb.bin, d), pb.bin >= 0 ? pb.sub : std::size_t{0});
    };
    auto above_d = std::upper_bound(s_.class_edges.begin(), s_.class_edges.end(),
                                    d0 + static_cast<double>(run.begin) * ux);
    left_value_ = 0.0F;
    left_bin_ = -1;
    auto next_key = run.begin < run.end ? key_at(run.begin) : std::pair(-1, std::size_t{0});
    for (std::size_t c = run.begin; c < run.end;) {
        const auto key = next_key;
        // The segment's end: estimated, then checked.
        const double end_estimate = segment_estimate(key, c, d0, run.end, above_d);
        std::size_t e = static_cast<std::size_t>(
            std::clamp(end_estimate, static_cast<double>(c + 1), static_cast<double>(run.end)));
        e = segment_end(key_at, key, c, e, run.end);
        if (e < run.end) next_key = key_at(e);
        if (key.first < 0)
            left_bin_ = -1;
        else
            add_segment(key.first, key.second, c, e, vals, row_flags, d0);
        c = e;
    }
}

void ShallowScan::add_segment(std::int32_t b, std::size_t sub, std::size_t c, std::size_t e,
                              const float* vals, const std::uint8_t* row_flags, double d0) {
    const Band::Outputs acc = acc_;
    assert(sub >= acc.sub_lo && sub < acc.sub_lo + band_.n_subs);
    BinSums& bs = acc.bins[static_cast<std::size_t>(b)];
    unsigned flag_bits = 0;
    for (std::size_t j = c; j < e; ++j) flag_bits |= row_flags[j];
    double sum = 0, sum2 = 0, diff2 = 0, column_sum = 0;
    std::size_t count = 0, diffs = 0;
    if (flag_bits == 0) {
        // Every pixel used: the moments and the differences of neighbours inside the segment in
        // lanes, the difference with the pixel on its left, Σ column in closed form; the columns'
        // slice sums (a column whose bin changes first hands its sums over).
        if (left_bin_ == b) {
            const double diff = static_cast<double>(vals[c]) - left_value_;
            diff2 += diff * diff;
            ++diffs;
        }
        const RunMoments m = run_moments(vals + c, e - c);
        sum = m.sum;
        sum2 = m.sum2;
        diff2 += m.neighbour_diff2;
        count = e - c;
        diffs += count - 1;
        column_sum = 0.5 * static_cast<double>(c + e - 1) * static_cast<double>(count);
        unsigned other_bin = 0;
        for (std::size_t j = c; j < e; ++j) other_bin |= col_bin_[j] != b ? 1U : 0U;
        if (other_bin != 0)
            for (std::size_t j = c; j < e; ++j)
                if (col_bin_[j] != b) {
                    flush(j);
                    col_bin_[j] = b;
                }
        for (std::size_t j = c; j < e; ++j) {
            col_sum_[j] += static_cast<double>(vals[j]);
            ++col_n_[j];
        }
        left_bin_ = b;
        left_value_ = vals[e - 1];
    } else {
        for (std::size_t j = c; j < e; ++j) {
            if (row_flags[j] != 0) {
                ++band_.flagged;
                ++bs.flagged;
                left_bin_ = -1;
                continue;
            }
            const double v = vals[j];
            sum += v;
            sum2 += v * v;
            ++count;
            column_sum += static_cast<double>(j);
            if (left_bin_ == b) {
                const double diff = v - static_cast<double>(left_value_);
                diff2 += diff * diff;
                ++diffs;
            }
            left_bin_ = b;
            left_value_ = vals[j];
            if (col_bin_[j] != b) {
                flush(j);
                col_bin_[j] = b;
            }
            col_sum_[j] += v;
            ++col_n_[j];
        }
    }
    bs.sum += sum;
    bs.sum2 += sum2;
    bs.diff2 += diff2;
    bs.count += count;
    bs.diffs += diffs;
    acc.sub_count[sub - acc.sub_lo] += static_cast<std::uint32_t>(count);
    acc.sub_d[sub - acc.sub_lo] += static_cast<double>(count) * d0 + column_sum * s_.ux;
}

}  // namespace

void scan_band_steep(const ScanSetup& setup, Band& band) { SteepScan(setup, band).run(); }

void scan_band_shallow(const ScanSetup& setup, Band& band) { ShallowScan(setup, band).run(); }

}  // namespace roughscope::image::detail
