// The steps of the sphere's BRDF table (sphere_steps.hpp): the cells, the pass over the disc and
// the cells' measurements (docs/curved-objects.md).
#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "object_profile.hpp"
#include "sphere_steps.hpp"

namespace roughscope::image::detail {
namespace {

// Used pixels of a run of one row in one cell: their moments, and for the pixels left out (flagged
// or outside the region) Σ px, Σ px².
struct SegmentSums {
    double sum = 0, sum2 = 0, diff2 = 0;
    double skipped_x = 0, skipped_xx = 0;
    std::uint32_t count = 0, diffs = 0;
    std::size_t flagged = 0;
};

// A grey segment of n values, every pixel used (the common case): the sums without the per-pixel
// tests, in two interleaved lanes.
SegmentSums grey_segment_sums(const float* a, std::size_t n) {
    SegmentSums seg;
    double s0 = 0, s1 = 0, q0 = 0, q1 = 0, d0 = 0, d1 = 0;
    std::size_t i = 0;
    for (; i + 2 <= n; i += 2) {
        const double v0 = a[i], v1 = a[i + 1];
        s0 += v0;
        s1 += v1;
        q0 += v0 * v0;
        q1 += v1 * v1;
        const double e1 = v1 - v0;
        d1 += e1 * e1;
        if (i + 2 < n) {
            const double e2 = static_cast<double>(a[i + 2]) - v1;
            d0 += e2 * e2;
        }
    }
    if (i < n) {
        const double v = a[i];
        s0 += v;
        q0 += v * v;
    }
    seg.sum = s0 + s1;
    seg.sum2 = q0 + q1;
    seg.diff2 = d0 + d1;
    seg.count = static_cast<std::uint32_t>(n);
    seg.diffs = static_cast<std::uint32_t>(n - 1);
    return seg;
}

// One pass's rows (sum_sphere_cells): everything it reads, as members set once.
class SpherePass {
  public:
    struct Counts {
        std::size_t used = 0, flagged = 0;
    };

    SpherePass(const LinearImage& image, const std::uint8_t* region, const CircleFit& circle,
               const SphereOptions& options, SphereCells& cells)
        : cx_(circle.centre_x_px),
          cy_(circle.centre_y_px),
          R_(circle.radius_px),
          inv_R_(1.0 / circle.radius_px),
          rho2_max_(options.limb_fraction * options.limb_fraction),
          cos_max_(std::cos(deg_to_rad(options.max_angle_deg))),
          Lx_(options.light.x()),
          Ly_(options.light.y()),
          Lz_(options.light.z()),
          Vx_(options.view.x()),
          Vy_(options.view.y()),
          Vz_(options.view.z()),
          w_(image.width),
          k_(cells.cell_px),
          gw_(cells.columns),
          p0_(image.plane(0)),
          p1_(image.channels == 3 ? image.plane(1) : nullptr),
          p2_(image.channels == 3 ? image.plane(2) : nullptr),
          flags_(image.flags.data()),
          reg_(region),
          cells_(cells.cells.data()) {
        assert(Lz_ > 0.0 && Vz_ > 0.0);
        const double w = static_cast<double>(image.width);
        c_lo_ = static_cast<std::size_t>(std::clamp(std::floor(cx_ - R_), 0.0, w));
        c_hi_ = static_cast<std::size_t>(std::clamp(std::ceil(cx_ + R_), 0.0, w));
    }

    // Row r's pixels into its cells. Only the columns within 2 px of the chord ρ = ρ_max are
    // visited (the test is exact; the chord only skips pixels far outside it).
    void row(std::size_t r, Counts& counts) const;

  private:
    // The used segment [c0, c1) of row r (other pixels: flagged or outside the region).
    SegmentSums segment_sums(std::size_t r, std::size_t c0, std::size_t c1) const;

