// What the parts of the roughness map share (maps.hpp, docs/maps.md): the small value types of
// its cells and sums, and the row loops of row_kernels.cpp. Private to the maps topic.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <utility>

#include <Eigen/Core>

#include "roughscope/maps/maps.hpp"

namespace roughscope::image::detail {

inline constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
inline constexpr double kLogStep = 1e-5;  // central difference of ln M in ln x

// The per-pixel map's running column sums restart from zero every kSumRestartRows rows, and its
// bands of rows start on such a row: a pixel's sums do not depend on where its band began (the
// map is the same on any number of threads, bit for bit) and the running sums' rounding never
// builds up over more than kSumRestartRows rows.
inline constexpr std::size_t kSumRestartRows = 64;
// The per-pixel map's passes over a row go in chunks of this many pixels.
inline constexpr std::size_t kPixelChunk = 256;

inline bool normal_view(const Geometry& g) { return g.theta_s_rad == 0.0; }

inline std::uint8_t class_code(RoughnessClass c) { return static_cast<std::uint8_t>(c); }

// ln M at ln x and d ln M / d ln x by a central difference.
template <class M>
std::pair<double, double> log_model(M&& model, double lx) {
    const double y = std::log(model(std::exp(lx)));
    const double yp = std::log(model(std::exp(lx + kLogStep)));
    const double ym = std::log(model(std::exp(lx - kLogStep)));
    return {y, (yp - ym) / (2.0 * kLogStep)};
}

// Running mean and variance of a set of values (for the summaries).
struct Accumulator {
    std::size_t n = 0;
    double sum = 0.0, sum2 = 0.0;
    void add(double v) {
        ++n;
        sum += v;
        sum2 += v * v;
    }
    // The mean and its standard error sd/√n; one value, or values without spread, give no
    // standard error: unknown (NaN), not 0.
    std::optional<Estimate> mean() const {
        if (n == 0) return std::nullopt;
        const double m = sum / static_cast<double>(n);
        if (!std::isfinite(m)) return std::nullopt;
        double se = std::numeric_limits<double>::quiet_NaN();
        if (n >= 2) {
            const double var =
                std::max(0.0, (sum2 - static_cast<double>(n) * m * m) / static_cast<double>(n - 1));
            if (var > 0.0 && std::isfinite(var)) se = std::sqrt(var / static_cast<double>(n));
        }
        return Estimate{m, se};
    }
};

// Per class (RoughnessClass order).
using ClassSums = std::array<Accumulator, 3>;

// What one map cell (pixel or tile) needs: ln(E1/E2), its variance and, for a normal map, the
// (mean) normal.
struct Cell {
    double ratio = 1.0;
    double log_ratio = 0.0;
    double var_log_ratio = 0.0;
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
};

// Sums over a tile or neighbourhood.
struct Sums {
    double n = 0, s1 = 0, s2 = 0, s11 = 0, s22 = 0, s12 = 0;
    void add(double x1, double x2) {
        n += 1.0;
        s1 += x1;
        s2 += x2;
        s11 += x1 * x1;
        s22 += x2 * x2;
        s12 += x1 * x2;
    }
    // var(ln m1/m2) · n (the variance of one pixel's ln ratio), with the means.
    bool pixel_log_variance(double& m1, double& m2, double& var) const {
        if (n < 2.0) return false;
        m1 = s1 / n;
        m2 = s2 / n;
        if (!(m1 > 0.0) || !(m2 > 0.0)) return false;
        const double v1 = std::max(0.0, (s11 - n * m1 * m1) / (n - 1.0));
        const double v2 = std::max(0.0, (s22 - n * m2 * m2) / (n - 1.0));
        const double c12 = (s12 - n * m1 * m2) / (n - 1.0);
        var = std::max(0.0, v1 / (m1 * m1) + v2 / (m2 * m2) - 2.0 * c12 / (m1 * m2));
        return true;
    }
};

// What a band of rows counted.
struct Counts {
    std::size_t valid = 0, missing = 0, no_solution = 0, no_solution_other = 0, no_solution_T = 0;
    void add(const Counts& c) {
        valid += c.valid;
        missing += c.missing;
        no_solution += c.no_solution;
        no_solution_other += c.no_solution_other;
        no_solution_T += c.no_solution_T;
    }
};

// What decides a pixel's fate before its look-ups.
enum class PixelState : std::uint8_t { Estimate, Missing, NoSolution };

struct RowCounts {
    std::size_t valid = 0, missing = 0, no_solution = 0, no_solution_other = 0;
    ClassSums classes;  // of the primary σ/T
};

// A flat sample's per-pixel map without σ: the row passes of Evaluator::evaluate_flat_row, which
// make only the layers asked for (every other map evaluates cells one by one into every layer).
inline bool lean_pixel_map(const MapOptions& o) {
    return o.window_px == 1 && o.normal_map.empty() && !o.sigma_um;
}

// ---------------------------------------------------------------------------------------------
// The row loops (row_kernels.cpp): loops without branches over plain arrays that the compiler
// vectorises, each built for several instruction sets and run in the processor's best
// (map_instruction_set); the same arithmetic in every build, so the same map.

// RatioInverseTable::find_ratio_bins's loop over its bins (`bins`, five numbers each, `count`
// of them from the key `key_min`): x and slope at ratio[i], NaN where no bin is used; true when
// a ratio (not NaN) missed the bins.
bool ratio_bins_row(std::size_t n, const double* ratio, const double* bins, std::int64_t key_min,
                    std::int64_t count, int shift, double sign, double inv_anchor, double* x,
                    double* slope);

// out = (p0 + p1 + p2)·scale (p1, p2 null: p0·scale); whether every value is finite.
bool scaled_row_is_finite(std::size_t W, const float* p0, const float* p1, const float* p2,
                          double scale, double* out);

// A row of a flat sample's per-pixel map into its layers (Evaluator::evaluate_flat_row): from
// the pixels' state (as a double, PixelState), ratio, var(ln ratio) and σ/T and slope d(σ/T)/d ln
// ratio of the primary correlation (xo/so: of the other) — all NaN where there is no estimate —
// the layers σ/T, sd(σ/T) = |slope| · sd(ln ratio) (and E1/E2), the class by the primary σ/T
// (`klass`: as a double, a row of scratch) and its sums. The other correlation's layers are
// written where FlatRowOut::o is not null, E1/E2 where FlatRowOut::ratio is not.
struct FlatRowIn {
    const double *ratio, *var, *state, *xp, *sp, *xo, *so;
    double slightly, very;
};
struct FlatRowOut {
    float *ratio, *p, *pse, *o, *ose;
    double* klass;
    std::uint8_t* cls;
};
RowCounts write_flat_row(std::size_t n, const FlatRowIn& in, const FlatRowOut& out);

// The per-pixel map's column sums (n, Σx1, Σx2, Σx1², Σx2², Σx1x2 over rows [r − R, r + R]) +=
// row (a, b, weights u) · add_weight − row (ra, rb, ru) · remove_weight, in one pass.
struct ColumnSums {
    double *n, *s1, *s2, *s11, *s22, *s12;
};
void update_column_sums(std::size_t W, const double* a, const double* b, const double* u,
                        double add_weight, const double* ra, const double* rb, const double* ru,
                        double remove_weight, const ColumnSums& sums);

// The window's sums at each pixel of a row (2R + 1 column sums from the padded column sums
// `cols`), then the pixel's ratio x1/x2, var(ln x1/x2) of one pixel and its state (PixelState).
struct ConstColumnSums {
    const double *n, *s1, *s2, *s11, *s22, *s12;
};
void pixel_statistics(std::size_t W, const double* a, const double* b, const double* u,
                      const ConstColumnSums& cols, double* ratio, double* var, double* state);

}  // namespace roughscope::image::detail
