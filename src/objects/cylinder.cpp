#include "roughscope/objects/cylinder.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <span>
#include <string>
#include <vector>

#include "object_profile.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/memory.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/scattering/validity.hpp"

namespace roughscope::image {
namespace {

using check::format_number;

constexpr double kSubBinsPerPx = 8.0;     // resolution of the distribution across the axis
constexpr std::size_t kNodesPerBin = 32;  // geometry nodes of a bin's model average
// Bands of rows of the pass over the pixels: at most kMaxBands, of at least kRowsPerBand rows
// (fixed, so the sums do not depend on the number of threads).
constexpr std::size_t kRowsPerBand = 256;
constexpr std::size_t kMaxBands = 8;
// Floor of a bin's standard error, in units of the profile's maximum: a quantisation step of a
// 14-bit camera (noise-free synthetic data have none of their own).
constexpr double kMinRelativeStandardError = 1e-4;

std::string image_name(const LinearImage& image) {
    return image.info.source.empty() ? std::string("image") : image.info.source;
}

// Per-bin accumulators of the single pass.
struct BinSums {
    double sum = 0, sum2 = 0, diff2 = 0;
    std::size_t count = 0, diffs = 0, flagged = 0;
};

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

}  // namespace

std::string_view to_string(CylinderHalf half) {
    switch (half) {
        case CylinderHalf::Right:
            return "right";
        case CylinderHalf::Left:
            return "left";
        case CylinderHalf::Both:
            return "both";
    }
    return "right";
}

CylinderHalf parse_cylinder_half(std::string_view name) {
    if (name == "right") return CylinderHalf::Right;
    if (name == "left") return CylinderHalf::Left;
    if (name == "both") return CylinderHalf::Both;
    throw InvalidArgument(
        concat("unknown cylinder half ", quote_input(name), " (valid: right, left, both)"));
}

std::string_view to_string(ProfileModel model) {
    switch (model) {
        case ProfileModel::Lambert:
            return "lambert";
        case ProfileModel::BkGaussian:
            return "bk_gaussian";
        case ProfileModel::VhGaussian:
            return "vh_gaussian";
        case ProfileModel::VhExponential:
            return "vh_exponential";
    }
    return "lambert";
}

std::string_view display_name(ProfileModel model) {
    switch (model) {
        case ProfileModel::Lambert:
            return "Lambert";
        case ProfileModel::BkGaussian:
            return "Eq. 7 B–K(G)";
        case ProfileModel::VhGaussian:
            return "Eq. 9 V–H–B–K(G)";
        case ProfileModel::VhExponential:
            return "Eq. 10 V–H–B–K(E)";
    }
    return "Lambert";
}

ProfileModel parse_profile_model(std::string_view name) {
    for (const ProfileModel m : kProfileModels)
        if (name == to_string(m)) return m;
    throw InvalidArgument(concat("unknown profile model ", quote_input(name),
                                 " (valid: lambert, bk_gaussian, vh_gaussian, vh_exponential)"));
}

double profile_model_brightness(ProfileModel model, const Geometry& geom, double sigma_over_T,
                                Radiometry radiometry) {
    switch (model) {
        case ProfileModel::Lambert:  // Lambert's law: E ∝ cos θi
            check::geometry(geom);
            return std::cos(geom.theta_i_rad);
        case ProfileModel::BkGaussian:  // Eq. 7 (general form Eq. 4, F_Beck)
            return very_rough_brightness(geom, sigma_over_T, Correlation::Gaussian,
                                         GeometricFactor::Beckmann, radiometry);
        case ProfileModel::VhGaussian:  // Eq. 9 (general form Eq. 4, F_VH)
            return very_rough_brightness(geom, sigma_over_T, Correlation::Gaussian,
                                         GeometricFactor::VernoldHarvey, radiometry);
        case ProfileModel::VhExponential:  // Eq. 10 (general form Eq. 5, F_VH)
            return very_rough_brightness(geom, sigma_over_T, Correlation::Exponential,
                                         GeometricFactor::VernoldHarvey, radiometry);
    }
    return 0.0;
}

const ProfileModelCurve& CylinderProfile::curve(ProfileModel model) const {
    for (const ProfileModelCurve& c : models)
        if (c.model == model) return c;
    throw InvalidArgument(concat("the profile has no curve ", to_string(model)));
}

void check_cylinder_options(const CylinderOptions& options) {
    detail::check_unit_direction("cylinder light", options.light);
    detail::check_unit_direction("cylinder view", options.view);
    if (!(options.bin_width_deg > 0.0 && options.bin_width_deg <= 45.0))
        throw InvalidArgument(
            concat("cylinder bin_width_deg = ", format_number(options.bin_width_deg),
                   " is outside the valid range (0, 45] deg"));
    if (options.min_pixels_per_bin < 1)
        throw InvalidArgument("cylinder min_pixels_per_bin must be at least 1");
    if (!(options.limb_fraction > 0.0 && options.limb_fraction <= 1.0))
        throw InvalidArgument(
            concat("cylinder limb_fraction = ", format_number(options.limb_fraction),
                   " is outside the valid range (0, 1]"));
    if (options.sigma_over_T) check::positive("cylinder sigma_over_T", *options.sigma_over_T);
    if (!(options.fit_max_theta_i_deg > 0.0 && options.fit_max_theta_i_deg < 90.0))
        throw InvalidArgument(
            concat("cylinder fit_max_theta_i_deg = ", format_number(options.fit_max_theta_i_deg),
                   " is outside the valid range (0, 90) deg"));
    if (!(options.fit_max_flagged_fraction >= 0.0 && options.fit_max_flagged_fraction <= 1.0))
        throw InvalidArgument(concat(
            "cylinder fit_max_flagged_fraction = ", format_number(options.fit_max_flagged_fraction),
            " is outside the valid range [0, 1]"));
    check::positive("cylinder departure_k", options.departure_k);
    if (options.departure_bins < 1)
        throw InvalidArgument("cylinder departure_bins must be at least 1");
    if (options.axis) {
        const CylinderAxis& a = *options.axis;
        (void)cylinder_axis_from_line(a.point_x_px, a.point_y_px, a.direction_x, a.direction_y,
                                      a.radius_px);
    }
}

// The dark-limb warning's factor (measure_cylinder_profile).
constexpr double kDarkLimbFactor = 10.0;

CylinderProfile measure_cylinder_profile(const LinearImage& image,
                                         const std::vector<std::uint8_t>* region_mask,
                                         const CylinderOptions& options) {
    check_cylinder_options(options);
    // The values: read and checked by the silhouette's pass, or here when there is none.
    check_linear_image_layout(image);
    const std::size_t w = image.width, h = image.height;
    if (region_mask && region_mask->size() != image.pixel_count())
        throw InvalidArgument(concat("cylinder region mask has ",
                                     std::to_string(region_mask->size()), " entries, the image ",
                                     image_name(image), " has ",
                                     std::to_string(image.pixel_count()), " pixels"));

    CylinderProfile out;
    out.light = options.light;
    out.view = options.view;
    out.half = options.half;
    out.bin_width_rad = deg_to_rad(options.bin_width_deg);

    // The axis, and the object mask when it comes from the silhouette.
    std::vector<detail::RowRun> object_rows;  // empty: every pixel
    double silhouette_level = 0.0;
    if (options.axis) {
        check_linear_image(image);
        out.axis = cylinder_axis_from_line(options.axis->point_x_px, options.axis->point_y_px,
                                           options.axis->direction_x, options.axis->direction_y,
                                           options.axis->radius_px);
    } else {
        detail::Outline outline = detail::find_outline(image, options.silhouette, options.threads);
        out.axis = fit_cylinder_axis(outline.silhouette, options.axis_fit);
        silhouette_level = outline.silhouette.threshold;
        object_rows = std::move(outline.rows);
    }
    const CylinderAxis& axis = out.axis;
    const double R = axis.radius_px;
    const double ux = axis.across_x(), uy = axis.across_y();
    const double ax = axis.direction_x, ay = axis.direction_y;

    // Sub-bins of the distance across the axis (1/8 px) and their bin.
    const double bw = out.bin_width_rad;
    const bool both = options.half == CylinderHalf::Both;
    const auto n_bins = static_cast<std::size_t>(std::ceil((both ? kPi : kPi / 2.0) / bw - 1e-9));
    const auto n_sub = static_cast<std::size_t>(std::ceil(2.0 * R * kSubBinsPerPx)) + 1;
    // Bin of the normal angle α (x: α, −α or α + π/2 by the half); −1 outside the half or the
    // limb.
    const auto bin_of = [&](double d) -> std::int32_t {
        if (std::abs(d) > options.limb_fraction * R) return -1;
        const double alpha = std::asin(std::clamp(d / R, -1.0, 1.0));
        double x = 0;
        switch (options.half) {
            case CylinderHalf::Right:
                x = alpha;
                break;
            case CylinderHalf::Left:
                x = -alpha;
                break;
            case CylinderHalf::Both:
                x = alpha + kPi / 2.0;
                break;
        }
        if (x < 0) return -1;
        return static_cast<std::int32_t>(std::min(n_bins - 1, static_cast<std::size_t>(x / bw)));
    };
    // Each sub-bin holds at most one bin edge (bins are ≥ 1/8 px wide only when R sin(bw) ≥ 1/8,
    // which every R ≥ 4 px and bw ≥ 2° meet; narrower bins share a sub-bin and the finer edge is
    // missed): the pixel's side of that edge, split[k], picks the half-sub-bin 2k or 2k + 1.
    std::vector<double> split(n_sub, std::numeric_limits<double>::infinity());
    std::vector<std::int32_t> sub_bin(2 * n_sub, -1);
    for (std::size_t k = 0; k < n_sub; ++k) {
        const double d_lo = static_cast<double>(k) / kSubBinsPerPx - R;
        const double d_hi = d_lo + 1.0 / kSubBinsPerPx;
        const std::int32_t b_lo = bin_of(d_lo), b_hi = bin_of(d_hi);
        sub_bin[2 * k] = b_lo;
        sub_bin[2 * k + 1] = b_lo;
        if (b_lo != b_hi) {  // bisect for the edge
            double a = d_lo, b = d_hi;
            for (int it = 0; it < 60; ++it) {
                const double m = 0.5 * (a + b);
                (bin_of(m) == b_lo ? a : b) = m;
            }
            split[k] = b;
            sub_bin[2 * k + 1] = b_hi;
        }
    }

    // Slices (1 px) along the axis: t = (p − P)·a over the image's corners.
    double t_min = std::numeric_limits<double>::infinity(), t_max = -t_min;
    for (const double cx : {0.0, static_cast<double>(w)})
        for (const double cy : {0.0, static_cast<double>(h)}) {
            const double t = (cx - axis.point_x_px) * ax + (cy - axis.point_y_px) * ay;
            t_min = std::min(t_min, t);
            t_max = std::max(t_max, t);
        }
    const auto n_slices = static_cast<std::size_t>(std::ceil(t_max - t_min)) + 1;
    const std::size_t n_bands = std::clamp<std::size_t>(h / kRowsPerBand, 1, kMaxBands);
    // The pass's accumulators, at most: every band's bins and its slices of each bin.
    check_memory(static_cast<double>(n_bands) * static_cast<double>(n_bins) *
                     (sizeof(BinSums) + 12.0 * static_cast<double>(n_slices)),
                 concat("cylinder bin_width_deg = ", format_number(options.bin_width_deg), " (",
                        std::to_string(n_bins), " bins of the normal angle over ",
                        std::to_string(n_slices), " slices along the axis)"),
                 "give a wider bin_width_deg (default 2)");

    // The single pass, over bands of rows (a fixed number, whatever the number of threads: the
    // sums do not depend on it). Each band sums into its own accumulators over the ranges of
    // sub-bins, bins and slices its rows can reach; they are added in band order. Noise from
    // differences with the previous pixel along the axis' closer image direction (previous row
    // for a steep axis, previous column otherwise), same bin.
    const bool rows_along_axis = std::abs(ay) >= std::abs(ax);
    const float* p0 = image.plane(0);
    const float* p1 = image.channels == 3 ? image.plane(1) : nullptr;
    const float* p2 = image.channels == 3 ? image.plane(2) : nullptr;
    const std::uint8_t* reg = region_mask ? region_mask->data() : nullptr;
    const double sub_offset = R * kSubBinsPerPx;
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
            return {bins.data(),      sub_count.data(),   sub_d.data(),
                    slice_sum.data(), slice_count.data(), sub_lo,
                    bin_lo,           n_band_slices,      slice_lo};
        }
    };
    std::vector<Band> bands(n_bands);
    // Ranges from the band's corners, one sub-bin and one slice of margin for rounding.
    const auto prepare_band = [&](Band& band, std::size_t r0, std::size_t r1) {
        band.r0 = r0;
        band.r1 = r1;
        double d_lo = std::numeric_limits<double>::infinity(), d_hi = -d_lo;
        double t_lo = d_lo, t_hi = -d_lo;
        for (const double x : {0.0, static_cast<double>(w)})
            for (const double y : {static_cast<double>(r0), static_cast<double>(r1)}) {
                const double d = (x - axis.point_x_px) * ux + (y - axis.point_y_px) * uy;
                const double t = (x - axis.point_x_px) * ax + (y - axis.point_y_px) * ay - t_min;
                d_lo = std::min(d_lo, d);
                d_hi = std::max(d_hi, d);
                t_lo = std::min(t_lo, t);
                t_hi = std::max(t_hi, t);
            }
        const auto index_in = [](double x, std::size_t n) {
            return static_cast<std::size_t>(
                std::clamp(std::floor(x), 0.0, static_cast<double>(n - 1)));
        };
        const std::size_t k_lo = index_in(d_lo * kSubBinsPerPx + sub_offset - 1.0, n_sub);
        const std::size_t k_hi = index_in(d_hi * kSubBinsPerPx + sub_offset + 1.0, n_sub);
        band.sub_lo = 2 * k_lo;
        band.n_subs = 2 * (k_hi - k_lo + 1);
        std::int32_t b_lo = std::numeric_limits<std::int32_t>::max(), b_hi = -1;
        for (std::size_t sk = band.sub_lo; sk < band.sub_lo + band.n_subs; ++sk)
            if (sub_bin[sk] >= 0) {
                b_lo = std::min(b_lo, sub_bin[sk]);
                b_hi = std::max(b_hi, sub_bin[sk]);
            }
        band.bin_lo = b_hi >= 0 ? static_cast<std::size_t>(b_lo) : 0;
        band.n_band_bins = b_hi >= 0 ? static_cast<std::size_t>(b_hi - b_lo + 1) : 0;
        band.slice_lo = index_in(t_lo - 1.0, n_slices);
        band.n_band_slices = index_in(t_hi + 1.0, n_slices) - band.slice_lo + 1;
        band.bins.assign(n_bins, BinSums{});
        band.sub_count.assign(band.n_subs, 0);
        band.sub_d.assign(band.n_subs, 0.0);
        band.slice_sum.assign(band.n_band_bins * band.n_band_slices, 0.0);
        band.slice_count.assign(band.n_band_bins * band.n_band_slices, 0);
    };
    // The bin of pixel (r, c) at distance d and its half-sub-bin, or −1: outside the object's
    // run of the row (silhouette.hpp: the mask is one run a row), the region, the half or the
    // limb. Flags are not looked at.
    struct PixelBin {
        std::int32_t bin = -1;
        std::size_t sub = 0;
    };
    // Sub-bin k's edge and the bins on either side of it, side by side (one cache line a pixel;
    // the two bins are read while the edge is compared).
    struct SubBinEntry {
        double split = 0.0;
        std::array<std::int32_t, 2> bin{};
    };
    std::vector<SubBinEntry> sub_bins(n_sub);
    for (std::size_t k = 0; k < n_sub; ++k)
        sub_bins[k] = {split[k], {sub_bin[2 * k], sub_bin[2 * k + 1]}};
    const auto pixel_bin = [=, table = sub_bins.data()](std::size_t i, double d) -> PixelBin {
        const double sf = d * kSubBinsPerPx + sub_offset;
        if (!(sf >= 0.0 && sf < static_cast<double>(n_sub)) || (reg && !reg[i])) return {};
        const auto k = static_cast<std::size_t>(sf);
        const SubBinEntry& e = table[k];
        const std::size_t side = d >= e.split ? 1 : 0;
        return {e.bin[side], 2 * k + side};
    };
    const auto row_run = [&](std::size_t r) -> detail::RowRun {
        return object_rows.empty() ? detail::RowRun{0, w} : object_rows[r];
    };
    // Helpers of the two segment passes (below): a row's d and t at column 0 (as the per-pixel
    // path computes them), a column's slice, a row's values (RGB averaged as the per-pixel path
    // does) over [begin, end), the first column past an edge at `at` of a quantity at0 + c·step
    // (rising: the first at or above it; falling: the first below it), and the row at which a
    // column whose quantity moves by `per_row` a row and is `room` from its nearest edge must be
    // classified again (less 1e-6 for rounding; none when it does not move).
    const double xc0 = 0.5 - axis.point_x_px;
    const auto row_d0 = [&](std::size_t r) {
        return xc0 * ux + (static_cast<double>(r) + 0.5 - axis.point_y_px) * uy;
    };
    const auto row_t0 = [&](std::size_t r) {
        return xc0 * ax + (static_cast<double>(r) + 0.5 - axis.point_y_px) * ay - t_min;
    };
    const auto slice_at = [&](double t0, std::size_t c) {
        return std::min(static_cast<std::size_t>(std::max(0.0, t0 + static_cast<double>(c) * ax)),
                        n_slices - 1);
    };
    const auto values_of = [&](std::size_t r, std::size_t begin, std::size_t end,
                               float* buffer) -> const float* {
        const std::size_t o = r * w;
        if (!p1) return p0 + o;
        for (std::size_t c = begin; c < end; ++c)
            buffer[c] = (p0[o + c] + p1[o + c] + p2[o + c]) * (1.0F / 3.0F);
        return buffer;
    };
    // The bins of row r's pixels into bins[c] (−1: unused or flagged) over its run, returned.
    const auto mark_row_bins = [&](std::size_t r, std::int32_t* bins) {
        const detail::RowRun run = row_run(r);
        const double d0 = row_d0(r);
        for (std::size_t c = run.begin; c < run.end; ++c) {
            const std::size_t i = r * w + c;
            const std::int32_t b = pixel_bin(i, d0 + static_cast<double>(c) * ux).bin;
            bins[c] = b >= 0 && image.flags[i] != 0 ? -1 : b;
        }
        return run;
    };
    // The previous row's bins outside this row's run: no pixel above.
    const auto clear_outside = [](std::int32_t* bins, std::size_t begin, std::size_t end,
                                  detail::RowRun run) {
        std::fill(bins + begin, bins + std::max(begin, std::min(end, run.begin)), -1);
        std::fill(bins + std::min(end, std::max(begin, run.end)), bins + end, -1);
    };
    const auto scan_band = [&](Band& band) {
        // Local copies (kept in registers: the stores below cannot alias them).
        // The previous row's entry of the sub-bin table per column: along a steep axis a column
        // keeps its sub-bin from row to row, and the table (one entry per 1/8 px, one cache line
        // a pixel) is read only where it changes.
        struct ColumnEntry {
            SubBinEntry entry;
            std::size_t k = std::numeric_limits<std::size_t>::max();
        };
        std::vector<ColumnEntry> column(w);
        ColumnEntry* const column_entry = column.data();
        const SubBinEntry* const table = sub_bins.data();
        const auto cached_bin = [=](std::size_t i, std::size_t c, double d) -> PixelBin {
            const double sf = d * kSubBinsPerPx + sub_offset;
            if (!(sf >= 0.0 && sf < static_cast<double>(n_sub)) || (reg && !reg[i])) return {};
            const auto k = static_cast<std::size_t>(sf);
            ColumnEntry& ce = column_entry[c];
            if (ce.k != k) ce = {table[k], k};
            const std::size_t side = d >= ce.entry.split ? 1 : 0;
            return {ce.entry.bin[side], 2 * k + side};
        };
        const std::uint8_t* const flags = image.flags.data();
        const float *const v0 = p0, *const v1 = p1, *const v2 = p2;
        const double step_d = ux, step_t = ax;
        const bool steep = rows_along_axis;
        const std::size_t last_slice = n_slices - 1;
        const Band::Outputs acc = band.outputs();
        std::vector<float> prev_value(w, 0.0F);
        std::vector<std::int32_t> prev_bin(w, -1);
        float* const prev_v = prev_value.data();
        std::int32_t* const prev_b = prev_bin.data();
        std::size_t prev_begin = 0, prev_end = 0;  // columns of the previous row visited
        // The row before the band: bins and values only (it is summed by the band above).
        if (band.r0 > 0 && rows_along_axis) {
            const detail::RowRun run = mark_row_bins(band.r0 - 1, prev_b);
            const float* const above = values_of(band.r0 - 1, run.begin, run.end, prev_v);
            for (std::size_t c = run.begin; c < run.end; ++c)
                if (prev_b[c] >= 0) prev_v[c] = above[c];
            prev_begin = run.begin;
            prev_end = run.end;
        }
        for (std::size_t r = band.r0; r < band.r1; ++r) {
            const detail::RowRun run = row_run(r);
            clear_outside(prev_b, prev_begin, prev_end, run);
            prev_begin = run.begin;
            prev_end = run.end;
            const double d0 = row_d0(r), t0 = row_t0(r);
            float left_value = 0.0F;
            std::int32_t left_bin = -1;
            // Runs of one bin, one half-sub-bin and one slice along the row are summed here and
            // added to the band's accumulators when they end.
            BinSums bin_run;
            std::int32_t bin_run_of = -1;
            std::size_t sub_run_of = 0, sub_run_count = 0;
            double sub_run_d = 0.0;
            std::size_t slice_run_of = 0, slice_run_count = 0;
            double slice_run_sum = 0.0;
            const auto end_bin_run = [&] {
                if (bin_run_of < 0) return;
                BinSums& bs = acc.bins[static_cast<std::size_t>(bin_run_of)];
                bs.sum += bin_run.sum;
                bs.sum2 += bin_run.sum2;
                bs.diff2 += bin_run.diff2;
                bs.count += bin_run.count;
                bs.diffs += bin_run.diffs;
                bin_run = BinSums{};
            };
            const auto end_sub_run = [&] {
                if (sub_run_count == 0) return;
                acc.sub_count[sub_run_of] += static_cast<std::uint32_t>(sub_run_count);
                acc.sub_d[sub_run_of] += sub_run_d;
                sub_run_count = 0;
                sub_run_d = 0.0;
            };
            const auto end_slice_run = [&] {
                if (slice_run_count == 0) return;
                acc.slice_sum[slice_run_of] += slice_run_sum;
                acc.slice_count[slice_run_of] += static_cast<std::uint32_t>(slice_run_count);
                slice_run_count = 0;
                slice_run_sum = 0.0;
            };
            for (std::size_t c = run.begin; c < run.end; ++c) {
                const std::size_t i = r * w + c;
                const double d = d0 + static_cast<double>(c) * step_d;
                const PixelBin pbin = cached_bin(i, c, d);
                std::int32_t b = pbin.bin;
                if (b >= 0 && flags[i] != 0) {
                    ++band.flagged;
                    ++acc.bins[static_cast<std::size_t>(b)].flagged;
                    b = -1;
                }
                if (b >= 0) {
                    float v = v0[i];
                    if (v1) v = (v + v1[i] + v2[i]) * (1.0F / 3.0F);
                    const double vd = v;
                    if (b != bin_run_of) {
                        end_bin_run();
                        bin_run_of = b;
                    }
                    bin_run.sum += vd;
                    bin_run.sum2 += vd * vd;
                    ++bin_run.count;
                    assert(pbin.sub >= band.sub_lo && pbin.sub < band.sub_lo + band.n_subs);
                    if (pbin.sub - acc.sub_lo != sub_run_of) {
                        end_sub_run();
                        sub_run_of = pbin.sub - acc.sub_lo;
                    }
                    ++sub_run_count;
                    sub_run_d += d;
                    const std::size_t sl = std::min(static_cast<std::size_t>(std::max(
                                                        0.0, t0 + static_cast<double>(c) * step_t)),
                                                    last_slice);
                    assert(sl >= band.slice_lo && sl < band.slice_lo + band.n_band_slices);
                    const std::size_t si =
                        (static_cast<std::size_t>(b) - acc.bin_lo) * acc.band_slices +
                        (sl - acc.slice_lo);
                    if (si != slice_run_of) {
                        end_slice_run();
                        slice_run_of = si;
                    }
                    slice_run_sum += vd;
                    ++slice_run_count;
                    const std::int32_t nb = steep ? prev_b[c] : left_bin;
                    if (nb == b) {
                        const double diff = vd - (steep ? prev_v[c] : left_value);
                        bin_run.diff2 += diff * diff;
                        ++bin_run.diffs;
                    }
                    left_value = v;
                    prev_v[c] = v;
                }
                left_bin = b;
                prev_b[c] = b;
            }
            end_bin_run();
            end_sub_run();
            end_slice_run();
        }
    };
    // The same sums along a steep axis without a region mask, with the per-pixel work cut down
    // (scan_band is its reference: they agree to rounding). A row is cut into segments of one bin
    // and one slice: the classification (pixel_bin, the slice) is evaluated at the segment's ends
    // only, found from the next edge between bins and the next slice boundary and then checked
    // (d and t are linear along the row, the bins and slices contiguous in d and t). A segment
    // without a flagged pixel is summed without further tests. A pixel's half-sub-bin is kept per
    // column: the column's d moves by u_y a row, so its half-sub-bin is recomputed only at the
    // rows where it can have changed (scheduled from the distance to the half-sub-bin's edges),
    // and the column's count and Σd are added to the half-sub-bin when it changes.
    // Edges in d between the classes of consecutive half-sub-bins (and the table's ends).
    std::vector<double> class_edges;
    class_edges.push_back(-R);
    for (std::size_t hs = 0; hs + 1 < 2 * n_sub; ++hs) {
        if (sub_bin[hs] == sub_bin[hs + 1]) continue;
        const std::size_t k = hs / 2;
        class_edges.push_back(hs % 2 == 0 ? split[k]
                                          : static_cast<double>(k + 1) / kSubBinsPerPx - R);
    }
    class_edges.push_back(static_cast<double>(n_sub) / kSubBinsPerPx - R);
    const auto column_past = [](double at, double at0, double step) {
        const double x = (at - at0) / step;
        return step > 0 ? std::ceil(x) : std::floor(x) + 1.0;
    };
    const auto recheck_row = [](std::size_t r, double room, double per_row,
                                std::size_t r_end) -> std::size_t {
        if (per_row == 0.0) return r_end;
        const double rows_left = std::floor((room - 1e-6) / per_row);
        return rows_left >= 1.0 ? r + static_cast<std::size_t>(
                                          std::min(rows_left, static_cast<double>(r_end - r)))
                                : r + 1;
    };
    // A pixel's bin, or for an unused pixel the side of the used bins it is on (−1 below the
    // middle of their range of d, −2 above). The unused pixels of a row are then contiguous runs
    // like the bins' (the bins are one interval of d, the unused pixels the rest).
    double used_lo = std::numeric_limits<double>::infinity(), used_hi = -used_lo;
    for (std::size_t hs = 0; hs < 2 * n_sub; ++hs)
        if (sub_bin[hs] >= 0) {
            const std::size_t k = hs / 2;  // the sub-bin
            const double lo = static_cast<double>(k) / kSubBinsPerPx - R;
            used_lo = std::min(used_lo, lo);
            used_hi = std::max(used_hi, lo + 1.0 / kSubBinsPerPx);
        }
    const double used_middle = 0.5 * (used_lo + used_hi);
    const auto unused_side = [used_middle](std::int32_t bin, double d) -> std::int32_t {
        return bin >= 0 ? bin : (d < used_middle ? -1 : -2);
    };
    // The end of the segment of `key` that starts at column c of a row (the first column in
    // (c, end) whose key differs, else end), from an estimate `e`: checked next to it (the usual
    // case: two evaluations), else found by an exponential and a binary search (the keys of a
    // row are contiguous runs).
    const auto segment_end = [](const auto& key_at, const auto& key, std::size_t c, std::size_t e,
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
    };
    const auto scan_band_steep = [&](Band& band) {
        constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
        const std::uint8_t* const flags = image.flags.data();
        const float* const v1 = p1;
        const Band::Outputs acc = band.outputs();
        const double* const split_of = split.data();
        // The half-sub-bin of (row with d0, column c), kNone outside the table, and the
        // distance in d to its nearest edge.
        const auto half_sub_bin = [&](double d, double& room) -> std::uint32_t {
            const double sf = d * kSubBinsPerPx + sub_offset;
            if (!(sf >= 0.0 && sf < static_cast<double>(n_sub))) {
                room = sf < 0.0 ? -R - d : d - (static_cast<double>(n_sub) / kSubBinsPerPx - R);
                return kNone;
            }
            const auto k = static_cast<std::size_t>(sf);
            const double lo = static_cast<double>(k) / kSubBinsPerPx - R;
            const double hi = lo + 1.0 / kSubBinsPerPx;
            const bool upper = d >= split_of[k];
            room = upper ? std::min(d - split_of[k], hi - d)
                         : std::min(d - lo, std::min(split_of[k], hi) - d);
            return static_cast<std::uint32_t>(2 * k + (upper ? 1 : 0));
        };
        const std::size_t rows = band.r1 - band.r0;
        std::vector<std::uint32_t> col_hs(w, kNone), col_n(w, 0);
        std::vector<double> col_d0(w, 0.0);
        std::vector<std::vector<std::uint32_t>> recheck(rows);
        // A column keeps its half-sub-bin while its d, moving by |u_y| a row, stays inside it.
        const auto schedule = [&](std::size_t r, std::size_t c, double room) {
            const std::size_t next = recheck_row(r, room, std::abs(uy), band.r1);
            if (next < band.r1) recheck[next - band.r0].push_back(static_cast<std::uint32_t>(c));
        };
        const auto flush = [&](std::size_t c) {
            if (col_n[c] == 0) return;
            const std::uint32_t hs = col_hs[c];
            assert(hs != kNone && hs >= acc.sub_lo && hs < acc.sub_lo + band.n_subs);
            acc.sub_count[hs - acc.sub_lo] += col_n[c];
            acc.sub_d[hs - acc.sub_lo] +=
                col_d0[c] + static_cast<double>(col_n[c]) * (static_cast<double>(c) * ux);
            col_n[c] = 0;
            col_d0[c] = 0.0;
        };
        const auto set_column = [&](std::size_t r, std::size_t c) {
            double room = 0.0;
            const std::uint32_t hs = half_sub_bin(row_d0(r) + static_cast<double>(c) * ux, room);
            if (hs != col_hs[c]) {
                flush(c);
                col_hs[c] = hs;
            }
            schedule(r, c, room);
        };
        for (std::size_t c = 0; c < w; ++c) set_column(band.r0, c);

        std::vector<std::int32_t> prev_bin(w, -1);
        std::int32_t* const prev_b = prev_bin.data();
        std::size_t prev_begin = 0, prev_end = 0;
        std::vector<float> above_buffer(v1 ? w : 0), row_buffer(v1 ? w : 0);
        const float* above = nullptr;
        if (band.r0 > 0) {  // the row before the band: bins only (summed by the band above)
            const detail::RowRun run = mark_row_bins(band.r0 - 1, prev_b);
            prev_begin = run.begin;
            prev_end = run.end;
            above = values_of(band.r0 - 1, run.begin, run.end, above_buffer.data());
        }
        for (std::size_t r = band.r0; r < band.r1; ++r) {
            for (const std::uint32_t c : recheck[r - band.r0]) set_column(r, c);
            const detail::RowRun run = row_run(r);
            clear_outside(prev_b, prev_begin, prev_end, run);
            prev_begin = run.begin;
            prev_end = run.end;
            const double d0 = row_d0(r), t0 = row_t0(r);
            const float* const vals = values_of(r, run.begin, run.end, row_buffer.data());
            const std::uint8_t* const row_flags = flags + r * w;
            const auto class_at = [&](std::size_t c) {
                const double d = d0 + static_cast<double>(c) * ux;
                return std::pair(unused_side(pixel_bin(0, d).bin, d), slice_at(t0, c));
            };
            // The first edge above d at the segment's start (it moves one way along the row).
            auto above_d = std::upper_bound(class_edges.begin(), class_edges.end(),
                                            d0 + static_cast<double>(run.begin) * ux);
            auto next_key = run.begin < run.end ? class_at(run.begin) : std::pair(-1, 0UL);
            for (std::size_t c = run.begin; c < run.end;) {
                const auto key = next_key;
                // The segment's end: the next edge between bins (in d) and the next slice
                // boundary (in t), whichever comes first along the row, then checked.
                const double d = d0 + static_cast<double>(c) * ux;
                double end_estimate = static_cast<double>(run.end);
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
                    end_estimate =
                        std::min(end_estimate,
                                 column_past(ax > 0 ? std::floor(t) + 1.0 : std::floor(t), t0, ax));
                }
                std::size_t e = static_cast<std::size_t>(std::clamp(
                    end_estimate, static_cast<double>(c + 1), static_cast<double>(run.end)));
                e = segment_end(class_at, key, c, e, run.end);
                if (e < run.end) next_key = class_at(e);
                const std::int32_t b = key.first;
                if (b < 0) {
                    std::fill(prev_b + c, prev_b + e, -1);
                    c = e;
                    continue;
                }
                assert(key.second >= acc.slice_lo && key.second < acc.slice_lo + acc.band_slices);
                const std::size_t si =
                    (static_cast<std::size_t>(b) - acc.bin_lo) * acc.band_slices +
                    (key.second - acc.slice_lo);
                BinSums& bs = acc.bins[static_cast<std::size_t>(b)];
                double sum_a = 0, sum_b = 0, sum2_a = 0, sum2_b = 0, diff2 = 0;
                std::size_t count = 0, diffs = 0;
                unsigned flag_bits = 0;
                for (std::size_t j = c; j < e; ++j) flag_bits |= row_flags[j];
                const bool any_flag = flag_bits != 0;
                if (!any_flag) {
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
                            ++band.flagged;
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
                c = e;
            }
            if (v1) std::swap(above_buffer, row_buffer);
            above = v1 ? above_buffer.data() : vals;
        }
        for (std::size_t c = 0; c < w; ++c) flush(c);
    };
    // The same along an axis closer to the image's rows (scan_band is its reference too). Along a
    // row d moves by u_x a pixel (|u_x| < 0.71) and t by a_x: a row is cut into segments of one
    // bin and one half-sub-bin (their pixels' count and Σd in closed form), and each column keeps
    // the slice its sums belong to until the rows at which its t, moving by a_y a row, can have
    // crossed a slice boundary (or its bin changes); noise from differences with the left
    // neighbour, inside a flag-free segment without per-pixel tests.
    const auto scan_band_shallow = [&](Band& band) {
        const std::uint8_t* const flags = image.flags.data();
        const std::size_t last_slice = n_slices - 1;
        const Band::Outputs acc = band.outputs();
        const double* const split_of = split.data();
        const std::size_t rows = band.r1 - band.r0;
        std::vector<std::int32_t> col_bin(w, -1);
        std::vector<std::size_t> col_slice(w, 0);
        std::vector<std::uint32_t> col_n(w, 0);
        std::vector<double> col_sum(w, 0.0);
        std::vector<std::vector<std::uint32_t>> recheck(rows);
        const auto flush = [&](std::size_t c) {
            if (col_n[c] == 0) return;
            assert(col_bin[c] >= 0);
            const std::size_t b = static_cast<std::size_t>(col_bin[c]);
            assert(col_slice[c] >= acc.slice_lo && col_slice[c] < acc.slice_lo + acc.band_slices);
            const std::size_t si =
                (b - acc.bin_lo) * acc.band_slices + (col_slice[c] - acc.slice_lo);
            acc.slice_sum[si] += col_sum[c];
            acc.slice_count[si] += col_n[c];
            col_n[c] = 0;
            col_sum[c] = 0.0;
        };
        // A column's slice, and when it must be found again: t moves by |a_y| a row.
        const auto set_slice = [&](std::size_t r, std::size_t c) {
            const double t0 = row_t0(r);
            const double t = t0 + static_cast<double>(c) * ax;
            const std::size_t sl = slice_at(t0, c);
            const double below =
                sl == 0 ? -std::numeric_limits<double>::infinity() : static_cast<double>(sl);
            const double above = sl == last_slice ? std::numeric_limits<double>::infinity()
                                                  : static_cast<double>(sl + 1);
            if (sl != col_slice[c]) {
                flush(c);
                col_slice[c] = sl;
            }
            const std::size_t next =
                recheck_row(r, std::min(t - below, above - t), std::abs(ay), band.r1);
            if (next < band.r1) recheck[next - band.r0].push_back(static_cast<std::uint32_t>(c));
        };
        for (std::size_t c = 0; c < w; ++c) set_slice(band.r0, c);
        std::vector<float> row_buffer(p1 ? w : 0);
        for (std::size_t r = band.r0; r < band.r1; ++r) {
            for (const std::uint32_t c : recheck[r - band.r0]) set_slice(r, c);
            const detail::RowRun run = row_run(r);
            const double d0 = row_d0(r);
            const float* const vals = values_of(r, run.begin, run.end, row_buffer.data());
            const std::uint8_t* const row_flags = flags + r * w;
            // The key of a pixel: its bin and (for a used bin) its half-sub-bin.
            const auto key_at = [&](std::size_t c) {
                const double d = d0 + static_cast<double>(c) * ux;
                const PixelBin pb = pixel_bin(0, d);
                return std::pair(unused_side(pb.bin, d), pb.bin >= 0 ? pb.sub : std::size_t{0});
            };
            auto above_d = std::upper_bound(class_edges.begin(), class_edges.end(),
                                            d0 + static_cast<double>(run.begin) * ux);
            float left_value = 0.0F;
            std::int32_t left_bin = -1;
            auto next_key = run.begin < run.end ? key_at(run.begin) : std::pair(-1, std::size_t{0});
            for (std::size_t c = run.begin; c < run.end;) {
                const auto key = next_key;
                const std::int32_t b = key.first;
                // The segment's end: the next edge of its half-sub-bin (a used bin) or between
                // bins (the class edges) along the row, then checked.
                const double d = d0 + static_cast<double>(c) * ux;
                double end_estimate = static_cast<double>(run.end);
                if (ux != 0.0) {
                    if (ux > 0)
                        while (above_d != class_edges.end() && *above_d <= d) ++above_d;
                    else
                        while (above_d != class_edges.begin() && *(above_d - 1) > d) --above_d;
                    if (b >= 0) {
                        const std::size_t k = key.second / 2;
                        const double lo = static_cast<double>(k) / kSubBinsPerPx - R;
                        const double hi = lo + 1.0 / kSubBinsPerPx;
                        const bool upper = key.second % 2 == 1;
                        const double edge = ux > 0 ? (upper ? hi : std::min(split_of[k], hi))
                                                   : (upper ? split_of[k] : lo);
                        end_estimate = std::min(end_estimate, column_past(edge, d0, ux));
                    } else if (ux > 0 && above_d != class_edges.end()) {
                        end_estimate = std::min(end_estimate, column_past(*above_d, d0, ux));
                    } else if (ux < 0 && above_d != class_edges.begin()) {
                        end_estimate = std::min(end_estimate, column_past(*(above_d - 1), d0, ux));
                    }
                }
                std::size_t e = static_cast<std::size_t>(std::clamp(
                    end_estimate, static_cast<double>(c + 1), static_cast<double>(run.end)));
                e = segment_end(key_at, key, c, e, run.end);
                if (e < run.end) next_key = key_at(e);
                if (b < 0) {
                    left_bin = -1;
                    c = e;
                    continue;
                }
                const std::size_t sub = key.second;
                assert(sub >= acc.sub_lo && sub < acc.sub_lo + band.n_subs);
                BinSums& bs = acc.bins[static_cast<std::size_t>(b)];
                unsigned flag_bits = 0;
                for (std::size_t j = c; j < e; ++j) flag_bits |= row_flags[j];
                double sum = 0, sum2 = 0, diff2 = 0, column_sum = 0;
                std::size_t count = 0, diffs = 0;
                if (flag_bits == 0) {
                    // Every pixel used: the moments and the differences of neighbours inside the
                    // segment in lanes, the difference with the pixel on its left, Σ column in
                    // closed form; the columns' slice sums (a column whose bin changes first
                    // hands its sums over).
                    if (left_bin == b) {
                        const double diff = static_cast<double>(vals[c]) - left_value;
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
                    for (std::size_t j = c; j < e; ++j) other_bin |= col_bin[j] != b ? 1U : 0U;
                    if (other_bin != 0)
                        for (std::size_t j = c; j < e; ++j)
                            if (col_bin[j] != b) {
                                flush(j);
                                col_bin[j] = b;
                            }
                    for (std::size_t j = c; j < e; ++j) {
                        col_sum[j] += static_cast<double>(vals[j]);
                        ++col_n[j];
                    }
                    left_bin = b;
                    left_value = vals[e - 1];
                } else {
                    for (std::size_t j = c; j < e; ++j) {
                        if (row_flags[j] != 0) {
                            ++band.flagged;
                            ++bs.flagged;
                            left_bin = -1;
                            continue;
                        }
                        const double v = vals[j];
                        sum += v;
                        sum2 += v * v;
                        ++count;
                        column_sum += static_cast<double>(j);
                        if (left_bin == b) {
                            const double diff = v - static_cast<double>(left_value);
                            diff2 += diff * diff;
                            ++diffs;
                        }
                        left_bin = b;
                        left_value = vals[j];
                        if (col_bin[j] != b) {
                            flush(j);
                            col_bin[j] = b;
                        }
                        col_sum[j] += v;
                        ++col_n[j];
                    }
                }
                bs.sum += sum;
                bs.sum2 += sum2;
                bs.diff2 += diff2;
                bs.count += count;
                bs.diffs += diffs;
                acc.sub_count[sub - acc.sub_lo] += static_cast<std::uint32_t>(count);
                acc.sub_d[sub - acc.sub_lo] += static_cast<double>(count) * d0 + column_sum * ux;
                c = e;
            }
        }
        for (std::size_t c = 0; c < w; ++c) flush(c);
    };
    detail::run_bands(n_bands, options.threads, [&](std::size_t k) {
        prepare_band(bands[k], h * k / n_bands, h * (k + 1) / n_bands);
        if (reg)
            scan_band(bands[k]);
        else if (rows_along_axis)
            scan_band_steep(bands[k]);
        else
            scan_band_shallow(bands[k]);
    });

    // The bands' sums, in band order.
    std::vector<BinSums> bins(n_bins);
    std::vector<double> slice_sum(n_bins * n_slices, 0.0);
    std::vector<std::uint32_t> slice_count(n_bins * n_slices, 0);
    std::vector<std::uint32_t> sub_count(2 * n_sub, 0);
    std::vector<double> sub_d(2 * n_sub, 0.0);
    for (const Band& band : bands) {
        out.pixels_flagged += band.flagged;
        for (std::size_t b = 0; b < n_bins; ++b) {
            BinSums& to = bins[b];
            const BinSums& from = band.bins[b];
            to.sum += from.sum;
            to.sum2 += from.sum2;
            to.diff2 += from.diff2;
            to.count += from.count;
            to.diffs += from.diffs;
            to.flagged += from.flagged;
        }
        for (std::size_t k = 0; k < band.n_subs; ++k) {
            sub_count[band.sub_lo + k] += band.sub_count[k];
            sub_d[band.sub_lo + k] += band.sub_d[k];
        }
        for (std::size_t b = 0; b < band.n_band_bins; ++b)
            for (std::size_t j = 0; j < band.n_band_slices; ++j) {
                const std::size_t from = b * band.n_band_slices + j;
                const std::size_t to = (band.bin_lo + b) * n_slices + band.slice_lo + j;
                slice_sum[to] += band.slice_sum[from];
                slice_count[to] += band.slice_count[from];
            }
    }

    // Bins: mean, standard errors, geometry nodes.
    struct Work {
        ProfileBin bin;
        std::vector<detail::ProfileNode> nodes;
    };
    std::vector<Work> kept;
    std::size_t dropped_small = 0, dropped_dark = 0;
    // Each bin's used half-sub-bins, in order.
    std::vector<std::vector<std::size_t>> subs_of_bin(n_bins);
    for (std::size_t k = 0; k < 2 * n_sub; ++k)
        if (sub_bin[k] >= 0 && sub_count[k] > 0)
            subs_of_bin[static_cast<std::size_t>(sub_bin[k])].push_back(k);
    for (std::size_t b = 0; b < n_bins; ++b) {
        const BinSums& bs = bins[b];
        out.pixels_used += bs.count;
        if (bs.count == 0) continue;
        if (bs.count < options.min_pixels_per_bin) {
            ++dropped_small;
            continue;
        }
        Work wk;
        ProfileBin& pb = wk.bin;
        const auto n = static_cast<double>(bs.count);
        pb.count = bs.count;
        pb.flagged = bs.flagged;
        pb.raw_mean = bs.sum / n;
        const double var =
            bs.count > 1 ? std::max(0.0, (bs.sum2 - n * pb.raw_mean * pb.raw_mean) / (n - 1.0))
                         : 0.0;
        const double noise_var =
            bs.diffs >= 2 ? bs.diff2 / (2.0 * static_cast<double>(bs.diffs)) : var;
        pb.stderr_pixel = std::sqrt(noise_var / n);
        double s2 = 0;
        std::size_t J = 0;
        for (std::size_t j = 0; j < n_slices; ++j) {
            const std::uint32_t nj = slice_count[b * n_slices + j];
            if (nj == 0) continue;
            ++J;
            const double e = slice_sum[b * n_slices + j] - static_cast<double>(nj) * pb.raw_mean;
            s2 += e * e;  // n_j² (m_j − m)²
        }
        pb.slices = J;
        pb.stderr_slices =
            J >= 2 ? std::sqrt(s2 * static_cast<double>(J) / static_cast<double>(J - 1)) / n : 0.0;
        // Nodes: the bin's sub-bins grouped into at most kNodesPerBin runs (count, mean d).
        const std::vector<std::size_t>& subs = subs_of_bin[b];
        const std::size_t group = (subs.size() + kNodesPerBin - 1) / kNodesPerBin;
        double dsum = 0;
        for (std::size_t g = 0; g < subs.size(); g += group) {
            double cnt = 0, ds = 0;
            for (std::size_t k = g; k < std::min(subs.size(), g + group); ++k) {
                cnt += sub_count[subs[k]];
                ds += sub_d[subs[k]];
            }
            dsum += ds;
            wk.nodes.push_back(
                detail::cylinder_node(ds / cnt / R, cnt / n, ux, uy, options.light, options.view));
        }
        pb.across_px = dsum / n;
        pb.alpha_rad = std::asin(std::clamp(pb.across_px / R, -1.0, 1.0));
        const detail::ProfileNode centre =
            detail::cylinder_node(pb.across_px / R, 1.0, ux, uy, options.light, options.view);
        if (!centre.lit) {
            ++dropped_dark;  // L or V below the horizon of the bin's mean normal
            continue;
        }
        pb.geometry = centre.geometry;
        pb.theta_i_rad = pb.geometry.theta_i_rad;
        kept.push_back(std::move(wk));
    }
    if (dropped_small)
        out.warnings.push_back(concat(std::to_string(dropped_small), " bin(s) with fewer than ",
                                      std::to_string(options.min_pixels_per_bin),
                                      " used pixels left out"));
    if (dropped_dark)
        out.warnings.push_back(concat(std::to_string(dropped_dark),
                                      " bin(s) where the light or the viewer is below the "
                                      "surface's horizon left out"));
    if (out.pixels_flagged)
        out.warnings.push_back(concat(std::to_string(out.pixels_flagged),
                                      " flagged pixel(s) (saturated, clipped) left out"));
    if (kept.size() < 3)
        throw DataError(concat(image_name(image), ": the cylinder profile has ",
                               std::to_string(kept.size()), " bin(s) with at least ",
                               std::to_string(options.min_pixels_per_bin),
                               " usable pixels; at least 3 are needed"));
    std::stable_sort(kept.begin(), kept.end(), [&](const Work& x, const Work& y) {
        return both ? x.bin.alpha_rad < y.bin.alpha_rad : x.bin.theta_i_rad < y.bin.theta_i_rad;
    });
    if (both)  // the departure rule and plots run over increasing θi
        std::stable_sort(kept.begin(), kept.end(), [](const Work& x, const Work& y) {
            return x.bin.theta_i_rad < y.bin.theta_i_rad;
        });

    // Normalise by the maximum (§2); the standard errors by the same factor.
    for (const Work& wk : kept) out.maximum = std::max(out.maximum, wk.bin.raw_mean);
    if (!(out.maximum > 0))
        throw DataError(
            concat(image_name(image), ": the cylinder profile has no positive brightness"));
    std::vector<std::vector<detail::ProfileNode>> nodes;
    for (Work& wk : kept) {
        ProfileBin& pb = wk.bin;
        pb.brightness = pb.raw_mean / out.maximum;
        pb.stderr_slices /= out.maximum;
        pb.stderr_pixel /= out.maximum;
        pb.standard_error =
            std::max({pb.stderr_slices, pb.stderr_pixel, kMinRelativeStandardError});
        pb.in_fit =
            pb.theta_i_rad <= deg_to_rad(options.fit_max_theta_i_deg) && pb.brightness > 0 &&
            pb.standard_error > 0 &&
            static_cast<double>(pb.flagged) <=
                options.fit_max_flagged_fraction * static_cast<double>(pb.flagged + pb.count);
        out.bins.push_back(pb);
        nodes.push_back(std::move(wk.nodes));
    }

    // Fits: the two correlations side by side (independent problems; the same result whatever
    // the number of threads).
    detail::run_bands(2, options.threads, [&](std::size_t k) {
        (k == 0 ? out.gaussian_fit : out.exponential_fit) = detail::fit_profile(
            out.bins, nodes, k == 0 ? Correlation::Gaussian : Correlation::Exponential,
            options.factor, options.radiometry);
    });
    if (out.gaussian_fit.sigma_over_T && out.exponential_fit.sigma_over_T)
        out.preferred = out.exponential_fit.aic < out.gaussian_fit.aic ? Correlation::Exponential
                                                                       : Correlation::Gaussian;
    else if (out.exponential_fit.sigma_over_T)
        out.preferred = Correlation::Exponential;

    // Model curves.
    for (const ProfileModel m : kProfileModels) {
        ProfileModelCurve curve;
        curve.model = m;
        curve.name = std::string(to_string(m));
        if (m != ProfileModel::Lambert) {
            if (options.sigma_over_T)
                curve.sigma_over_T = options.sigma_over_T;
            else
                curve.sigma_over_T = m == ProfileModel::VhExponential
                                         ? out.exponential_fit.sigma_over_T
                                         : out.gaussian_fit.sigma_over_T;
            if (!curve.sigma_over_T) {
                out.warnings.push_back(
                    concat("no ", to_string(m), " curve: the fit of its σ/T did not succeed"));
                out.models.push_back(std::move(curve));
                continue;
            }
        }
        const double s = curve.sigma_over_T.value_or(1.0);
        curve.prediction = detail::bin_model_averages(nodes, [&](const Geometry& g) {
            return profile_model_brightness(m, g, s, options.radiometry);
        });
        const double mx = *std::max_element(curve.prediction.begin(), curve.prediction.end());
        double ss = 0;
        for (std::size_t b = 0; b < out.bins.size(); ++b) {
            curve.prediction[b] = mx > 0 ? curve.prediction[b] / mx : 0.0;
            const double e = curve.prediction[b] - out.bins[b].brightness;
            ss += e * e;
        }
        curve.rms_difference = std::sqrt(ss / static_cast<double>(out.bins.size()));
        curve.departure_bin = detail::departure_bin(out.bins, curve.prediction, options.departure_k,
                                                    options.departure_bins);
        if (curve.departure_bin)
            curve.departure_theta_i_rad = out.bins[*curve.departure_bin].theta_i_rad;
        out.models.push_back(std::move(curve));
    }
    if (const auto& s = out.curve(ProfileModel::VhGaussian).sigma_over_T)
        out.theta_K_rad = caron_theta_K_rad(*s);
    // A detected axis takes the silhouette's edge for the limb. On an object whose brightness
    // fades smoothly to the silhouette's level (a narrow very-rough lobe lit from near the
    // camera) the edge lies inside the true limb, and the radius, hence every angle, is off; a
    // limb that stays bright to the edge (Lambert: cos 80° = 0.17) is found where it is. The
    // sign: the profile 10° inside the detected limb is within a few times the silhouette's
    // level.
    if (axis.detected && out.maximum > 0.0 && !out.bins.empty()) {
        // The bin nearest 80° (or the outermost one, when the profile stops short of 80°).
        const double level = silhouette_level / out.maximum;
        const double target = deg_to_rad(80.0);
        const auto distance = [&](const ProfileBin& b) {
            return std::abs(std::min(std::abs(b.alpha_rad), target) - target) -
                   1e-3 * std::abs(b.alpha_rad);
        };
        const ProfileBin* near = &out.bins.front();
        for (const ProfileBin& b : out.bins)
            if (distance(b) < distance(*near)) near = &b;
        if (std::abs(near->alpha_rad) >= deg_to_rad(60.0) &&
            near->brightness < kDarkLimbFactor * level)
            out.warnings.push_back(concat(
                "the profile at ", check::format_number(rad_to_deg(std::abs(near->alpha_rad))),
                "° from the axis (", check::format_number(near->brightness),
                " of the maximum) is within ", check::format_number(kDarkLimbFactor),
                "x the silhouette's level (", check::format_number(level),
                "): the limb is dark, the detected edge is likely inside the true limb, so the "
                "radius and the angles are biased; give the axis (or edges) of the cylinder"));
    }
    return out;
}

}  // namespace roughscope::image