    double cx_, cy_, R_, inv_R_, rho2_max_, cos_max_;
    double Lx_, Ly_, Lz_, Vx_, Vy_, Vz_;
    std::size_t w_, k_, gw_, c_lo_ = 0, c_hi_ = 0;
    const float *p0_, *p1_, *p2_;
    const std::uint8_t* flags_;
    const std::uint8_t* reg_;
    CellSums* cells_;
};

SegmentSums SpherePass::segment_sums(std::size_t r, std::size_t c0, std::size_t c1) const {
    const float* row0 = p0_ + r * w_;
    const float* row1 = p1_ ? p1_ + r * w_ : nullptr;
    const float* row2 = p2_ ? p2_ + r * w_ : nullptr;
    const std::uint8_t* row_flags = flags_ + r * w_;
    const std::uint8_t* row_reg = reg_ ? reg_ + r * w_ : nullptr;
    std::uint8_t any_flag = 0;
    if (!row_reg && !row1)
        for (std::size_t c = c0; c < c1; ++c) any_flag |= row_flags[c];
    if (!row_reg && !row1 && any_flag == 0) return grey_segment_sums(row0 + c0, c1 - c0);
    SegmentSums seg;
    bool left_used = false;  // the pixel on the left is used (and in this cell)
    float left_value = 0.0F;
    for (std::size_t c = c0; c < c1; ++c) {
        const bool out_of_region = row_reg && !row_reg[c];
        if (out_of_region || row_flags[c] != 0) {
            seg.flagged += out_of_region ? 0 : 1;
            const double px = static_cast<double>(c) + 0.5 - cx_;
            seg.skipped_x += px;
            seg.skipped_xx += px * px;
            left_used = false;
            continue;
        }
        float v = row0[c];
        if (row1) v = (v + row1[c] + row2[c]) * (1.0F / 3.0F);
        const double vd = v;
        seg.sum += vd;
        seg.sum2 += vd * vd;
        ++seg.count;
        if (left_used) {
            const double diff = vd - left_value;
            seg.diff2 += diff * diff;
            ++seg.diffs;
        }
        left_value = v;
        left_used = true;
    }
    return seg;
}

void SpherePass::row(std::size_t r, Counts& counts) const {
    const double ny = (cy_ - (static_cast<double>(r) + 0.5)) * inv_R_;
    const double ny2 = ny * ny;
    if (ny2 > rho2_max_) return;  // ρ² ≥ ny² > ρ_max² on the whole row
    const double half_chord = R_ * std::sqrt(rho2_max_ - ny2) + 2.0;
    const std::size_t c_begin = std::max(
        c_lo_, static_cast<std::size_t>(std::max(0.0, std::floor(cx_ - half_chord - 0.5))));
    const std::size_t c_end =
        std::min(c_hi_, static_cast<std::size_t>(std::max(0.0, std::ceil(cx_ + half_chord))));
    const double ny_l = ny * Ly_, ny_v = ny * Vy_, py = ny * R_;
    // The lit-and-seen test of the pixel centre in column c (docs/curved-objects.md).
    const auto lit_and_seen = [&](std::size_t c) {
        const double nx = (static_cast<double>(c) + 0.5 - cx_) * inv_R_;
        const double rho2 = nx * nx + ny2;
        if (!(rho2 <= rho2_max_)) return false;
        const double nz = std::sqrt(1.0 - rho2);
        const double nl = nx * Lx_ + ny_l + nz * Lz_;
        const double nv = nx * Vx_ + ny_v + nz * Vz_;
        return nl > cos_max_ && nv > cos_max_;
    };
    // Along a row ρ² is convex and n·L, n·V are concave (L_z, V_z > 0: check_unit_direction),
    // so the pixels that pass are the columns between the first and the last that do: those two
    // are found by the test from each end, the columns between taken without it.
    std::size_t first = c_begin, last = c_end;
    while (first < c_end && !lit_and_seen(first)) ++first;
    if (first == c_end) return;
    while (last > first + 1 && !lit_and_seen(last - 1)) --last;
    CellSums* row_cells = cells_ + (r / k_) * gw_;
    // The row's pixels of one cell are summed, then added to the cell.
    for (std::size_t gx = first / k_; gx * k_ < last; ++gx) {
        const std::size_t c0 = std::max(first, gx * k_), c1 = std::min(last, gx * k_ + k_);
        const SegmentSums seg = segment_sums(r, c0, c1);
        counts.flagged += seg.flagged;
        if (seg.count == 0) continue;
        CellSums& cs = row_cells[gx];
        cs.sum += seg.sum;
        cs.sum2 += seg.sum2;
        cs.diff2 += seg.diff2;
        // Σ px, Σ px² over [c0, c1): m x̄ and m x̄² + m (m² − 1)/12 with x̄ the columns' mean px;
        // then less the pixels left out. py is the same for the row's pixels.
        const auto m = static_cast<double>(c1 - c0);
        const double mean_x = 0.5 * static_cast<double>(c0 + c1) - cx_;
        cs.sx += m * mean_x - seg.skipped_x;
        cs.sxx += m * mean_x * mean_x + m * (m * m - 1.0) / 12.0 - seg.skipped_xx;
        cs.sy += static_cast<double>(seg.count) * py;
        cs.syy += static_cast<double>(seg.count) * (py * py);
        cs.count += seg.count;
        cs.diffs += seg.diffs;
        counts.used += seg.count;
    }
}

// The second derivative at x1 of the parabola through (x0, y0), (x1, y1), (x2, y2).
double second_derivative(double x0, double y0, double x1, double y1, double x2, double y2) {
    return 2.0 * ((y2 - y1) / (x2 - x1) - (y1 - y0) / (x1 - x0)) / (x2 - x0);
}

// The cells' grid and the usable test of a cell (enough used pixels).
struct CellGrid {
    const SphereCells& cells;
    double min_count;

