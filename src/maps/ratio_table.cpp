// The tabulated inverse of a brightness-ratio model (maps.hpp RatioInverseTable, docs/maps.md
// "σ/T: Eq. 17 and 19, through a table"): the nodes, the look-up's bucket index and the ratio
// bins of find_ratio. The forward ratios are estimation.hpp's.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "maps/map_internal.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/estimation/estimation.hpp"
#include "roughscope/maps/maps.hpp"

namespace roughscope::image {

using detail::log_model;
using detail::normal_view;

namespace {

void check_table_options(const RatioInverseTableOptions& t) {
    check::positive("table lower", t.lower);
    check::positive("table upper", t.upper);
    if (!(t.upper > t.lower))
        throw InvalidArgument(concat("table: upper = ", check::format_number(t.upper),
                                     " must exceed lower = ", check::format_number(t.lower)));
    if (t.nodes < 3 || t.nodes > 10'000'000)
        throw InvalidArgument(
            concat("table: nodes = ", std::to_string(t.nodes), " must be in [3, 10000000]"));
}

// Fills (y, x, dx/dy) from forward(ln x) → (y, dy/d ln x), keeping the longest run of nodes with
// a finite y and a non-zero slope of one sign, stored with y increasing.
template <class F>
void fill_table(F&& forward, const RatioInverseTableOptions& t, std::vector<double>& ys,
                std::vector<double>& xs, std::vector<double>& dxdy) {
    check_table_options(t);
    const double l0 = std::log(t.lower), l1 = std::log(t.upper);
    const double h = (l1 - l0) / static_cast<double>(t.nodes - 1);
    std::vector<double> y(t.nodes), x(t.nodes), d(t.nodes);
    std::vector<int> sign(t.nodes);
    for (std::size_t j = 0; j < t.nodes; ++j) {
        const double lx = j + 1 == t.nodes ? l1 : l0 + h * static_cast<double>(j);
        const auto [yj, dyj] = forward(lx);
        x[j] = std::exp(lx);
        y[j] = yj;
        d[j] = dyj;
        sign[j] =
            (std::isfinite(yj) && std::isfinite(dyj) && dyj != 0.0) ? (dyj > 0.0 ? 1 : -1) : 0;
    }
    // The longest run of one sign whose y is strictly monotone.
    std::size_t best_begin = 0, best_len = 0;
    for (std::size_t j = 0; j < t.nodes;) {
        if (sign[j] == 0) {
            ++j;
            continue;
        }
        std::size_t k = j + 1;
        while (k < t.nodes && sign[k] == sign[j] &&
               (sign[j] > 0 ? y[k] > y[k - 1] : y[k] < y[k - 1]))
            ++k;
        if (k - j > best_len) {
            best_begin = j;
            best_len = k - j;
        }
        j = k;
    }
    if (best_len < 3)
        throw NoSolution(
            "table: the model ratio is not monotone in the unknown over the table's "
            "range");
    ys.assign(y.begin() + static_cast<std::ptrdiff_t>(best_begin),
              y.begin() + static_cast<std::ptrdiff_t>(best_begin + best_len));
    xs.assign(x.begin() + static_cast<std::ptrdiff_t>(best_begin),
              x.begin() + static_cast<std::ptrdiff_t>(best_begin + best_len));
    dxdy.resize(best_len);
    // dx/dy = x / (dy/d ln x).
    for (std::size_t j = 0; j < best_len; ++j) dxdy[j] = xs[j] / d[best_begin + j];
    if (ys.front() > ys.back()) {
        std::reverse(ys.begin(), ys.end());
        std::reverse(xs.begin(), xs.end());
        std::reverse(dxdy.begin(), dxdy.end());
    }
}

}  // namespace

RatioInverseTable RatioInverseTable::sigma_over_T(const Geometry& geom1, const Geometry& geom2,
                                                  Correlation correlation,
                                                  const TwoGeometryOptions& model,
                                                  const RatioInverseTableOptions& table) {
    check::geometry(geom1, "geom1");
    check::geometry(geom2, "geom2");
    RatioInverseTable out;
    const auto ratio = [&](double s) {
        return model_ratio_very_rough(geom1, geom2, s, correlation, model);
    };
    if (normal_view(geom1) && normal_view(geom2)) {
        // Eq. 16 / 18: ln(E1/E2) = ln of the very-rough model ratio (estimation.hpp) and its
        // slope dy/d ln x = x / (dx/dy) from the derivative of Eq. 17 / 19 at that ratio
        // (ratio_range_gaussian validates the two angles).
        const double t1 = geom1.theta_i_rad, t2 = geom2.theta_i_rad;
        (void)ratio_range_gaussian(t1, t2, model.factor);
        fill_table(
            [&](double lx) {
                const double x = std::exp(lx), r = ratio(x);
                double slope = std::numeric_limits<double>::quiet_NaN();
                try {
                    slope = x / d_sigma_over_T_d_log_ratio(correlation, r, t1, t2, model.factor);
                } catch (const Error&) {
                    // A ratio beyond double's range or the closed form's: not a node.
                }
                return std::pair{std::log(r), slope};
            },
            table, out.y_, out.x_, out.dxdy_);
        out.build_coefficients();
        return out;
    }
    // Any other pair of geometries: the very-rough model ratio of the two-geometry solver.
    (void)ratio(1.0);  // validates
    fill_table([&](double lx) { return log_model(ratio, lx); }, table, out.y_, out.x_, out.dxdy_);
    out.build_coefficients();
    return out;
}

RatioInverseTable RatioInverseTable::correlation_length(const Geometry& geom1,
                                                        const Geometry& geom2, double sigma_um,
                                                        Correlation correlation,
                                                        const TwoGeometryOptions& model,
                                                        const RatioInverseTableOptions& table) {
    check::geometry(geom1, "geom1");
    check::geometry(geom2, "geom2");
    check::positive("sigma_um", sigma_um, " µm");
    RatioInverseTable out;
    fill_table(
        [&](double lx) {
            return log_model(
                [&](double T) {
                    try {
                        return model_ratio_diffuse(geom1, geom2, sigma_um, T, correlation, model);
                    } catch (const Error&) {
                        return std::numeric_limits<double>::quiet_NaN();
                    }
                },
                lx);
        },
        table, out.y_, out.x_, out.dxdy_);
    out.build_coefficients();
    return out;
}

std::optional<RatioInverseTable::Value> RatioInverseTable::lookup(double log_ratio,
                                                                  std::size_t& hint) const {
    Value v;
    if (!find(log_ratio, v, hint)) return std::nullopt;
    return v;
}

std::size_t RatioInverseTable::max_intervals_per_bucket() const {
    std::size_t worst = 0;
    for (std::size_t b = 0; b + 1 < bucket_first_interval_.size(); ++b)
        worst = std::max<std::size_t>(
            worst, bucket_first_interval_[b + 1] - bucket_first_interval_[b] + 1);
    return worst;
}

void RatioInverseTable::build_coefficients() {
    const std::size_t n = y_.size(), intervals = n - 1;
    // The bucket index: 4 buckets per interval, uniform in bucket_key (logarithmic towards both
    // ends of the table, where the nodes crowd: y − y_0 ∝ (σ/T)^−2 at large σ/T, Eq. 16).
    key_floor_front_ = 0.5 * (y_[1] - y_[0]);
    key_floor_back_ = 0.5 * (y_[n - 1] - y_[n - 2]);
    key_min_ = bucket_key(y_.front());
    const std::int64_t key_max = bucket_key(y_.back());
    const std::size_t buckets = 4 * intervals;
    bucket_scale_ = static_cast<double>(buckets) / static_cast<double>(key_max - key_min_);
    // bucket_first_interval_[b]: the interval holding the smallest y of bucket b — the one that
    // starts at the last node of a lower bucket (bucket_of is monotone in y); [b + 1] bounds
    // bucket b's largest.
    bucket_first_interval_.assign(buckets + 1, 0);
    std::vector<std::size_t> below(buckets + 1, 0);  // nodes in buckets < b
    for (std::size_t j = 0; j < n; ++j) ++below[bucket_of(y_[j]) + 1];
    for (std::size_t b = 1; b <= buckets; ++b) below[b] += below[b - 1];
    for (std::size_t b = 0; b <= buckets; ++b)
        bucket_first_interval_[b] = static_cast<std::uint32_t>(
            std::min(intervals - 1, below[b] > 0 ? below[b] - 1 : std::size_t{0}));
    coefficients_.resize(intervals);
    for (std::size_t j = 0; j + 1 < y_.size(); ++j) {
        const double dy = y_[j + 1] - y_[j];
        const double x0 = x_[j], x1 = x_[j + 1], d0 = dxdy_[j] * dy, d1 = dxdy_[j + 1] * dy;
        coefficients_[j] = {x0, d0, 3.0 * (x1 - x0) - 2.0 * d0 - d1, 2.0 * (x0 - x1) + d0 + d1,
                            1.0 / dy};
    }
    build_ratio_bins();
}

void RatioInverseTable::build_ratio_bins() {
    // The anchor: the table's end of larger x.
    const bool front = x_.front() >= x_.back();
    anchor_sign_ = front ? 1.0 : -1.0;
    anchor_log_ratio_ = front ? y_.front() : y_.back();
    inv_anchor_ratio_ = std::exp(-anchor_log_ratio_);
    constexpr int kLowestOctave = -48, kOctaves = 128;
    ratio_bin_key_min_ =
        std::bit_cast<std::uint64_t>(std::ldexp(1.0, kLowestOctave)) >> kRatioBinShift;
    const std::size_t bins = std::size_t{kOctaves} << (52 - kRatioBinShift);
    ratio_bins_.assign(5 * bins, 0.0);
    // x and dx/du at u (find at ln ratio = y_a + ln(1 + s u); d ln ratio/du = 1/(s + u)), and
    // how far x is uncertain from the rounding of ln ratio alone (a few ulp of it, through the
    // slope): near the anchor x is ill-conditioned in ln ratio, whatever the method.
    auto at = [&](double u, double& x, double& dx_du, double& conditioning) {
        Value v;
        std::size_t hint = 0;
        const double lr = anchor_log_ratio_ + std::log1p(anchor_sign_ * u);
        if (!find(lr, v, hint)) return false;
        x = v.x;
        dx_du = v.dx_dlog_ratio / (anchor_sign_ + u);
        conditioning = 4.0 * std::numeric_limits<double>::epsilon() * (1.0 + std::abs(lr)) *
                       std::abs(v.dx_dlog_ratio);
        return std::isfinite(x) && std::isfinite(dx_du);
    };
    for (std::size_t i = 0; i < bins; ++i) {
        const std::uint64_t key = ratio_bin_key_min_ + i;
        const double u0 = std::bit_cast<double>(key << kRatioBinShift);
        const double u1 = std::bit_cast<double>((key + 1) << kRatioBinShift);
        const double um = std::bit_cast<double>((key << kRatioBinShift) |
                                                (std::uint64_t{1} << (kRatioBinShift - 1)));
        const double du = u1 - u0;
        double x0 = 0, x1 = 0, xm = 0, s0 = 0, s1 = 0, sm = 0, unused = 0, conditioning = 0;
        if (!at(u0, x0, s0, unused) || !at(u1, x1, s1, unused) || !at(um, xm, sm, conditioning))
            continue;
        const double d0 = s0 * du, d1 = s1 * du;
        const std::array<double, 5> c{x0, d0, 3.0 * (x1 - x0) - 2.0 * d0 - d1,
                                      2.0 * (x0 - x1) + d0 + d1, 1.0 / du};
        const double t = 0.5;
        const double x = c[0] + t * (c[1] + t * (c[2] + t * c[3]));
        const double slope = (c[1] + t * (2.0 * c[2] + t * 3.0 * c[3])) * c[4];
        if (!(x > 0.0) || !(std::abs(x - xm) <= kRatioBinTolerance * xm + conditioning) ||
            !(std::abs(slope - sm) <= kRatioBinSlopeTolerance * std::abs(sm)))
            continue;
        std::copy(c.begin(), c.end(), ratio_bins_.begin() + static_cast<std::ptrdiff_t>(5 * i));
    }
}

bool RatioInverseTable::find_ratio_bins(std::size_t n, const double* ratio, double* x,
                                        double* dx_dlog_ratio) const {
    return detail::ratio_bins_row(n, ratio, ratio_bins_.data(),
                                  static_cast<std::int64_t>(ratio_bin_key_min_),
                                  static_cast<std::int64_t>(ratio_bins_.size() / 5), kRatioBinShift,
                                  anchor_sign_, inv_anchor_ratio_, x, dx_dlog_ratio);
}

std::size_t RatioInverseTable::ratio_bins_used() const {
    std::size_t used = 0;
    for (std::size_t i = 0; i < ratio_bins_.size(); i += 5) used += ratio_bins_[i] > 0.0 ? 1 : 0;
    return used;
}

RatioRange RatioInverseTable::ratio_range() const {
    return RatioRange{std::exp(y_.front()), std::exp(y_.back())};
}

}  // namespace roughscope::image
