// The pieces of the cylinder's band scan (step 2 of cylinder_steps.hpp) shared by its per-pixel
// path (cylinder_scan.cpp) and its segment paths (cylinder_scan_segments.cpp).
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "cylinder_steps.hpp"

namespace roughscope::image::detail {

// Sub-bin k's edge and the bins on either side of it, side by side (one cache line a pixel; the
// two bins are read while the edge is compared).
struct SubBinEntry {
    double split = 0.0;
    std::array<std::int32_t, 2> bin{};
};

// The bin of a pixel and its half-sub-bin (bin −1: unused).
struct PixelBin {
    std::int32_t bin = -1;
    std::size_t sub = 0;
};

// What every path of the scan reads: the image, the region, the object's rows and the binning,
// with the tables derived from it.
struct ScanSetup {
    ScanSetup(const LinearImage& image, const std::uint8_t* region, const CylinderBinning& binning,
              const std::vector<RowRun>& object_rows);

    const LinearImage& image;
    const std::uint8_t* region;  // nullptr: every pixel
    const CylinderBinning& binning;
    const std::vector<RowRun>& object_rows;  // empty: every pixel
    std::size_t width;
    double R, ux, uy, ax, ay;  // radius; across() and the axis' direction (image coordinates)
    double sub_offset;         // R · kSubBinsPerPx: a distance's position in the sub-bins
    std::size_t n_sub, n_slices;
    const float *p0, *p1, *p2;  // the planes (p1 = p2 = nullptr: grey)
    double xc0;                 // 0.5 − P_x: column 0's centre relative to the axis' point
    std::vector<SubBinEntry> sub_bins;
    // Edges in d between the classes of consecutive half-sub-bins (and the table's ends).
    std::vector<double> class_edges;
    // The middle of the used bins' range of d (unused_side).
    double used_middle = 0.0;