    const CellSums* usable(std::size_t gx, std::size_t gy) const {
        if (gx >= cells.columns || gy >= cells.rows) return nullptr;
        const CellSums& cs = cells.cells[gy * cells.columns + gx];
        return cs.count > 0 && static_cast<double>(cs.count) >= min_count ? &cs : nullptr;
    }
};

double mean_of(const CellSums& c) { return c.sum / c.count; }
double cx_of(const CellSums& c) { return c.sx / c.count; }
double cy_of(const CellSums& c) { return c.sy / c.count; }

// Ē = E(centroid) + ½ (E_xx var_x + E_yy var_y) + ... (Taylor expansion over the cell): the
// value at the centroid (xm, ym), with the curvature from the parabola through the means of the
// cell and its two neighbours along each axis.
double cell_value_at_centroid(const CellGrid& grid, std::size_t gx, std::size_t gy, double xm,
                              double ym) {
    const CellSums& cs = grid.cells.cells[gy * grid.cells.columns + gx];
    const auto n = static_cast<double>(cs.count);
    const double mean = cs.sum / n;
    double value = mean;
    if (grid.cells.cell_px > 1) {
        const CellSums* l = gx > 0 ? grid.usable(gx - 1, gy) : nullptr;
        const CellSums* rt = grid.usable(gx + 1, gy);
        if (l && rt)
            value -= 0.5 *
                     second_derivative(cx_of(*l), mean_of(*l), xm, mean, cx_of(*rt), mean_of(*rt)) *
                     std::max(0.0, cs.sxx / n - xm * xm);
        // Image rows go down, y (camera frame) up: the cell above has the larger y.
        const CellSums* up = gy > 0 ? grid.usable(gx, gy - 1) : nullptr;
        const CellSums* dn = grid.usable(gx, gy + 1);
        if (up && dn)
            value -=
                0.5 *
                second_derivative(cy_of(*dn), mean_of(*dn), ym, mean, cy_of(*up), mean_of(*up)) *
                std::max(0.0, cs.syy / n - ym * ym);
    }
    return value;
}

}  // namespace

std::size_t sphere_cell_px(const SphereOptions& options, double radius_px) {
    const double rho_max = options.limb_fraction;
    const double disc_px = kPi * (rho_max * radius_px) * (rho_max * radius_px);
    return options.cell_px > 0
               ? options.cell_px
               : std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(std::sqrt(
                                              disc_px / static_cast<double>(options.max_cells)))));
}

