#include "roughscope/objects/sphere.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "object_profile.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"

namespace roughscope::image {
namespace {

using check::format_number;

std::string image_name(const LinearImage& image) {
    return image.info.source.empty() ? std::string("image") : image.info.source;
}

struct CellSums {
    double sum = 0, sum2 = 0, diff2 = 0;
    double sx = 0, sy = 0, sxx = 0, syy = 0;  // pixel centres about the circle's centre, px
    std::uint32_t count = 0, diffs = 0;
};

// The second derivative at x1 of the parabola through (x0, y0), (x1, y1), (x2, y2).
double second_derivative(double x0, double y0, double x1, double y1, double x2, double y2) {
    return 2.0 * ((y2 - y1) / (x2 - x1) - (y1 - y0) / (x1 - x0)) / (x2 - x0);
}

}  // namespace

void check_sphere_options(const SphereOptions& options) {
    detail::check_unit_direction("sphere light", options.light);
    detail::check_unit_direction("sphere view", options.view);
    if (!(options.limb_fraction > 0.0 && options.limb_fraction <= 1.0))
        throw InvalidArgument(
            concat("sphere limb_fraction = ", format_number(options.limb_fraction),
                   " is outside the valid range (0, 1]"));
    if (!(options.max_angle_deg > 0.0 && options.max_angle_deg <= 90.0))
        throw InvalidArgument(
            concat("sphere max_angle_deg = ", format_number(options.max_angle_deg),
                   " is outside the valid range (0, 90] deg"));
    if (options.max_cells < 1) throw InvalidArgument("sphere max_cells must be at least 1");
    if (!(options.min_cell_fraction >= 0.0 && options.min_cell_fraction <= 1.0))
        throw InvalidArgument(
            concat("sphere min_cell_fraction = ", format_number(options.min_cell_fraction),
                   " is outside the valid range [0, 1]"));
    if (options.circle) {
        check::finite("sphere circle centre x", options.circle->centre_x_px);
        check::finite("sphere circle centre y", options.circle->centre_y_px);
        check::positive("sphere circle radius", options.circle->radius_px, " px");
    }
    validate(options.comparison);
}

SphereResult measure_sphere_table(const LinearImage& image,
                                  const std::vector<std::uint8_t>* region_mask,
                                  const SphereOptions& options) {
    check_sphere_options(options);
    // The values: read and checked by the silhouette's pass, or here when there is none.
    check_linear_image_layout(image);
    const std::size_t w = image.width, h = image.height;
    if (region_mask && region_mask->size() != image.pixel_count())
        throw InvalidArgument(concat("sphere region mask has ", std::to_string(region_mask->size()),
                                     " entries, the image ", image_name(image), " has ",
                                     std::to_string(image.pixel_count()), " pixels"));
    SphereResult out;
    if (options.circle) {
        check_linear_image(image);
        out.circle = *options.circle;
    } else {
        out.circle = fit_sphere_circle(
            detail::find_outline(image, options.silhouette, options.threads).silhouette,
            options.circle_fit);
        out.circle_detected = true;
    }
    const double cx = out.circle.centre_x_px, cy = out.circle.centre_y_px;
    const double R = out.circle.radius_px;
    const double rho_max = options.limb_fraction;
    const double disc_px = kPi * (rho_max * R) * (rho_max * R);
    const std::size_t k =
        options.cell_px > 0
            ? options.cell_px
            : std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(std::sqrt(
                                           disc_px / static_cast<double>(options.max_cells)))));
    out.cell_px = k;
    const std::size_t gw = (w + k - 1) / k, gh = (h + k - 1) / k;
    std::vector<CellSums> cells(gw * gh);

    const double cos_max = std::cos(deg_to_rad(options.max_angle_deg));
    const Eigen::Vector3d L = options.light, V = options.view;
    const float* p0 = image.plane(0);
    const float* p1 = image.channels == 3 ? image.plane(1) : nullptr;
    const float* p2 = image.channels == 3 ? image.plane(2) : nullptr;
    const std::uint8_t* reg = region_mask ? region_mask->data() : nullptr;
    const double inv_R = 1.0 / R, rho2_max = rho_max * rho_max;
    // Rows and columns that can hold the disc.
    const auto r_lo = static_cast<std::size_t>(std::clamp(std::floor(cy - R), 0.0, double(h)));
    const auto r_hi = static_cast<std::size_t>(std::clamp(std::ceil(cy + R), 0.0, double(h)));
    const auto c_lo = static_cast<std::size_t>(std::clamp(std::floor(cx - R), 0.0, double(w)));
    const auto c_hi = static_cast<std::size_t>(std::clamp(std::ceil(cx + R), 0.0, double(w)));
    // Row r's pixels into its cells. Only the columns within 2 px of the chord ρ = ρ_max are
    // visited (the test below is exact; the chord only skips pixels far outside it).
    struct Counts {
        std::size_t used = 0, flagged = 0;
    };
    // Everything the pass reads, as locals (no reload through references in the loop).
    const double Lx = L.x(), Ly = L.y(), Lz = L.z(), Vx = V.x(), Vy = V.y(), Vz = V.z();
    const std::uint8_t* flags = image.flags.data();
    assert(Lz > 0.0 && Vz > 0.0);
    const auto accumulate_row = [=, &cells](std::size_t r, Counts& counts) {
        const double ny = (cy - (static_cast<double>(r) + 0.5)) * inv_R;
        const double ny2 = ny * ny;
        if (ny2 > rho2_max) return;  // ρ² ≥ ny² > ρ_max² on the whole row
        const double half_chord = R * std::sqrt(rho2_max - ny2) + 2.0;
        const std::size_t c_begin = std::max(
            c_lo, static_cast<std::size_t>(std::max(0.0, std::floor(cx - half_chord - 0.5))));
        const std::size_t c_end =
            std::min(c_hi, static_cast<std::size_t>(std::max(0.0, std::ceil(cx + half_chord))));
        const double ny_l = ny * Ly, ny_v = ny * Vy, py = ny * R;
        const float* row0 = p0 + r * w;
        const float* row1 = p1 ? p1 + r * w : nullptr;
        const float* row2 = p2 ? p2 + r * w : nullptr;
        const std::uint8_t* row_flags = flags + r * w;
        const std::uint8_t* row_reg = reg ? reg + r * w : nullptr;
        // The lit-and-seen test of the pixel centre in column c (docs/curved-objects.md).
        const auto lit_and_seen = [&](std::size_t c) {
            const double nx = (static_cast<double>(c) + 0.5 - cx) * inv_R;
            const double rho2 = nx * nx + ny2;
            if (!(rho2 <= rho2_max)) return false;
            const double nz = std::sqrt(1.0 - rho2);
            const double nl = nx * Lx + ny_l + nz * Lz;
            const double nv = nx * Vx + ny_v + nz * Vz;
            return nl > cos_max && nv > cos_max;
        };
        // Along a row ρ² is convex and n·L, n·V are concave (L_z, V_z > 0:
        // check_unit_direction), so the pixels that pass are the columns between the first and
        // the last that do: those two are found by the test from each end, the columns between
        // taken without it.
        std::size_t first = c_begin, last = c_end;
        while (first < c_end && !lit_and_seen(first)) ++first;
        if (first == c_end) return;
        while (last > first + 1 && !lit_and_seen(last - 1)) --last;
        CellSums* row_cells = cells.data() + (r / k) * gw;
        // The row's pixels of one cell are summed here, then added to the cell.
        for (std::size_t gx = first / k; gx * k < last; ++gx) {
            const std::size_t c0 = std::max(first, gx * k), c1 = std::min(last, gx * k + k);
            double sum = 0, sum2 = 0, diff2 = 0;
            double skipped_x = 0, skipped_xx = 0;  // Σ px, Σ px² of the pixels left out
            std::uint32_t count = 0, diffs = 0;
            std::size_t flagged = 0;
            bool left_used = false;  // the pixel on the left is used (and in this cell)
            float left_value = 0.0F;
            // A grey segment with every pixel used (the common case): the sums without the
            // per-pixel tests, in two interleaved lanes.
            std::uint8_t any_flag = 0;
            if (!row_reg && !row1)
                for (std::size_t c = c0; c < c1; ++c) any_flag |= row_flags[c];
            if (!row_reg && !row1 && any_flag == 0) {
                const float* a = row0 + c0;
                const std::size_t n = c1 - c0;
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
                sum = s0 + s1;
                sum2 = q0 + q1;
                diff2 = d0 + d1;
                count = static_cast<std::uint32_t>(n);
                diffs = static_cast<std::uint32_t>(n - 1);
            } else {
                for (std::size_t c = c0; c < c1; ++c) {
                    const bool out_of_region = row_reg && !row_reg[c];
                    if (out_of_region || row_flags[c] != 0) {
                        flagged += out_of_region ? 0 : 1;
                        const double px = static_cast<double>(c) + 0.5 - cx;
                        skipped_x += px;
                        skipped_xx += px * px;
                        left_used = false;
                        continue;
                    }
                    float v = row0[c];
                    if (row1) v = (v + row1[c] + row2[c]) * (1.0F / 3.0F);
                    const double vd = v;
                    sum += vd;
                    sum2 += vd * vd;
                    ++count;
                    if (left_used) {
                        const double diff = vd - left_value;
                        diff2 += diff * diff;
                        ++diffs;
                    }
                    left_value = v;
                    left_used = true;
                }
            }
            counts.flagged += flagged;
            if (count == 0) continue;
            CellSums& cs = row_cells[gx];
            cs.sum += sum;
            cs.sum2 += sum2;
            cs.diff2 += diff2;
            // Σ px, Σ px² over [c0, c1): m x̄ and m x̄² + m (m² − 1)/12 with x̄ the columns' mean
            // px; then less the pixels left out. py is the same for the row's pixels.
            const auto m = static_cast<double>(c1 - c0);
            const double mean_x = 0.5 * static_cast<double>(c0 + c1) - cx;
            cs.sx += m * mean_x - skipped_x;
            cs.sxx += m * mean_x * mean_x + m * (m * m - 1.0) / 12.0 - skipped_xx;
            cs.sy += static_cast<double>(count) * py;
            cs.syy += static_cast<double>(count) * (py * py);
            cs.count += count;
            cs.diffs += diffs;
            counts.used += count;
        }
    };
    // Bands of whole rows of cells, one thread each: a cell is summed by one band, in the same
    // order whatever the number of threads.
    const std::size_t gy_lo = r_lo / k, gy_hi = r_hi > r_lo ? (r_hi - 1) / k + 1 : gy_lo;
    const std::size_t bands = std::min<std::size_t>(64, gy_hi - gy_lo);
    std::vector<Counts> band_counts(bands);
    detail::run_bands(bands, options.threads, [&](std::size_t band) {
        const std::size_t g0 = gy_lo + (gy_hi - gy_lo) * band / bands;
        const std::size_t g1 = gy_lo + (gy_hi - gy_lo) * (band + 1) / bands;
        for (std::size_t r = std::max(r_lo, g0 * k); r < std::min(r_hi, g1 * k); ++r)
            accumulate_row(r, band_counts[band]);
    });
    for (const Counts& bc : band_counts) {
        out.pixels_used += bc.used;
        out.pixels_flagged += bc.flagged;
    }
    if (out.pixels_flagged)
        out.warnings.push_back(concat(std::to_string(out.pixels_flagged),
                                      " flagged pixel(s) (saturated, clipped) left out"));

    // Cells → BRDF measurements.
    struct Row {
        Geometry g;
        double f = 0, se = 0;
    };
    std::vector<Row> rows;
    const double min_count = options.min_cell_fraction * static_cast<double>(k * k);
    std::size_t dropped = 0;
    auto usable = [&](std::size_t gx, std::size_t gy) -> const CellSums* {
        if (gx >= gw || gy >= gh) return nullptr;
        const CellSums& cs = cells[gy * gw + gx];
        return cs.count > 0 && static_cast<double>(cs.count) >= min_count ? &cs : nullptr;
    };
    const auto mean_of = [](const CellSums& c) { return c.sum / c.count; };
    const auto cx_of = [](const CellSums& c) { return c.sx / c.count; };
    const auto cy_of = [](const CellSums& c) { return c.sy / c.count; };
    for (std::size_t gy = 0; gy < gh; ++gy)
        for (std::size_t gx = 0; gx < gw; ++gx) {
            const CellSums& cs = cells[gy * gw + gx];
            if (cs.count == 0) continue;
            if (!usable(gx, gy)) {
                ++dropped;
                continue;
            }
            const auto n = static_cast<double>(cs.count);
            const double xm = cs.sx / n, ym = cs.sy / n;  // centroid, px about the centre
            const double mean = cs.sum / n;
            // Ē = E(centroid) + ½ (E_xx var_x + E_yy var_y) + ... (Taylor expansion over the
            // cell): the value at the centroid, with the curvature from the parabola through
            // the means of the cell and its two neighbours along each axis.
            double value = mean;
            if (k > 1) {
                const CellSums* l = gx > 0 ? usable(gx - 1, gy) : nullptr;
                const CellSums* rt = usable(gx + 1, gy);
                if (l && rt)
                    value -= 0.5 *
                             second_derivative(cx_of(*l), mean_of(*l), xm, mean, cx_of(*rt),
                                               mean_of(*rt)) *
                             std::max(0.0, cs.sxx / n - xm * xm);
                // Image rows go down, y (camera frame) up: the cell above has the larger y.
                const CellSums* up = gy > 0 ? usable(gx, gy - 1) : nullptr;
                const CellSums* dn = usable(gx, gy + 1);
                if (up && dn)
                    value -= 0.5 *
                             second_derivative(cy_of(*dn), mean_of(*dn), ym, mean, cy_of(*up),
                                               mean_of(*up)) *
                             std::max(0.0, cs.syy / n - ym * ym);
            }
            const double nx = xm * inv_R, ny = ym * inv_R;
            const Eigen::Vector3d normal(nx, ny, std::sqrt(std::max(0.0, 1.0 - nx * nx - ny * ny)));
            const auto g = geometry_from_vectors(normal.normalized(), L, V);
            if (!g || g->theta_i_rad >= kPi / 2 || g->theta_s_rad >= kPi / 2) {
                ++dropped;
                continue;
            }
            const double var =
                cs.count > 1 ? std::max(0.0, (cs.sum2 - n * mean * mean) / (n - 1.0)) : 0.0;
            const double noise_var =
                cs.diffs >= 2 ? cs.diff2 / (2.0 * static_cast<double>(cs.diffs)) : var;
            const double cos_i = std::cos(g->theta_i_rad);
            rows.push_back(Row{*g, value / cos_i, std::sqrt(noise_var / n) / cos_i});
        }
    if (dropped)
        out.warnings.push_back(
            concat(std::to_string(dropped), " cell(s) with too few usable pixels left out"));
    if (rows.size() < 3)
        throw DataError(concat(image_name(image), ": the sphere has ", std::to_string(rows.size()),
                               " usable cell(s); at least 3 are needed"));
    // Weights 1/σ_f², scaled to a mean of 1 (all 1 when no cell has a noise estimate).
    double mean_inv = 0;
    std::size_t with_noise = 0;
    for (const Row& rw : rows)
        if (rw.se > 0) {
            mean_inv += 1.0 / (rw.se * rw.se);
            ++with_noise;
        }
    const bool weighted = with_noise == rows.size();
    if (weighted) mean_inv /= static_cast<double>(rows.size());
    out.table.name = image.info.source.empty() ? std::string("sphere") : image.info.source;
    out.table.channel = image.channels == 3 ? "mean" : "grey";
    out.table.measurements.reserve(rows.size());
    int index = 0;
    for (const Row& rw : rows) {
        const double weight = weighted ? 1.0 / (rw.se * rw.se) / mean_inv : 1.0;
        out.table.measurements.push_back(make_brdf_measurement(
            ++index, rw.g.theta_i_rad, kPi, rw.g.theta_s_rad, rw.g.phi_s_rad, rw.f, weight));
    }
    if (!weighted)
        out.warnings.push_back("no pixel-noise estimate in some cells: all cells weighted 1");
    return out;
}

SphereResult measure_sphere(const LinearImage& image, const std::vector<std::uint8_t>* region_mask,
                            const SphereOptions& options) {
    SphereResult out = measure_sphere_table(image, region_mask, options);
    ComparisonOptions comparison = options.comparison;
    if (comparison.threads == 0) comparison.threads = options.threads;
    out.comparison = compare_brdf(out.table, comparison);
    return out;
}

}  // namespace roughscope::image
