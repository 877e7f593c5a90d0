// Step 2 of the cylinder profile (cylinder_steps.hpp): the band scan — its set-up, the bands, the
// per-pixel path and the sums of the bands in order (docs/curved-objects.md, "Cylinder
// profile": pixels used, bins, along the axis).
#include "cylinder_scan.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace roughscope::image::detail {

ScanSetup::ScanSetup(const LinearImage& image_, const std::uint8_t* region_,
                     const CylinderBinning& binning_, const std::vector<RowRun>& object_rows_)
    : image(image_),
      region(region_),
      binning(binning_),
      object_rows(object_rows_),
      width(image_.width),
      R(binning_.axis.radius_px),
      ux(binning_.axis.across_x()),
      uy(binning_.axis.across_y()),
      ax(binning_.axis.direction_x),
      ay(binning_.axis.direction_y),
      sub_offset(R * kSubBinsPerPx),
      n_sub(binning_.sub_bins),
      n_slices(binning_.slices),
      p0(image_.plane(0)),
      p1(image_.channels == 3 ? image_.plane(1) : nullptr),
      p2(image_.channels == 3 ? image_.plane(2) : nullptr),
      xc0(0.5 - binning_.axis.point_x_px) {
    const std::vector<double>& split = binning.split;
    const std::vector<std::int32_t>& sub_bin = binning.sub_bin;
    sub_bins.resize(n_sub);
    for (std::size_t k = 0; k < n_sub; ++k)
        sub_bins[k] = {split[k], {sub_bin[2 * k], sub_bin[2 * k + 1]}};
    class_edges.push_back(-R);
    for (std::size_t hs = 0; hs + 1 < 2 * n_sub; ++hs) {
        if (sub_bin[hs] == sub_bin[hs + 1]) continue;
        const std::size_t k = hs / 2;
        class_edges.push_back(hs % 2 == 0 ? split[k]
                                          : static_cast<double>(k + 1) / kSubBinsPerPx - R);
    }
    class_edges.push_back(static_cast<double>(n_sub) / kSubBinsPerPx - R);
    double used_lo = std::numeric_limits<double>::infinity(), used_hi = -used_lo;
    for (std::size_t hs = 0; hs < 2 * n_sub; ++hs)
        if (sub_bin[hs] >= 0) {
            const std::size_t k = hs / 2;  // the sub-bin
            const double lo = static_cast<double>(k) / kSubBinsPerPx - R;
            used_lo = std::min(used_lo, lo);
            used_hi = std::max(used_hi, lo + 1.0 / kSubBinsPerPx);
        }
    used_middle = 0.5 * (used_lo + used_hi);
}

const float* ScanSetup::values_of(std::size_t r, std::size_t begin, std::size_t end,
                                  float* buffer) const {
    const std::size_t o = r * width;
    if (!p1) return p0 + o;
    for (std::size_t c = begin; c < end; ++c)
        buffer[c] = (p0[o + c] + p1[o + c] + p2[o + c]) * (1.0F / 3.0F);
    return buffer;
}

RowRun ScanSetup::mark_row_bins(std::size_t r, std::int32_t* bins) const {
    const RowRun run = row_run(r);
    const double d0 = row_d0(r);
    for (std::size_t c = run.begin; c < run.end; ++c) {
        const std::size_t i = r * width + c;
        const std::int32_t b = pixel_bin(i, d0 + static_cast<double>(c) * ux).bin;
        bins[c] = b >= 0 && image.flags[i] != 0 ? -1 : b;
    }
    return run;
}