namespace roughscope::image::detail {

void check_unit_direction(std::string_view name, const Eigen::Vector3d& v) {
    if (!v.allFinite() || std::abs(v.norm() - 1.0) > 1e-6)
        throw InvalidArgument(concat(name, " direction (", check::format_number(v.x()), ", ",
                                     check::format_number(v.y()), ", ", check::format_number(v.z()),
                                     ") must be a finite unit vector (camera frame)"));
    if (!(v.z() > 0.0))
        throw InvalidArgument(concat(name, " direction (", check::format_number(v.x()), ", ",
                                     check::format_number(v.y()), ", ", check::format_number(v.z()),
                                     ") must point towards the camera's side (z > 0): it is "
                                     "below the horizon of every visible surface point"));
}

ProfileNode cylinder_node(double s, double weight, double ux, double uy,
                          const Eigen::Vector3d& light, const Eigen::Vector3d& view) {
    s = std::clamp(s, -1.0, 1.0);
    const Eigen::Vector3d n(s * ux, -s * uy, std::sqrt(std::max(0.0, 1.0 - s * s)));
    ProfileNode node;
    node.weight = weight;
    if (const auto g = geometry_from_vectors(n.normalized(), light, view)) {
        node.geometry = *g;
        node.lit = true;
    }
    return node;
}

ProfileFit fit_profile(const std::vector<ProfileBin>& bins,
                       const std::vector<std::vector<ProfileNode>>& nodes, Correlation correlation,
                       GeometricFactor factor, Radiometry radiometry) {
    ProfileFit fit;
    fit.correlation = correlation;
    std::vector<std::size_t> used;
    LeastSquaresProblem problem;
    for (std::size_t b = 0; b < bins.size(); ++b) {
        if (!bins[b].in_fit) continue;
        used.push_back(b);
        problem.data.push_back(bins[b].brightness);
        problem.weights.push_back(1.0 / (bins[b].standard_error * bins[b].standard_error));
    }
    fit.bins = static_cast<int>(used.size());
    if (used.size() < 3) {
        fit.status = SolverStatus::NotIdentifiable;
        fit.message = concat(std::to_string(used.size()),
                             " bin(s) in the fit range; σ/T and the gain need at least 3");
        return fit;
    }
    ParameterSpec p;
    p.name = "sigma_over_T";
    p.lower = 1e-3;
    p.upper = 1e3;
    problem.parameters = {p};
    problem.residual = ResidualType::Absolute;
    problem.gain = GainMode::Profiled;
    problem.model = [&](std::span<const double> theta, std::span<double> out) {
        const double s = theta[0];
        for (std::size_t k = 0; k < used.size(); ++k) {
            double m = 0;
            for (const ProfileNode& n : nodes[used[k]])
                if (n.lit)
                    m += n.weight *
                         very_rough_brightness(n.geometry, s, correlation, factor, radiometry);
            if (!std::isfinite(m)) return false;
            out[k] = m;
        }
        return true;
    };
    const LeastSquaresResult r = solve_least_squares(problem);
    fit.status = r.status;
    fit.message = r.message;
    fit.aic = r.aic;
    fit.gain = r.gain;
    const FitParameter& sp = r.parameter("sigma_over_T");
    if (sp.identified && r.status != SolverStatus::Failed &&
        r.status != SolverStatus::NotIdentifiable) {
        fit.sigma_over_T = sp.value;
        if (r.covariance_available && !sp.at_bound) fit.sigma_over_T_stderr = sp.std_error;
    }
    return fit;
}

std::optional<std::size_t> departure_bin(const std::vector<ProfileBin>& bins,
                                         const std::vector<double>& prediction, double k,
                                         std::size_t run) {
    const std::size_t n = bins.size();
    auto off = [&](std::size_t b) {
        return std::abs(prediction[b] - bins[b].brightness) > k * bins[b].standard_error;
    };
    for (std::size_t b = 0; b < n; ++b) {
        const std::size_t end = std::min(n, b + run);
        bool all = true;
        for (std::size_t j = b; j < end && all; ++j) all = off(j);
        if (all) return b;
    }
    return std::nullopt;
}

}  // namespace roughscope::image::detail