    // The bin of pixel i at distance d and its half-sub-bin, or bin −1: outside the region, the
    // half or the limb. Flags are not looked at.
    PixelBin pixel_bin(std::size_t i, double d) const {
        const double sf = d * kSubBinsPerPx + sub_offset;
        if (!(sf >= 0.0 && sf < static_cast<double>(n_sub)) || (region && !region[i])) return {};
        const auto k = static_cast<std::size_t>(sf);
        const SubBinEntry& e = sub_bins[k];
        const std::size_t side = d >= e.split ? 1 : 0;
        return {e.bin[side], 2 * k + side};
    }
    // Row r's run of the object (silhouette.hpp: the mask is one run a row).
    RowRun row_run(std::size_t r) const {
        return object_rows.empty() ? RowRun{0, width} : object_rows[r];
    }
    // A row's d and t − t_min at column 0.
    double row_d0(std::size_t r) const {
        return xc0 * ux + (static_cast<double>(r) + 0.5 - binning.axis.point_y_px) * uy;
    }
    double row_t0(std::size_t r) const {
        return xc0 * ax + (static_cast<double>(r) + 0.5 - binning.axis.point_y_px) * ay -
               binning.t_min_px;
    }
    // Column c's slice in a row whose t − t_min at column 0 is t0.
    std::size_t slice_at(double t0, std::size_t c) const {
        return std::min(static_cast<std::size_t>(std::max(0.0, t0 + static_cast<double>(c) * ax)),
                        n_slices - 1);
    }
    // Row r's values over [begin, end) (RGB averaged into buffer), indexed by column.
    const float* values_of(std::size_t r, std::size_t begin, std::size_t end, float* buffer) const;
    // The bins of row r's pixels into bins[c] (−1: unused or flagged) over its run, returned.
    RowRun mark_row_bins(std::size_t r, std::int32_t* bins) const;
    // A pixel's bin, or for an unused pixel the side of the used bins it is on (−1 below the
    // middle of their range of d, −2 above). The unused pixels of a row are then contiguous runs
    // like the bins' (the bins are one interval of d, the unused pixels the rest).
    std::int32_t unused_side(std::int32_t bin, double d) const {
        return bin >= 0 ? bin : (d < used_middle ? -1 : -2);
    }
};

// The previous row's bins outside this row's run: no pixel above.
inline void clear_outside(std::int32_t* bins, std::size_t begin, std::size_t end, RowRun run) {
    std::fill(bins + begin, bins + std::max(begin, std::min(end, run.begin)), -1);
    std::fill(bins + std::min(end, std::max(begin, run.end)), bins + end, -1);
}

// One band of rows and its accumulators over the ranges of half-sub-bins, bins and slices its
// rows can reach.
struct Band {
    std::size_t r0 = 0, r1 = 0;
    std::size_t sub_lo = 0, n_subs = 0;       // half-sub-bins [sub_lo, sub_lo + n_subs)
    std::size_t bin_lo = 0, n_band_bins = 0;  // bins of those half-sub-bins
    std::size_t slice_lo = 0, n_band_slices = 0;
    std::vector<BinSums> bins;
    std::vector<std::uint32_t> sub_count;
    std::vector<double> sub_d;
    std::vector<double> slice_sum;  // (b − bin_lo) · n_band_slices + (j − slice_lo)
    std::vector<std::uint32_t> slice_count;
    std::size_t flagged = 0;
    // The accumulators as raw pointers and their ranges' offsets (for the passes' locals).
    struct Outputs {
        BinSums* bins;
        std::uint32_t* sub_count;
        double* sub_d;
        double* slice_sum;
        std::uint32_t* slice_count;
        std::size_t sub_lo, bin_lo, band_slices, slice_lo;
    };
    Outputs outputs() {
        return {bins.data(), sub_count.data(), sub_d.data(),  slice_sum.data(), slice_count.data(),
                sub_lo,      bin_lo,           n_band_slices, slice_lo};
    }
};

// The sums of one band along a steep axis (|a_y| ≥ |a_x|) without a region, and along an axis
// closer to the rows (cylinder_scan_segments.cpp); scan_band_per_pixel (cylinder_scan.cpp) is
// their reference: they agree to rounding.
void scan_band_steep(const ScanSetup& setup, Band& band);
void scan_band_shallow(const ScanSetup& setup, Band& band);

// The first column past an edge at `at` of a quantity at0 + c·step (rising: the first at or
// above it; falling: the first below it).
inline double column_past(double at, double at0, double step) {
    const double x = (at - at0) / step;
    return step > 0 ? std::ceil(x) : std::floor(x) + 1.0;
}

// The row at which a column whose quantity moves by `per_row` a row and is `room` from its
// nearest edge must be classified again (less 1e-6 for rounding; r_end when it does not move).
inline std::size_t recheck_row(std::size_t r, double room, double per_row, std::size_t r_end) {
    if (per_row == 0.0) return r_end;
    const double rows_left = std::floor((room - 1e-6) / per_row);
    return rows_left >= 1.0
               ? r + static_cast<std::size_t>(std::min(rows_left, static_cast<double>(r_end - r)))
               : r + 1;
}

// The end of the segment of `key` that starts at column c of a row (the first column in (c, end)
// whose key differs, else end), from an estimate `e`: checked next to it (the usual case: two
// evaluations), else found by an exponential and a binary search (the keys of a row are
// contiguous runs).
template <class KeyAt, class Key>
std::size_t segment_end(const KeyAt& key_at, const Key& key, std::size_t c, std::size_t e,
                        std::size_t end) {
    e = std::clamp(e, c + 1, end);
    const bool same_before = key_at(e - 1) == key;
    if (same_before && (e == end || key_at(e) != key)) return e;
    // key_at(lo) == key; hi is end or a column whose key differs.
    std::size_t lo = c, hi = end;
    if (same_before)
        lo = e;  // key_at(e) == key
    else
        hi = e - 1;
    std::size_t step = 1;
    while (lo + step < hi && key_at(lo + step) == key) {
        lo += step;
        step *= 2;
    }
    hi = std::min(hi, lo + step);
    while (hi - lo > 1) {
        const std::size_t mid = lo + (hi - lo) / 2;
        (key_at(mid) == key ? lo : hi) = mid;
    }
    return hi;
}

}  // namespace roughscope::image::detail