SphereCells sum_sphere_cells(const LinearImage& image, const std::uint8_t* region,
                             const CircleFit& circle, const SphereOptions& options,
                             std::size_t cell_px) {
    const std::size_t w = image.width, h = image.height, k = cell_px;
    SphereCells out;
    out.cell_px = k;
    out.columns = (w + k - 1) / k;
    out.rows = (h + k - 1) / k;
    out.cells.resize(out.columns * out.rows);
    const SpherePass pass(image, region, circle, options, out);
    // Rows that can hold the disc.
    const double cy = circle.centre_y_px, R = circle.radius_px;
    const auto r_lo = static_cast<std::size_t>(std::clamp(std::floor(cy - R), 0.0, double(h)));
    const auto r_hi = static_cast<std::size_t>(std::clamp(std::ceil(cy + R), 0.0, double(h)));
    // Bands of whole rows of cells, one thread each: a cell is summed by one band, in the same
    // order whatever the number of threads.
    const std::size_t gy_lo = r_lo / k, gy_hi = r_hi > r_lo ? (r_hi - 1) / k + 1 : gy_lo;
    const std::size_t bands = std::min<std::size_t>(64, gy_hi - gy_lo);
    std::vector<SpherePass::Counts> band_counts(bands);
    run_bands(bands, options.threads, [&](std::size_t band) {
        const std::size_t g0 = gy_lo + (gy_hi - gy_lo) * band / bands;
        const std::size_t g1 = gy_lo + (gy_hi - gy_lo) * (band + 1) / bands;
        for (std::size_t r = std::max(r_lo, g0 * k); r < std::min(r_hi, g1 * k); ++r)
            pass.row(r, band_counts[band]);
    });
    for (const SpherePass::Counts& bc : band_counts) {
        out.pixels_used += bc.used;
        out.pixels_flagged += bc.flagged;
    }
    return out;
}

std::vector<CellMeasurement> cell_measurements(const SphereCells& cells, const CircleFit& circle,
                                               const SphereOptions& options, std::size_t& dropped) {
    const std::size_t k = cells.cell_px;
    const CellGrid grid{cells, options.min_cell_fraction * static_cast<double>(k * k)};
    const double inv_R = 1.0 / circle.radius_px;
    std::vector<CellMeasurement> rows;
    dropped = 0;
    for (std::size_t gy = 0; gy < cells.rows; ++gy)
        for (std::size_t gx = 0; gx < cells.columns; ++gx) {
            const CellSums& cs = cells.cells[gy * cells.columns + gx];
            if (cs.count == 0) continue;
            if (!grid.usable(gx, gy)) {
                ++dropped;
                continue;
            }
            const auto n = static_cast<double>(cs.count);
            const double xm = cs.sx / n, ym = cs.sy / n;  // centroid, px about the centre
            const double mean = cs.sum / n;
            const double value = cell_value_at_centroid(grid, gx, gy, xm, ym);
            const double nx = xm * inv_R, ny = ym * inv_R;
            const Eigen::Vector3d normal(nx, ny, std::sqrt(std::max(0.0, 1.0 - nx * nx - ny * ny)));
            const auto g = geometry_from_vectors(normal.normalized(), options.light, options.view);
            if (!g || g->theta_i_rad >= kPi / 2 || g->theta_s_rad >= kPi / 2) {
                ++dropped;
                continue;
            }
            const double var =
                cs.count > 1 ? std::max(0.0, (cs.sum2 - n * mean * mean) / (n - 1.0)) : 0.0;
            const double noise_var =
                cs.diffs >= 2 ? cs.diff2 / (2.0 * static_cast<double>(cs.diffs)) : var;
            const double cos_i = std::cos(g->theta_i_rad);
            rows.push_back(CellMeasurement{*g, value / cos_i, std::sqrt(noise_var / n) / cos_i});
        }
    return rows;
}

}  // namespace roughscope::image::detail