namespace {

// Ranges of the band of rows [r0, r1) from its corners, one sub-bin and one slice of margin for
// rounding, and its accumulators.
void prepare_band(const ScanSetup& s, Band& band, std::size_t r0, std::size_t r1) {
    const CylinderAxis& axis = s.binning.axis;
    band.r0 = r0;
    band.r1 = r1;
    double d_lo = std::numeric_limits<double>::infinity(), d_hi = -d_lo;
    double t_lo = d_lo, t_hi = -d_lo;
    for (const double x : {0.0, static_cast<double>(s.width)})
        for (const double y : {static_cast<double>(r0), static_cast<double>(r1)}) {
            const double d = (x - axis.point_x_px) * s.ux + (y - axis.point_y_px) * s.uy;
            const double t =
                (x - axis.point_x_px) * s.ax + (y - axis.point_y_px) * s.ay - s.binning.t_min_px;
            d_lo = std::min(d_lo, d);
            d_hi = std::max(d_hi, d);
            t_lo = std::min(t_lo, t);
            t_hi = std::max(t_hi, t);
        }
    const auto index_in = [](double x, std::size_t n) {
        return static_cast<std::size_t>(std::clamp(std::floor(x), 0.0, static_cast<double>(n - 1)));
    };
    const std::size_t k_lo = index_in(d_lo * kSubBinsPerPx + s.sub_offset - 1.0, s.n_sub);
    const std::size_t k_hi = index_in(d_hi * kSubBinsPerPx + s.sub_offset + 1.0, s.n_sub);
    band.sub_lo = 2 * k_lo;
    band.n_subs = 2 * (k_hi - k_lo + 1);
    std::int32_t b_lo = std::numeric_limits<std::int32_t>::max(), b_hi = -1;
    for (std::size_t sk = band.sub_lo; sk < band.sub_lo + band.n_subs; ++sk)
        if (s.binning.sub_bin[sk] >= 0) {
            b_lo = std::min(b_lo, s.binning.sub_bin[sk]);
            b_hi = std::max(b_hi, s.binning.sub_bin[sk]);
        }
    band.bin_lo = b_hi >= 0 ? static_cast<std::size_t>(b_lo) : 0;
    band.n_band_bins = b_hi >= 0 ? static_cast<std::size_t>(b_hi - b_lo + 1) : 0;
    band.slice_lo = index_in(t_lo - 1.0, s.n_slices);
    band.n_band_slices = index_in(t_hi + 1.0, s.n_slices) - band.slice_lo + 1;
    band.bins.assign(s.binning.bins, BinSums{});
    band.sub_count.assign(band.n_subs, 0);
    band.sub_d.assign(band.n_subs, 0.0);
    band.slice_sum.assign(band.n_band_bins * band.n_band_slices, 0.0);
    band.slice_count.assign(band.n_band_bins * band.n_band_slices, 0);
}

// Runs of one bin, one half-sub-bin and one slice along a row, summed here and added to the
// band's accumulators when they end.
struct RowRuns {
    explicit RowRuns(const Band::Outputs& outputs) : acc(outputs) {}

    const Band::Outputs& acc;
    BinSums bin_run;
    std::int32_t bin_run_of = -1;
    std::size_t sub_run_of = 0, sub_run_count = 0;
    double sub_run_d = 0.0;
    std::size_t slice_run_of = 0, slice_run_count = 0;
    double slice_run_sum = 0.0;

    void end_bin_run() {
        if (bin_run_of < 0) return;
        BinSums& bs = acc.bins[static_cast<std::size_t>(bin_run_of)];
        bs.sum += bin_run.sum;
        bs.sum2 += bin_run.sum2;
        bs.diff2 += bin_run.diff2;
        bs.count += bin_run.count;
        bs.diffs += bin_run.diffs;
        bin_run = BinSums{};
    }
    void end_sub_run() {
        if (sub_run_count == 0) return;
        acc.sub_count[sub_run_of] += static_cast<std::uint32_t>(sub_run_count);
        acc.sub_d[sub_run_of] += sub_run_d;
        sub_run_count = 0;
        sub_run_d = 0.0;
    }
    void end_slice_run() {
        if (slice_run_count == 0) return;
        acc.slice_sum[slice_run_of] += slice_run_sum;
        acc.slice_count[slice_run_of] += static_cast<std::uint32_t>(slice_run_count);
        slice_run_count = 0;
        slice_run_sum = 0.0;
    }
};

// The band pixel by pixel (any region; the segment paths' reference).
class PerPixelScan {
  public:
    PerPixelScan(const ScanSetup& s, Band& band)
        : s_(s),
          band_(band),
          acc_(band.outputs()),
          column_(s.width),
          prev_value_(s.width, 0.0F),
          prev_bin_(s.width, -1) {}

