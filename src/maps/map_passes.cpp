// The roughness map's passes over the rows of the two captures (map_evaluator.hpp, docs/maps.md
// "Tile means and the ratio"): tiles, and pixels with their neighbourhood's noise.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "maps/map_evaluator.hpp"
#include "maps/map_internal.hpp"
#include "roughscope/maps/maps.hpp"

namespace roughscope::image::detail {
namespace {

// The brightness of one row of a capture: channel average / s_k. A non-finite value in the row
// (any plane) is check_linear_image's InvalidArgument, so every value of the images is checked
// once, as it is read.
void load_row(const MapCapture& c, std::size_t r, std::vector<double>& out) {
    const LinearImage& im = *c.image;
    const double scale = 1.0 / (static_cast<double>(im.channels) * c.exposure_scale);
    const float* p0 = im.plane(0) + r * im.width;
    const bool three = im.channels != 1;
    if (scaled_row_is_finite(im.width, p0, three ? im.plane(1) + r * im.width : nullptr,
                             three ? im.plane(2) + r * im.width : nullptr, scale, out.data()))
        return;
    for (std::size_t ch = 0; ch < im.channels; ++ch)
        for (std::size_t x = 0; x < im.width; ++x) {
            const std::size_t k = ch * im.pixel_count() + r * im.width + x;
            if (!std::isfinite(im.values[k])) throw_non_finite_value(im, k);
        }
}

// A cell without an estimate has no class (its float layers stay NaN).
void mark_no_class(RoughnessMap& map, std::size_t index) {
    map.roughness_class[index] = kClassNone;
    if (!map.roughness_class_g.empty()) map.roughness_class_g[index] = kClassNone;
}

// A cell whose ratio no model produces (both correlations).
void mark_no_solution(Evaluator& ev, RoughnessMap& map, std::size_t index) {
    ++ev.counts().no_solution;
    ++ev.counts().no_solution_other;
    mark_no_class(map, index);
}

bool pixel_used(const MapCapture& c1, const MapCapture& c2, const MapOptions& o, std::size_t p) {
    if ((c1.image->flags[p] | c2.image->flags[p]) != 0) return false;
    if (!o.normal_map.empty()) {
        const float* n = o.normal_map.data() + 3 * p;
        if (!std::isfinite(n[0]) || !std::isfinite(n[1]) || !std::isfinite(n[2])) return false;
    }
    return true;
}

// The class statistics of a finished row of cells (the per-class mean of the summary: the rows'
// sums are added in row order afterwards, so the means do not depend on the bands).
ClassSums row_class_sums(const RoughnessMap& map, const MapOptions& o, std::size_t row) {
    const MapLayerValues& primary = map.sigma_over_T(o.correlation);
    ClassSums sums;
    for (std::size_t i = row * map.width; i < (row + 1) * map.width; ++i) {
        const std::uint8_t c = map.roughness_class[i];
        if (c != kClassNone) sums[c].add(primary[i]);
    }
    return sums;
}

}  // namespace

// Tiles: one pass over the rows, the sums of each tile of a row of tiles.
void tile_map(const std::vector<MapCapture>& captures, const MapOptions& o, Evaluator& ev,
              RoughnessMap& map, std::vector<std::int32_t>& cell_region,
              std::vector<ClassSums>& row_classes, std::size_t ty_begin, std::size_t ty_end) {
    const MapCapture& c1 = captures[0];
    const MapCapture& c2 = captures[1];
    const std::size_t W = c1.image->width, H = c1.image->height, w = o.window_px;
    std::vector<double> x1(W), x2(W);
    std::vector<Sums> sums(map.width);
    std::vector<Eigen::Vector3d> normals(map.width);
    std::vector<std::int32_t> region(map.width);
    const bool labels = !o.region_labels.empty();
    for (std::size_t ty = ty_begin; ty < ty_end; ++ty) {
        std::fill(sums.begin(), sums.end(), Sums{});
        std::fill(normals.begin(), normals.end(), Eigen::Vector3d::Zero());
        std::fill(region.begin(), region.end(), -2);
        const std::size_t r0 = ty * w, r1 = std::min(H, r0 + w);
        for (std::size_t r = r0; r < r1; ++r) {
            load_row(c1, r, x1);
            load_row(c2, r, x2);
            for (std::size_t tx = 0; tx < map.width; ++tx) {
                const std::size_t q0 = tx * w, q1 = std::min(W, q0 + w);
                Sums& s = sums[tx];
                for (std::size_t x = q0; x < q1; ++x) {
                    const std::size_t p = r * W + x;
                    if (labels) {
                        const std::int32_t l = o.region_labels[p];
                        std::int32_t& t = region[tx];
                        t = t == -2 ? l : (t == l ? t : -1);
                    }
                    if (!pixel_used(c1, c2, o, p)) continue;
                    s.add(x1[x], x2[x]);
                    if (!o.normal_map.empty()) {
                        const float* n = o.normal_map.data() + 3 * p;
                        normals[tx] += Eigen::Vector3d(n[0], n[1], n[2]);
                    }
                }
            }
        }
        for (std::size_t tx = 0; tx < map.width; ++tx) {
            const std::size_t index = ty * map.width + tx;
            const std::size_t q0 = tx * w, q1 = std::min(W, q0 + w);
            const double area = static_cast<double>((q1 - q0) * (r1 - r0));
            if (labels) cell_region[index] = std::max(region[tx], -1);
            const Sums& s = sums[tx];
            double m1 = 0, m2 = 0, var = 0;
            if (s.n < std::max(2.0, o.min_used_fraction * area)) {
                ++ev.counts().missing;
                mark_no_class(map, index);
                continue;
            }
            if (!s.pixel_log_variance(m1, m2, var)) {
                mark_no_solution(ev, map, index);
                continue;
            }
            Cell cell;
            cell.ratio = m1 / m2;
            cell.log_ratio = std::log(cell.ratio);
            cell.var_log_ratio = var / s.n;
            cell.normal = normals[tx];
            ev.evaluate(index, cell);
        }
        row_classes[ty] = row_class_sums(map, o, ty);
    }
}

// The first touch of every cell of rows [r_begin, r_end) of the map: NaN, no class (the
// layers are allocated without a fill; each band's thread writes its own).
void clear_rows(RoughnessMap& map, std::size_t r_begin, std::size_t r_end) {
    const std::size_t begin = r_begin * map.width, count = (r_end - r_begin) * map.width;
    for (auto* layer : {&map.E1_over_E2, &map.sigma_over_T_gaussian,
                        &map.sigma_over_T_gaussian_stderr, &map.sigma_over_T_exponential,
                        &map.sigma_over_T_exponential_stderr, &map.T_um, &map.T_um_stderr})
        if (!layer->empty()) std::fill_n(layer->data() + begin, count, kNaN);
    for (auto* layer : {&map.roughness_class, &map.roughness_class_g})
        if (!layer->empty()) std::fill_n(layer->data() + begin, count, kClassNone);
}

// and the pixel's ln-ratio variance, then the look-ups per pixel.
void pixel_map(const std::vector<MapCapture>& captures, const MapOptions& o, Evaluator& ev,
               RoughnessMap& map, std::vector<std::int32_t>& cell_region,
               std::vector<ClassSums>& row_classes, std::size_t r_begin, std::size_t r_end) {
    const MapCapture& c1 = captures[0];
    const MapCapture& c2 = captures[1];
    const std::size_t W = c1.image->width, H = c1.image->height, R = kPixelNoiseRadius;
    const std::size_t ring = 2 * R + 2;
    // The ring of rows: the two brightnesses and the pixel's weight (1 used, 0 not); the row each
    // slot holds.
    std::vector<std::vector<double>> x1(ring, std::vector<double>(W)),
        x2(ring, std::vector<double>(W)), used(ring, std::vector<double>(W));
    std::vector<std::size_t> slot_row(ring, H);
    // The column sums n, Σx1, Σx2, Σx1², Σx2², Σx1x2, each padded by R zeros either side.
    const std::size_t padded = W + 2 * R;
    std::array<std::vector<double>, 6> col;
    for (auto& c : col) c.assign(padded, 0.0);
    std::vector<double> ratio(W), var(W), state(W);
    auto load = [&](std::size_t r) {
        const std::size_t k = r % ring;
        if (slot_row[k] == r) return;
        load_row(c1, r, x1[k]);
        load_row(c2, r, x2[k]);
        const std::uint8_t* __restrict f1 = c1.image->flags.data() + r * W;
        const std::uint8_t* __restrict f2 = c2.image->flags.data() + r * W;
        double* __restrict u = used[k].data();
        for (std::size_t x = 0; x < W; ++x) u[x] = (f1[x] | f2[x]) == 0 ? 1.0 : 0.0;
        if (!o.normal_map.empty())
            for (std::size_t x = 0; x < W; ++x)
                if (!pixel_used(c1, c2, o, r * W + x)) u[x] = 0.0;
        slot_row[k] = r;
    };
    // Row `add` into the column sums and row `remove` out of them (either H: none).
    auto update = [&](std::size_t add, std::size_t remove) {
        const std::size_t k = add < H ? add % ring : remove % ring;
        const std::size_t q = remove < H ? remove % ring : k;
        update_column_sums(W, x1[k].data(), x2[k].data(), used[k].data(), add < H ? 1.0 : 0.0,
                           x1[q].data(), x2[q].data(), used[q].data(), remove < H ? 1.0 : 0.0,
                           {col[0].data() + R, col[1].data() + R, col[2].data() + R,
                            col[3].data() + R, col[4].data() + R, col[5].data() + R});
    };
    // The column sums of rows [r − R, r + R] ∩ [0, H), from zero.
    auto restart = [&](std::size_t r) {
        for (auto& c : col) std::fill(c.begin(), c.end(), 0.0);
        for (std::size_t q = r >= R ? r - R : 0; q < std::min(H, r + R + 1); ++q) {
            load(q);
            update(q, H);
        }
    };
    const bool labels = !o.region_labels.empty();
    for (std::size_t r = r_begin; r < r_end; ++r) {
        if (r == r_begin || r % kSumRestartRows == 0) {
            restart(r);
        } else {
            // Row r + R comes in (if any), row r − R − 1 leaves (if any).
            const std::size_t add = r + R < H ? r + R : H, remove = r >= R + 1 ? r - R - 1 : H;
            if (add < H) load(add);
            if (add < H || remove < H) update(add, remove);
        }
        const std::size_t k = r % ring;
        // The statistics of pixels [c, c + count) of the row.
        auto statistics = [&](std::size_t c, std::size_t count) {
            pixel_statistics(count, x1[k].data() + c, x2[k].data() + c, used[k].data() + c,
                             {col[0].data() + c, col[1].data() + c, col[2].data() + c,
                              col[3].data() + c, col[4].data() + c, col[5].data() + c},
                             ratio.data(), var.data(), state.data());
        };
        const std::size_t row = r * W;
        if (labels)
            std::copy_n(o.region_labels.begin() + static_cast<std::ptrdiff_t>(row), W,
                        cell_region.begin() + static_cast<std::ptrdiff_t>(row));
        if (ev.fast_flat()) {
            // In chunks of the row, so that the chunk's scratch stays in the first-level cache
            // between the passes (statistics, look-ups, layers); the class sums added in order.
            ClassSums sums;
            for (std::size_t c = 0; c < W; c += kPixelChunk) {
                const std::size_t count = std::min(kPixelChunk, W - c);
                statistics(c, count);
                const ClassSums chunk =
                    ev.evaluate_flat_row(row + c, count, ratio.data(), var.data(), state.data());
                for (std::size_t q = 0; q < 3; ++q) {
                    sums[q].n += chunk[q].n;
                    sums[q].sum += chunk[q].sum;
                    sums[q].sum2 += chunk[q].sum2;
                }
            }
            row_classes[r] = sums;
        } else {
            statistics(0, W);
            clear_rows(map, r, r + 1);
            for (std::size_t x = 0; x < W; ++x) {
                const std::size_t index = row + x;
                const auto st = static_cast<PixelState>(static_cast<int>(state[x]));
                if (st == PixelState::Missing) {
                    ++ev.counts().missing;
                } else if (st == PixelState::NoSolution) {
                    ++ev.counts().no_solution;
                    ++ev.counts().no_solution_other;
                } else if (ev.flat()) {
                    ev.evaluate_flat(index, ratio[x], std::sqrt(var[x]));
                } else {
                    Cell cell;
                    cell.ratio = ratio[x];
                    cell.log_ratio = std::log(ratio[x]);
                    cell.var_log_ratio = var[x];
                    const float* nm = o.normal_map.data() + 3 * index;
                    cell.normal = Eigen::Vector3d(nm[0], nm[1], nm[2]);
                    ev.evaluate(index, cell);
                }
            }
            row_classes[r] = row_class_sums(map, o, r);
        }
    }
}

}  // namespace roughscope::image::detail