    void run() {
        // The row before the band: bins and values only (it is summed by the band above).
        if (band_.r0 > 0 && rows_along_axis()) {
            float* const prev_v = prev_value_.data();
            std::int32_t* const prev_b = prev_bin_.data();
            const RowRun run = s_.mark_row_bins(band_.r0 - 1, prev_b);
            const float* const above = s_.values_of(band_.r0 - 1, run.begin, run.end, prev_v);
            for (std::size_t c = run.begin; c < run.end; ++c)
                if (prev_b[c] >= 0) prev_v[c] = above[c];
            prev_begin_ = run.begin;
            prev_end_ = run.end;
        }
        for (std::size_t r = band_.r0; r < band_.r1; ++r) scan_row(r);
    }

  private:
    // The previous row's entry of the sub-bin table per column: along a steep axis a column
    // keeps its sub-bin from row to row, and the table (one entry per 1/8 px, one cache line a
    // pixel) is read only where it changes.
    struct ColumnEntry {
        SubBinEntry entry;
        std::size_t k = std::numeric_limits<std::size_t>::max();
    };

    bool rows_along_axis() const { return std::abs(s_.ay) >= std::abs(s_.ax); }

    PixelBin cached_bin(std::size_t i, std::size_t c, double d) {
        const double sf = d * kSubBinsPerPx + s_.sub_offset;
        if (!(sf >= 0.0 && sf < static_cast<double>(s_.n_sub)) || (s_.region && !s_.region[i]))
            return {};
        const auto k = static_cast<std::size_t>(sf);
        ColumnEntry& ce = column_[c];
        if (ce.k != k) ce = {s_.sub_bins[k], k};
        const std::size_t side = d >= ce.entry.split ? 1 : 0;
        return {ce.entry.bin[side], 2 * k + side};
    }

    void scan_row(std::size_t r);

    const ScanSetup& s_;
    Band& band_;
    const Band::Outputs acc_;
    std::vector<ColumnEntry> column_;
    std::vector<float> prev_value_;
    std::vector<std::int32_t> prev_bin_;
    std::size_t prev_begin_ = 0, prev_end_ = 0;  // columns of the previous row visited
};

void PerPixelScan::scan_row(std::size_t r) {
    // Local copies (kept in registers: the stores below cannot alias them).
    const std::uint8_t* const flags = s_.image.flags.data();
    const float *const v0 = s_.p0, *const v1 = s_.p1, *const v2 = s_.p2;
    const double step_d = s_.ux, step_t = s_.ax;
    const bool steep = rows_along_axis();
    const std::size_t last_slice = s_.n_slices - 1;
    const std::size_t w = s_.width;
    float* const prev_v = prev_value_.data();
    std::int32_t* const prev_b = prev_bin_.data();
    const RowRun run = s_.row_run(r);
    clear_outside(prev_b, prev_begin_, prev_end_, run);
    prev_begin_ = run.begin;
    prev_end_ = run.end;
    const double d0 = s_.row_d0(r), t0 = s_.row_t0(r);
    float left_value = 0.0F;
    std::int32_t left_bin = -1;
    RowRuns runs(acc_);
    for (std::size_t c = run.begin; c < run.end; ++c) {
        const std::size_t i = r * w + c;
        const double d = d0 + static_cast<double>(c) * step_d;
        const PixelBin pbin = cached_bin(i, c, d);
        std::int32_t b = pbin.bin;
        if (b >= 0 && flags[i] != 0) {
            ++band_.flagged;
            ++acc_.bins[static_cast<std::size_t>(b)].flagged;
            b = -1;
        }
        if (b >= 0) {
            float v = v0[i];
            if (v1) v = (v + v1[i] + v2[i]) * (1.0F / 3.0F);
            const double vd = v;
            if (b != runs.bin_run_of) {
                runs.end_bin_run();
                runs.bin_run_of = b;
            }
            runs.bin_run.sum += vd;
            runs.bin_run.sum2 += vd * vd;
            ++runs.bin_run.count;
            assert(pbin.sub >= band_.sub_lo && pbin.sub < band_.sub_lo + band_.n_subs);
            if (pbin.sub - acc_.sub_lo != runs.sub_run_of) {
                runs.end_sub_run();
                runs.sub_run_of = pbin.sub - acc_.sub_lo;
            }
            ++runs.sub_run_count;
            runs.sub_run_d += d;
            const std::size_t sl = std::min(
                static_cast<std::size_t>(std::max(0.0, t0 + static_cast<double>(c) * step_t)),
                last_slice);
            assert(sl >= band_.slice_lo && sl < band_.slice_lo + band_.n_band_slices);
            const std::size_t si = (static_cast<std::size_t>(b) - acc_.bin_lo) * acc_.band_slices +
                                   (sl - acc_.slice_lo);
            if (si != runs.slice_run_of) {
                runs.end_slice_run();
                runs.slice_run_of = si;
            }
            runs.slice_run_sum += vd;
            ++runs.slice_run_count;
            const std::int32_t nb = steep ? prev_b[c] : left_bin;
            if (nb == b) {
                const double diff = vd - (steep ? prev_v[c] : left_value);
                runs.bin_run.diff2 += diff * diff;
                ++runs.bin_run.diffs;
            }
            left_value = v;
            prev_v[c] = v;
        }
        left_bin = b;
        prev_b[c] = b;
    }
    runs.end_bin_run();
    runs.end_sub_run();
    runs.end_slice_run();
}

// The bands' sums, added in band order.
CylinderSums add_bands(const std::vector<Band>& bands, const CylinderBinning& g) {
    const std::size_t n_bins = g.bins, n_slices = g.slices;
    CylinderSums sums;
    sums.bins.assign(n_bins, BinSums{});
    sums.slice_sum.assign(n_bins * n_slices, 0.0);
    sums.slice_count.assign(n_bins * n_slices, 0);
    sums.sub_count.assign(2 * g.sub_bins, 0);
    sums.sub_d.assign(2 * g.sub_bins, 0.0);
    for (const Band& band : bands) {
        sums.pixels_flagged += band.flagged;
        for (std::size_t b = 0; b < n_bins; ++b) {
            BinSums& to = sums.bins[b];
            const BinSums& from = band.bins[b];
            to.sum += from.sum;
            to.sum2 += from.sum2;
            to.diff2 += from.diff2;
            to.count += from.count;
            to.diffs += from.diffs;
            to.flagged += from.flagged;
        }
        for (std::size_t k = 0; k < band.n_subs; ++k) {
            sums.sub_count[band.sub_lo + k] += band.sub_count[k];
            sums.sub_d[band.sub_lo + k] += band.sub_d[k];
        }
        for (std::size_t b = 0; b < band.n_band_bins; ++b)
            for (std::size_t j = 0; j < band.n_band_slices; ++j) {
                const std::size_t from = b * band.n_band_slices + j;
                const std::size_t to = (band.bin_lo + b) * n_slices + band.slice_lo + j;
                sums.slice_sum[to] += band.slice_sum[from];
                sums.slice_count[to] += band.slice_count[from];
            }
    }
    return sums;
}

}  // namespace

CylinderSums scan_cylinder(const LinearImage& image, const std::uint8_t* region,
                           const CylinderBinning& binning, const std::vector<RowRun>& object_rows,
                           std::size_t threads, ScanPath path) {
    const ScanSetup setup(image, region, binning, object_rows);
    const std::size_t h = image.height, n_bands = binning.bands;
    const bool rows_along_axis = std::abs(setup.ay) >= std::abs(setup.ax);
    // A fixed number of bands, whatever the number of threads: the sums do not depend on it.
    std::vector<Band> bands(n_bands);
    run_bands(n_bands, threads, [&](std::size_t k) {
        prepare_band(setup, bands[k], h * k / n_bands, h * (k + 1) / n_bands);
        if (region || path == ScanPath::PerPixel)
            PerPixelScan(setup, bands[k]).run();
        else if (rows_along_axis)
            scan_band_steep(setup, bands[k]);
        else
            scan_band_shallow(setup, bands[k]);
    });
    return add_bands(bands, binning);
}

}  // namespace roughscope::image::detail
