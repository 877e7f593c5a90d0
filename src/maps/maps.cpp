// Roughness maps: two photographs → σ/T per pixel or tile (image/maps.hpp, docs/maps.md).
#include "roughscope/maps/maps.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <exception>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <utility>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/memory.hpp"
#include "roughscope/core/text.hpp"

namespace roughscope::image {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr std::size_t kMaxWindowPx = 4096;
constexpr double kLogStep = 1e-5;  // central difference of ln M in ln x

// g = σ² v_z² = (2πσ/λ)² (cos θi + cos θs)² (§3.1).
double roughness_g(double sigma_um, const Geometry& geom, double wavelength_um) {
    const double vz =
        2.0 * kPi / wavelength_um * (std::cos(geom.theta_i_rad) + std::cos(geom.theta_s_rad));
    return sigma_um * sigma_um * vz * vz;
}

bool normal_view(const Geometry& g) { return g.theta_s_rad == 0.0; }

std::uint8_t class_code(RoughnessClass c) { return static_cast<std::uint8_t>(c); }

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

struct RegionAccumulator {
    Accumulator gaussian, exponential, T;
    Accumulator log_ratio;  // ln(E1/E2) of the region's tiles/pixels
    std::size_t missing = 0;
    std::array<std::size_t, 3> classes{};
};

}  // namespace

// ---------------------------------------------------------------------------------------------
// Classes

RoughnessClass roughness_class_of_sigma_over_T(double sigma_over_T, double slightly_rough_max,
                                               double very_rough_min) {
    if (sigma_over_T < slightly_rough_max) return RoughnessClass::SlightlyRough;
    if (sigma_over_T > very_rough_min) return RoughnessClass::VeryRough;
    return RoughnessClass::ModeratelyRough;
}

// ---------------------------------------------------------------------------------------------
// RatioInverseTable

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

// d ln M / d ln x by a central difference.
template <class M>
std::pair<double, double> log_model(M&& model, double lx) {
    const double y = std::log(model(std::exp(lx)));
    const double yp = std::log(model(std::exp(lx + kLogStep)));
    const double ym = std::log(model(std::exp(lx - kLogStep)));
    return {y, (yp - ym) / (2.0 * kLogStep)};
}

}  // namespace

RatioInverseTable RatioInverseTable::sigma_over_T(const Geometry& geom1, const Geometry& geom2,
                                                  Correlation correlation,
                                                  const TwoGeometryOptions& model,
                                                  const RatioInverseTableOptions& table) {
    check::geometry(geom1, "geom1");
    check::geometry(geom2, "geom2");
    RatioInverseTable out;
    if (normal_view(geom1) && normal_view(geom2)) {
        // Eq. 16 / 18 with a = v_xy²/v_z² = tan²(θi/2) at normal view and C the ratio's finite
        // bound (ratio_range_gaussian validates the two angles).
        const double t1 = geom1.theta_i_rad, t2 = geom2.theta_i_rad;
        const RatioRange range = ratio_range_gaussian(t1, t2, model.factor);
        const double C = t1 < t2 ? range.lower : range.upper;
        const double lnC = std::log(C);
        const double a1 = std::pow(std::tan(t1 / 2.0), 2), a2 = std::pow(std::tan(t2 / 2.0), 2);
        if (correlation == Correlation::Gaussian) {
            // Eq. 16: ln(E1/E2) = ln C + (a2 − a1)/(4 (σ/T)²).
            fill_table(
                [&](double lx) {
                    const double s2 = std::exp(2.0 * lx);
                    return std::pair{lnC + (a2 - a1) / (4.0 * s2), -(a2 - a1) / (2.0 * s2)};
                },
                table, out.y_, out.x_, out.dxdy_);
        } else {
            // Eq. 18: ln(E1/E2) = ln C + (3/2) ln[(1 + a2/(σ/T)²)/(1 + a1/(σ/T)²)].
            fill_table(
                [&](double lx) {
                    const double s2 = std::exp(2.0 * lx);
                    return std::pair{lnC + 1.5 * (std::log1p(a2 / s2) - std::log1p(a1 / s2)),
                                     -3.0 * (a2 / (s2 + a2) - a1 / (s2 + a1))};
                },
                table, out.y_, out.x_, out.dxdy_);
        }
        out.build_coefficients();
        return out;
    }
    // Any other pair of geometries: the very-rough model ratio of the two-geometry solver.
    (void)model_ratio_very_rough(geom1, geom2, 1.0, correlation, model);  // validates
    fill_table(
        [&](double lx) {
            return log_model(
                [&](double s) {
                    return model_ratio_very_rough(geom1, geom2, s, correlation, model);
                },
                lx);
        },
        table, out.y_, out.x_, out.dxdy_);
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

namespace {

// The row loops' builds (the AVX-512 ones: target "avx512f,avx512dq,avx512vl,avx512bw"): the
// processor's best instruction set up to the limit (limit_map_instruction_set).
std::atomic<MapInstructionSet> isa_limit{MapInstructionSet::Avx512};
MapInstructionSet processor_isa() {
    static const MapInstructionSet best = [] {
        if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
            __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512bw"))
            return MapInstructionSet::Avx512;
        if (__builtin_cpu_supports("avx2")) return MapInstructionSet::Avx2;
        return MapInstructionSet::Baseline;
    }();
    return best;
}
MapInstructionSet active_isa() {
    return std::min(processor_isa(), isa_limit.load(std::memory_order_relaxed));
}

// The loop of find_ratio_bins (find_ratio's bin arithmetic, the bin's position t from the
// mantissa's low bits as a double in [1, 2) minus 1 — exact, and without a 64-bit integer
// conversion SSE2 lacks), inlined into a default and an AVX2 build of it.
[[gnu::always_inline]] inline void ratio_bins_loop(std::size_t n, const double* __restrict ratio,
                                                   const double* __restrict bins,
                                                   std::int64_t key_min, std::int64_t count,
                                                   int shift, double sign, double inv_anchor,
                                                   double* __restrict x, double* __restrict slope,
                                                   std::uint64_t& pending) {
    const std::uint64_t mantissa = (std::uint64_t{1} << shift) - 1;
    const std::uint64_t one = std::bit_cast<std::uint64_t>(1.0);
    const int up = 52 - shift;
    const std::uint64_t quiet_nan =
        std::bit_cast<std::uint64_t>(std::numeric_limits<double>::quiet_NaN());
    std::uint64_t left = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const double u = sign * (ratio[i] * inv_anchor - 1.0);
        const auto bits = std::bit_cast<std::uint64_t>(u);
        const std::int64_t bin = static_cast<std::int64_t>(bits >> shift) - key_min;
        const bool inside = static_cast<std::uint64_t>(bin) < static_cast<std::uint64_t>(count);
        const std::int64_t k = 5 * (bin & -static_cast<std::int64_t>(inside));  // bin 0 outside
        const double c0 = bins[k], c1 = bins[k + 1], c2 = bins[k + 2], c3 = bins[k + 3];
        const double t = std::bit_cast<double>(((bits & mantissa) << up) | one) - 1.0;
        const double value = c0 + t * (c1 + t * (c2 + t * c3));
        // 1/(bin width) = 2^(shift − 52) / 2^(exponent of u): from the exponent's bits (one
        // gather fewer than reading the bin's c4, the same power of 2).
        const double inv_width = std::bit_cast<double>(
            (std::uint64_t{2046 + 52 - static_cast<std::uint64_t>(shift)} - ((bits >> 52) & 0x7ff))
            << 52);
        const double d = (c1 + t * (2.0 * c2 + t * 3.0 * c3)) * inv_width * (sign + u);
        // Both NaN where the bin is not used: the quiet-NaN bits ORed in (no branch for the
        // vectoriser).
        const std::uint64_t unused =
            (std::uint64_t{0} - static_cast<std::uint64_t>(!(inside & (c0 > 0.0)))) & quiet_nan;
        x[i] = std::bit_cast<double>(std::bit_cast<std::uint64_t>(value) | unused);
        slope[i] = std::bit_cast<double>(std::bit_cast<std::uint64_t>(d) | unused);
        // A ratio (not NaN) outside the used bins: for find.
        left |= unused & (std::uint64_t{0} - static_cast<std::uint64_t>(ratio[i] == ratio[i]));
    }
    pending = left;
}

[[gnu::target("avx2")]] bool ratio_bins_avx2(std::size_t n, const double* ratio, const double* bins,
                                             std::int64_t key_min, std::int64_t count, int shift,
                                             double sign, double inv_anchor, double* x,
                                             double* slope) {
    std::uint64_t pending = 0;
    ratio_bins_loop(n, ratio, bins, key_min, count, shift, sign, inv_anchor, x, slope, pending);
    return pending != 0;
}
[[gnu::target("avx512f,avx512dq,avx512vl,avx512bw")]] bool ratio_bins_avx512(
    std::size_t n, const double* ratio, const double* bins, std::int64_t key_min,
    std::int64_t count, int shift, double sign, double inv_anchor, double* x, double* slope) {
    std::uint64_t pending = 0;
    ratio_bins_loop(n, ratio, bins, key_min, count, shift, sign, inv_anchor, x, slope, pending);
    return pending != 0;
}

bool ratio_bins_default(std::size_t n, const double* ratio, const double* bins,
                        std::int64_t key_min, std::int64_t count, int shift, double sign,
                        double inv_anchor, double* x, double* slope) {
    std::uint64_t pending = 0;
    ratio_bins_loop(n, ratio, bins, key_min, count, shift, sign, inv_anchor, x, slope, pending);
    return pending != 0;
}

}  // namespace

MapInstructionSet limit_map_instruction_set(MapInstructionSet highest) {
    return isa_limit.exchange(highest, std::memory_order_relaxed);
}
MapInstructionSet map_instruction_set() { return active_isa(); }

bool RatioInverseTable::find_ratio_bins(std::size_t n, const double* ratio, double* x,
                                        double* dx_dlog_ratio) const {
    const MapInstructionSet isa = active_isa();
    auto* run = isa == MapInstructionSet::Avx512 ? ratio_bins_avx512
                : isa == MapInstructionSet::Avx2 ? ratio_bins_avx2
                                                 : ratio_bins_default;
    return run(n, ratio, ratio_bins_.data(), static_cast<std::int64_t>(ratio_bin_key_min_),
               static_cast<std::int64_t>(ratio_bins_.size() / 5), kRatioBinShift, anchor_sign_,
               inv_anchor_ratio_, x, dx_dlog_ratio);
}

std::size_t RatioInverseTable::ratio_bins_used() const {
    std::size_t used = 0;
    for (std::size_t i = 0; i < ratio_bins_.size(); i += 5) used += ratio_bins_[i] > 0.0 ? 1 : 0;
    return used;
}

RatioRange RatioInverseTable::ratio_range() const {
    return RatioRange{std::exp(y_.front()), std::exp(y_.back())};
}

// ---------------------------------------------------------------------------------------------
// roughness_map

namespace {

std::string capture_name(const MapCapture& c, std::size_t k) {
    if (!c.name.empty()) return c.name;
    if (c.image != nullptr && !c.image->info.source.empty()) return c.image->info.source;
    return concat("captures[", std::to_string(k), "]");
}

void check_map_input(const std::vector<MapCapture>& captures, const MapOptions& o) {
    if (captures.size() < 2)
        throw InvalidArgument(concat("roughness map: ", std::to_string(captures.size()),
                                     " capture(s) given; a map needs at least 2 (two light "
                                     "directions)"));
    for (std::size_t k = 0; k < captures.size(); ++k) {
        const MapCapture& c = captures[k];
        const std::string name = concat("roughness map: captures[", std::to_string(k), "]");
        if (c.image == nullptr) throw InvalidArgument(concat(name, ": no image"));
        // The values are checked where they are read (load_row): one pass over the images less.
        check_linear_image_layout(*c.image);
        check::positive(concat(name, ": exposure_scale"), c.exposure_scale);
        const LinearImage& first = *captures[0].image;
        if (c.image->width != first.width || c.image->height != first.height)
            throw InvalidArgument(concat(
                "roughness map: ", capture_name(c, k), " is ", std::to_string(c.image->width),
                " x ", std::to_string(c.image->height), " but ", capture_name(captures[0], 0),
                " is ", std::to_string(first.width), " x ", std::to_string(first.height),
                ": every capture must have the same size"));
        if (o.normal_map.empty()) {
            check::geometry(c.geometry, name);
        } else {
            if (!c.light || !c.view)
                throw InvalidArgument(concat(name,
                                             ": a normal map needs the light and view "
                                             "directions of every capture"));
            for (const auto* v : {&*c.light, &*c.view})
                if (!v->allFinite() || std::abs(v->norm() - 1.0) > 1e-6)
                    throw InvalidArgument(
                        concat(name, ": light and view must be finite unit vectors"));
        }
    }
    if (o.window_px < 1 || o.window_px > kMaxWindowPx)
        throw InvalidArgument(concat("roughness map: window_px = ", std::to_string(o.window_px),
                                     " must be in [1, ", std::to_string(kMaxWindowPx), "]"));
    if (!(o.min_used_fraction > 0.0 && o.min_used_fraction <= 1.0))
        throw InvalidArgument(
            concat("roughness map: min_used_fraction = ", check::format_number(o.min_used_fraction),
                   " must be in (0, 1]"));
    check::positive("roughness map: wavelength_um", o.wavelength_um, " µm");
    if (o.sigma_um) check::positive("roughness map: sigma_um", *o.sigma_um, " µm");
    check::non_negative("roughness map: sigma_um_stderr", o.sigma_um_stderr, " µm");
    check::non_negative("roughness map: max_shift_px", o.max_shift_px, " px");
    check::non_negative("roughness map: min_peak_to_sidelobe", o.min_peak_to_sidelobe);
    check::positive("roughness map: slightly_rough_max_sigma_over_T",
                    o.slightly_rough_max_sigma_over_T);
    if (!(o.very_rough_min_sigma_over_T >= o.slightly_rough_max_sigma_over_T) ||
        !std::isfinite(o.very_rough_min_sigma_over_T))
        throw InvalidArgument(concat("roughness map: very_rough_min_sigma_over_T = ",
                                     check::format_number(o.very_rough_min_sigma_over_T),
                                     " must be finite and at least slightly_rough_max_sigma_over_T"
                                     " = ",
                                     check::format_number(o.slightly_rough_max_sigma_over_T)));
    const std::size_t pixels = captures[0].image->pixel_count();
    if (!o.normal_map.empty() && o.normal_map.size() != 3 * pixels)
        throw InvalidArgument(concat("roughness map: the normal map has ",
                                     std::to_string(o.normal_map.size()),
                                     " values; it needs 3 per "
                                     "pixel (",
                                     std::to_string(3 * pixels), ")"));
    if (!o.region_labels.empty()) {
        if (o.region_labels.size() != pixels)
            throw InvalidArgument(concat(
                "roughness map: the region labels have ", std::to_string(o.region_labels.size()),
                " values; they need one per pixel (", std::to_string(pixels), ")"));
        const auto n = static_cast<std::int32_t>(o.region_names.size());
        for (std::size_t i = 0; i < pixels; ++i)
            if (o.region_labels[i] < -1 || o.region_labels[i] >= n)
                throw InvalidArgument(concat("roughness map: region label ",
                                             std::to_string(o.region_labels[i]), " at pixel ",
                                             std::to_string(i), " must be −1 (none) or in [0, ",
                                             std::to_string(n), ") (one name per region)"));
    }
}

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

// out = (p0 + p1 + p2)·scale (p1, p2 null: p0·scale); whether every value is finite — the sum of
// finite floats in double is finite, and v − v is +0 for a finite v and NaN otherwise (an
// integer OR of its bits, so that the compiler vectorises the loop).
[[gnu::always_inline]] inline bool scaled_row_is_finite_body(std::size_t W,
                                                             const float* __restrict p0,
                                                             const float* __restrict p1,
                                                             const float* __restrict p2,
                                                             double scale, double* __restrict out) {
    std::uint64_t not_finite = 0;
    if (p1 == nullptr) {
        for (std::size_t x = 0; x < W; ++x) {
            const double v = static_cast<double>(p0[x]) * scale;
            out[x] = v;
            not_finite |= std::bit_cast<std::uint64_t>(v - v);
        }
    } else {
        for (std::size_t x = 0; x < W; ++x) {
            const double v = (static_cast<double>(p0[x]) + p1[x] + p2[x]) * scale;
            out[x] = v;
            not_finite |= std::bit_cast<std::uint64_t>(v - v);
        }
    }
    return not_finite == 0;
}
[[gnu::target("avx512f,avx512dq,avx512vl,avx512bw")]] bool scaled_row_is_finite_avx512(
    std::size_t W, const float* p0, const float* p1, const float* p2, double scale, double* out) {
    return scaled_row_is_finite_body(W, p0, p1, p2, scale, out);
}
bool scaled_row_is_finite(std::size_t W, const float* p0, const float* p1, const float* p2,
                          double scale, double* out) {
    if (active_isa() == MapInstructionSet::Avx512)
        return scaled_row_is_finite_avx512(W, p0, p1, p2, scale, out);
    return scaled_row_is_finite_body(W, p0, p1, p2, scale, out);
}

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

// v, or NaN where the mask is all ones (bit operations: a select without a branch).
inline double nan_where(double v, std::uint64_t mask) {
    constexpr auto kNaNBits =
        std::bit_cast<std::uint64_t>(std::numeric_limits<double>::quiet_NaN());
    return std::bit_cast<double>((std::bit_cast<std::uint64_t>(v) & ~mask) | (mask & kNaNBits));
}
// All ones where `condition`, else 0.
inline std::uint64_t mask_of(bool condition) {
    return std::uint64_t{0} - static_cast<std::uint64_t>(condition);
}

// A row of a flat sample's per-pixel map into its layers, every cell written once: from the
// pixels' state (as a double, PixelState), ratio, var(ln ratio) and σ/T and slope d(σ/T)/d ln
// ratio of the primary correlation (MapOptions::correlation; xo/so: of the other, kOther) — all
// NaN where there is no estimate (state ≠ 0, or a ratio the table does not invert), so the
// layers are their conversions: σ/T, sd(σ/T) = |slope| · sd(ln ratio) (and E1/E2, kRatio). The
// class by the primary σ/T (`klass`: the class as a double, a row of scratch, narrowed to the
// class layer after) and its sums. In 64-bit masks, without branches, so that the compiler
// vectorises the loop.
struct FlatRowIn {
    const double *ratio, *var, *state, *xp, *sp, *xo, *so;
    double slightly, very;
};
struct FlatRowOut {
    float *ratio, *p, *pse, *o, *ose;
    double* klass;
    std::uint8_t* cls;
};
template <bool kOther, bool kRatio>
[[gnu::always_inline]] inline RowCounts write_flat_row_body(
    std::size_t n, const double* __restrict ratio, const double* __restrict var,
    const double* __restrict state, const double* __restrict xp, const double* __restrict sp,
    const double* __restrict xo, const double* __restrict so, double slightly, double very,
    float* __restrict e12, float* __restrict lp, float* __restrict lpse, float* __restrict lo,
    float* __restrict lose, double* __restrict klass, std::uint8_t* __restrict cls) {
    std::uint64_t valid = 0, valid_other = 0, missing = 0, n0 = 0, n1 = 0, n2 = 0;
    double s0 = 0, s1 = 0, s2 = 0, q0 = 0, q1 = 0, q2 = 0;
    // (The class sums in lanes: their order of addition is the build's, not the threads'.)
#pragma omp simd reduction(+ : valid, valid_other, missing, n0, n1, n2, s0, s1, s2, q0, q1, q2)
    for (std::size_t i = 0; i < n; ++i) {
        const double p = xp[i], sd = std::sqrt(var[i]);
        if constexpr (kRatio) e12[i] = static_cast<float>(ratio[i]);
        lp[i] = static_cast<float>(p);
        lpse[i] = static_cast<float>(std::abs(sp[i]) * sd);
        if constexpr (kOther) {
            lo[i] = static_cast<float>(xo[i]);
            lose[i] = static_cast<float>(std::abs(so[i]) * sd);
            valid_other += xo[i] == xo[i] ? 1 : 0;
        }
        const std::uint64_t none = mask_of(p != p);
        const std::uint64_t m0 = mask_of(p < slightly), m2 = mask_of(p > very);
        const std::uint64_t m1 = ~none & ~m0 & ~m2;
        klass[i] = std::bit_cast<double>((std::bit_cast<std::uint64_t>(1.0) & m1) |
                                         (std::bit_cast<std::uint64_t>(2.0) & m2) |
                                         (std::bit_cast<std::uint64_t>(255.0) & none));
        valid += 1 & ~none;
        missing += state[i] == 1.0 ? 1 : 0;
        // The layer's value (a float), as row_class_sums reads it.
        const auto bits = std::bit_cast<std::uint64_t>(static_cast<double>(static_cast<float>(p)));
        const double v0 = std::bit_cast<double>(bits & m0), v1 = std::bit_cast<double>(bits & m1),
                     v2 = std::bit_cast<double>(bits & m2);
        n0 += 1 & m0;
        n1 += 1 & m1;
        n2 += 1 & m2;
        s0 += v0;
        s1 += v1;
        s2 += v2;
        q0 += v0 * v0;
        q1 += v1 * v1;
        q2 += v2 * v2;
    }
    for (std::size_t i = 0; i < n; ++i) cls[i] = static_cast<std::uint8_t>(klass[i]);
    // Every pixel is an estimate, missing, or without a solution (the other correlation's
    // count: kOther only).
    RowCounts counts{
        valid, missing, n - valid - missing, kOther ? n - valid_other - missing : 0, {}};
    counts.classes[0] = {n0, s0, q0};
    counts.classes[1] = {n1, s1, q1};
    counts.classes[2] = {n2, s2, q2};
    return counts;
}

template <bool kOther, bool kRatio>
RowCounts write_flat_row_baseline(std::size_t n, const FlatRowIn& in, const FlatRowOut& out) {
    return write_flat_row_body<kOther, kRatio>(n, in.ratio, in.var, in.state, in.xp, in.sp, in.xo,
                                               in.so, in.slightly, in.very, out.ratio, out.p,
                                               out.pse, out.o, out.ose, out.klass, out.cls);
}
// write_flat_row_body built for AVX-512, AVX2 and the baseline (SSE2, where its 64-bit masks do
// not vectorise), the processor's pick at run time: the same arithmetic (no FMA contraction:
// -ffp-contract=off), so the same layers from each.
template <bool kOther, bool kRatio>
[[gnu::target("avx2")]] RowCounts write_flat_row_avx2(std::size_t n, const FlatRowIn& in,
                                                      const FlatRowOut& out) {
    return write_flat_row_body<kOther, kRatio>(n, in.ratio, in.var, in.state, in.xp, in.sp, in.xo,
                                               in.so, in.slightly, in.very, out.ratio, out.p,
                                               out.pse, out.o, out.ose, out.klass, out.cls);
}
template <bool kOther, bool kRatio>
[[gnu::target("avx512f,avx512dq,avx512vl,avx512bw")]] RowCounts write_flat_row_avx512(
    std::size_t n, const FlatRowIn& in, const FlatRowOut& out) {
    return write_flat_row_body<kOther, kRatio>(n, in.ratio, in.var, in.state, in.xp, in.sp, in.xo,
                                               in.so, in.slightly, in.very, out.ratio, out.p,
                                               out.pse, out.o, out.ose, out.klass, out.cls);
}
template <bool kOther, bool kRatio>
RowCounts write_flat_row_of(MapInstructionSet isa, std::size_t n, const FlatRowIn& in,
                            const FlatRowOut& out) {
    switch (isa) {
        case MapInstructionSet::Avx512:
            return write_flat_row_avx512<kOther, kRatio>(n, in, out);
        case MapInstructionSet::Avx2:
            return write_flat_row_avx2<kOther, kRatio>(n, in, out);
        case MapInstructionSet::Baseline:
            break;
    }
    return write_flat_row_baseline<kOther, kRatio>(n, in, out);
}
// The other correlation's layers written where out.o is not null, E1/E2 where out.ratio is not.
RowCounts write_flat_row(std::size_t n, const FlatRowIn& in, const FlatRowOut& out) {
    const MapInstructionSet isa = active_isa();
    const bool other = out.o != nullptr, ratio = out.ratio != nullptr;
    if (other && ratio) return write_flat_row_of<true, true>(isa, n, in, out);
    if (other) return write_flat_row_of<true, false>(isa, n, in, out);
    if (ratio) return write_flat_row_of<false, true>(isa, n, in, out);
    return write_flat_row_of<false, false>(isa, n, in, out);
}

// A flat sample's per-pixel map without σ: the row passes of evaluate_flat_row, which make only
// the layers asked for (every other map evaluates cells one by one into every layer).
bool lean_pixel_map(const MapOptions& o) {
    return o.window_px == 1 && o.normal_map.empty() && !o.sigma_um;
}

// Evaluates cells into the layers of the map (one copy per thread: its own hints and counts).
class Evaluator {
  public:
    Evaluator(const std::vector<MapCapture>& captures, const MapOptions& o, RoughnessMap& map)
        : c1_(captures[0]), c2_(captures[1]), o_(o), map_(map) {
        model_.factor = o.factor;
        model_.radiometry = o.radiometry;
        model_.wavelength_um = o.wavelength_um;
        flat_ = o.normal_map.empty();
        if (flat_) {
            // The tables are shared by the threads' copies (read only). A lean per-pixel map
            // needs only the primary correlation's, unless both layers or regions are asked for
            // (the regions' pooled σ/T give both).
            const bool both = !lean_pixel_map(o) || o.both_correlations || !o.region_labels.empty();
            const auto build = [&](Correlation c) {
                return std::make_shared<const RatioInverseTable>(RatioInverseTable::sigma_over_T(
                    c1_.geometry, c2_.geometry, c, model_, o.table));
            };
            if (both || o.correlation == Correlation::Gaussian)
                table_g_ = build(Correlation::Gaussian);
            if (both || o.correlation == Correlation::Exponential)
                table_e_ = build(Correlation::Exponential);
            map_.method = normal_view(c1_.geometry) && normal_view(c2_.geometry)
                              ? "table (Eq. 17/19)"
                              : "table (two-geometry model)";
            if (o.sigma_um) {
                const double g = std::max(roughness_g(*o.sigma_um, c1_.geometry, o.wavelength_um),
                                          roughness_g(*o.sigma_um, c2_.geometry, o.wavelength_um));
                flat_g_class_ = roughness_class(g);
                // T from the diffuse term valid at the sample's g: Eq. 3 (Eq. 15) for a
                // slightly rough sample, the exact series at any other g (Eq. 4/5 leave it:
                // at g = 18 Eq. 4 gives T 4 % high, Eq. 5 80 % low).
                TwoGeometryOptions m = model_;
                m.regime = *flat_g_class_ == RoughnessClass::SlightlyRough ? Regime::SlightlyRough
                                                                           : Regime::Series;
                try {
                    table_t_ = std::make_shared<const RatioInverseTable>(
                        RatioInverseTable::correlation_length(
                            c1_.geometry, c2_.geometry, *o.sigma_um, o.correlation, m, o.table));
                    if (o.sigma_um_stderr > 0.0) {
                        sigma_step_ = *o.sigma_um * 1e-4;
                        table_t2_ = std::make_shared<const RatioInverseTable>(
                            RatioInverseTable::correlation_length(c1_.geometry, c2_.geometry,
                                                                  *o.sigma_um + sigma_step_,
                                                                  o.correlation, m, o.table));
                    }
                } catch (const NoSolution& e) {
                    map_.warnings.push_back(concat("T given σ: ", e.what()));
                }
            }
        } else {
            map_.method = "solver per tile (two-geometry model)";
        }
    }

    // A flat sample's pixel (the layers' cells already NaN / no class): the two tables at the
    // ratio E1/E2, the error through their slopes.
    void evaluate_flat(std::size_t index, double ratio, double sd_lr) {
        map_.E1_over_E2[index] = static_cast<float>(ratio);
        RatioInverseTable::Value vg, ve;
        const bool g = table_g_->find_ratio(ratio, vg, hint_g_);
        const bool e = table_e_->find_ratio(ratio, ve, hint_e_);
        if (g) {
            map_.sigma_over_T_gaussian[index] = static_cast<float>(vg.x);
            map_.sigma_over_T_gaussian_stderr[index] =
                static_cast<float>(std::abs(vg.dx_dlog_ratio) * sd_lr);
        }
        if (e) {
            map_.sigma_over_T_exponential[index] = static_cast<float>(ve.x);
            map_.sigma_over_T_exponential_stderr[index] =
                static_cast<float>(std::abs(ve.dx_dlog_ratio) * sd_lr);
        }
        const bool gaussian = o_.correlation == Correlation::Gaussian;
        const bool has_primary = gaussian ? g : e;
        if (!(gaussian ? e : g)) ++counts_.no_solution_other;
        if (o_.sigma_um) estimate_T(index, std::log(ratio), sd_lr, std::nullopt, std::nullopt);
        if (!has_primary) {
            ++counts_.no_solution;
            return;
        }
        ++counts_.valid;
        const double x = gaussian ? vg.x : ve.x;
        map_.roughness_class[index] = class_code(roughness_class_of_sigma_over_T(
            x, o_.slightly_rough_max_sigma_over_T, o_.very_rough_min_sigma_over_T));
    }

    // A flat sample without σ (σ/T and its error, the class; the other correlation's σ/T and
    // error and E1/E2 where their layers are made): a row of pixels from `begin`, every cell
    // written once (no fill first).
    bool fast_flat() const { return flat_ && !o_.sigma_um; }
    // Returns the row's class sums.
    ClassSums evaluate_flat_row(std::size_t begin, std::size_t count, const double* ratio,
                                const double* var_log_ratio, const double* state) {
        const bool gaussian = o_.correlation == Correlation::Gaussian;
        const Correlation c = o_.correlation, oc = other_correlation(c);
        const bool other = !map_.sigma_over_T(oc).empty();
        for (auto* v : {&xp_, &sp_, &xo_, &so_, &klass_}) v->resize(count);
        const RatioInverseTable& tp = gaussian ? *table_g_ : *table_e_;
        const RatioInverseTable* to = gaussian ? table_e_.get() : table_g_.get();
        const bool pending_p = tp.find_ratio_bins(count, ratio, xp_.data(), sp_.data());
        const bool pending_o = other && to->find_ratio_bins(count, ratio, xo_.data(), so_.data());
        // The ratios outside the bins (few, or none): find at ln ratio (NaN stays where the
        // table has no solution).
        const auto rest = [&](const RatioInverseTable& table, std::vector<double>& x,
                              std::vector<double>& slope, std::size_t& hint) {
            for (std::size_t i = 0; i < count; ++i) {
                if (state[i] != 0.0 || !std::isnan(x[i])) continue;
                RatioInverseTable::Value v;
                if (!table.find(std::log(ratio[i]), v, hint)) continue;
                x[i] = v.x;
                slope[i] = v.dx_dlog_ratio;
            }
        };
        if (pending_p) rest(tp, xp_, sp_, gaussian ? hint_g_ : hint_e_);
        if (pending_o) rest(*to, xo_, so_, gaussian ? hint_e_ : hint_g_);
        MapLayerValues& lp = map_.sigma_over_T(c);
        MapLayerValues& lpse = map_.sigma_over_T_stderr(c);
        MapLayerValues& lo = map_.sigma_over_T(oc);
        MapLayerValues& lose = map_.sigma_over_T_stderr(oc);
        const FlatRowIn in{ratio,
                           var_log_ratio,
                           state,
                           xp_.data(),
                           sp_.data(),
                           xo_.data(),
                           so_.data(),
                           o_.slightly_rough_max_sigma_over_T,
                           o_.very_rough_min_sigma_over_T};
        const FlatRowOut out{map_.E1_over_E2.empty() ? nullptr : map_.E1_over_E2.data() + begin,
                             lp.data() + begin,
                             lpse.data() + begin,
                             other ? lo.data() + begin : nullptr,
                             other ? lose.data() + begin : nullptr,
                             klass_.data(),
                             map_.roughness_class.data() + begin};
        const RowCounts row = write_flat_row(count, in, out);
        counts_.valid += row.valid;
        counts_.missing += row.missing;
        counts_.no_solution += row.no_solution;
        counts_.no_solution_other += row.no_solution_other;
        return row.classes;
    }

    bool flat() const { return flat_; }
    // A flat sample's σ/T table of correlation c (null where it was not built).
    const RatioInverseTable* sigma_over_T_table(Correlation c) const {
        return c == Correlation::Gaussian ? table_g_.get() : table_e_.get();
    }

    void evaluate(std::size_t index, const Cell& cell) {
        const double lr = cell.log_ratio;
        map_.E1_over_E2[index] = static_cast<float>(cell.ratio);
        const double sd_lr = std::sqrt(cell.var_log_ratio);
        std::optional<Estimate> g, e;
        std::optional<Geometry> geom1, geom2;
        if (flat_) {
            if (auto v = table_g_->lookup(lr, hint_g_))
                g = Estimate{v->x, std::abs(v->dx_dlog_ratio) * sd_lr};
            if (auto v = table_e_->lookup(lr, hint_e_))
                e = Estimate{v->x, std::abs(v->dx_dlog_ratio) * sd_lr};
        } else {
            const double nn = cell.normal.norm();
            if (nn > 0.0) {
                const Eigen::Vector3d n = cell.normal / nn;
                geom1 = geometry_from_vectors(n, *c1_.light, *c1_.view);
                geom2 = geometry_from_vectors(n, *c2_.light, *c2_.view);
            }
            if (!geom1 || !geom2) {
                ++counts_.missing;
                map_.roughness_class[index] = kClassNone;
                if (!map_.roughness_class_g.empty()) map_.roughness_class_g[index] = kClassNone;
                return;
            }
            g = solve(lr, sd_lr, *geom1, *geom2, Correlation::Gaussian);
            e = solve(lr, sd_lr, *geom1, *geom2, Correlation::Exponential);
        }
        if (g) {
            map_.sigma_over_T_gaussian[index] = static_cast<float>(g->value);
            map_.sigma_over_T_gaussian_stderr[index] = static_cast<float>(g->std_error);
        }
        if (e) {
            map_.sigma_over_T_exponential[index] = static_cast<float>(e->value);
            map_.sigma_over_T_exponential_stderr[index] = static_cast<float>(e->std_error);
        }
        const std::optional<Estimate>& primary = o_.correlation == Correlation::Gaussian ? g : e;
        const std::optional<Estimate>& other = o_.correlation == Correlation::Gaussian ? e : g;
        if (!other) ++counts_.no_solution_other;
        if (o_.sigma_um) estimate_T(index, lr, sd_lr, geom1, geom2);
        if (!primary) {
            ++counts_.no_solution;
            map_.roughness_class[index] = kClassNone;
            return;
        }
        ++counts_.valid;
        map_.roughness_class[index] = class_code(roughness_class_of_sigma_over_T(
            primary->value, o_.slightly_rough_max_sigma_over_T, o_.very_rough_min_sigma_over_T));
    }

    // σ known: the class by g and T from the diffuse term valid at the cell's g (Eq. 3, i.e.
    // Eq. 15, for a slightly rough cell; the exact series otherwise).
    void estimate_T(std::size_t index, double lr, double sd_lr,
                    const std::optional<Geometry>& geom1, const std::optional<Geometry>& geom2) {
        const double sigma = *o_.sigma_um;
        RoughnessClass gc = RoughnessClass::VeryRough;
        if (flat_) {
            gc = *flat_g_class_;
        } else {
            gc = roughness_class(std::max(roughness_g(sigma, *geom1, o_.wavelength_um),
                                          roughness_g(sigma, *geom2, o_.wavelength_um)));
        }
        map_.roughness_class_g[index] = class_code(gc);
        std::optional<Estimate> T;
        if (flat_) {
            if (table_t_) {
                if (auto v = table_t_->lookup(lr, hint_t_)) {
                    double dT_dsigma = 0.0;
                    if (table_t2_) {
                        if (auto v2 = table_t2_->lookup(lr, hint_t2_))
                            dT_dsigma = (v2->x - v->x) / sigma_step_;
                    }
                    T = Estimate{
                        v->x, std::hypot(v->dx_dlog_ratio * sd_lr, dT_dsigma * o_.sigma_um_stderr)};
                }
            }
        } else {
            TwoGeometryOptions m = model_;
            m.regime = gc == RoughnessClass::SlightlyRough ? Regime::SlightlyRough : Regime::Series;
            try {
                const double t0 = correlation_length_two_geometries(std::exp(lr), *geom1, *geom2,
                                                                    sigma, o_.correlation, m);
                const double tp = correlation_length_two_geometries(
                    std::exp(lr + kLogStep), *geom1, *geom2, sigma, o_.correlation, m);
                const double ts = correlation_length_two_geometries(
                    std::exp(lr), *geom1, *geom2, sigma * (1.0 + 1e-4), o_.correlation, m);
                T = Estimate{t0, std::hypot((tp - t0) / kLogStep * sd_lr,
                                            (ts - t0) / (sigma * 1e-4) * o_.sigma_um_stderr)};
            } catch (const Error&) {
            }
        }
        if (T && std::isfinite(T->value) && std::isfinite(T->std_error)) {
            map_.T_um[index] = static_cast<float>(T->value);
            map_.T_um_stderr[index] = static_cast<float>(T->std_error);
        } else {
            ++counts_.no_solution_T;
        }
    }

    Counts& counts() { return counts_; }
    std::optional<RoughnessClass> flat_g_class() const { return flat_g_class_; }

  private:
    // The two-geometry solver (normal map), with d(σ/T)/d ln r = σ/T / (d ln M/d ln(σ/T)).
    std::optional<Estimate> solve(double lr, double sd_lr, const Geometry& g1, const Geometry& g2,
                                  Correlation c) const {
        try {
            const double s = sigma_over_T_two_geometries(std::exp(lr), g1, g2, c, model_);
            const auto [y, dy] =
                log_model([&](double x) { return model_ratio_very_rough(g1, g2, x, c, model_); },
                          std::log(s));
            (void)y;
            const double se = std::abs(s / dy) * sd_lr;
            if (!std::isfinite(s) || !std::isfinite(se)) return std::nullopt;
            return Estimate{s, se};
        } catch (const Error&) {
            return std::nullopt;
        }
    }

    const MapCapture& c1_;
    const MapCapture& c2_;
    const MapOptions& o_;
    RoughnessMap& map_;
    TwoGeometryOptions model_;
    bool flat_ = true;
    std::shared_ptr<const RatioInverseTable> table_g_, table_e_, table_t_, table_t2_;
    double sigma_step_ = 0.0;
    std::optional<RoughnessClass> flat_g_class_;
    std::size_t hint_g_ = 0, hint_e_ = 0, hint_t_ = 0, hint_t2_ = 0;
    Counts counts_;
    // A row's σ/T and slopes (primary, other correlation), and its class as a double
    // (evaluate_flat_row).
    std::vector<double> xp_, sp_, xo_, so_, klass_;
};

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

// The per-pixel map's running column sums restart from zero every kSumRestartRows rows, and its
// bands of rows start on such a row: a pixel's sums do not depend on where its band began (the
// map is the same on any number of threads, bit for bit) and the running sums' rounding never
// builds up over more than kSumRestartRows rows.
constexpr std::size_t kSumRestartRows = 64;
// The per-pixel map's passes over a row go in chunks of this many pixels.
constexpr std::size_t kPixelChunk = 256;

// The per-pixel map's column sums (n, Σx1, Σx2, Σx1², Σx2², Σx1x2 over rows [r − R, r + R]) +=
// row (a, b, weights u) · add_weight − row (ra, rb, ru) · remove_weight, in one pass. (Free
// functions with restrict parameters, so that the compiler vectorises them.)
[[gnu::always_inline]] inline void update_column_sums_body(
    std::size_t W, const double* __restrict a, const double* __restrict b,
    const double* __restrict u, double add_weight, const double* __restrict ra,
    const double* __restrict rb, const double* __restrict ru, double remove_weight,
    double* __restrict n, double* __restrict s1, double* __restrict s2, double* __restrict s11,
    double* __restrict s22, double* __restrict s12) {
    for (std::size_t x = 0; x < W; ++x) {
        const double w = add_weight * u[x], wa = w * a[x], wb = w * b[x];
        const double v = remove_weight * ru[x], va = v * ra[x], vb = v * rb[x];
        n[x] += w - v;
        s1[x] += wa - va;
        s2[x] += wb - vb;
        s11[x] += wa * a[x] - va * ra[x];
        s22[x] += wb * b[x] - vb * rb[x];
        s12[x] += wa * b[x] - va * rb[x];
    }
}
[[gnu::target("avx512f,avx512dq,avx512vl,avx512bw")]] void update_column_sums_avx512(
    std::size_t W, const double* a, const double* b, const double* u, double add_weight,
    const double* ra, const double* rb, const double* ru, double remove_weight, double* n,
    double* s1, double* s2, double* s11, double* s22, double* s12) {
    update_column_sums_body(W, a, b, u, add_weight, ra, rb, ru, remove_weight, n, s1, s2, s11, s22,
                            s12);
}
void update_column_sums(std::size_t W, const double* a, const double* b, const double* u,
                        double add_weight, const double* ra, const double* rb, const double* ru,
                        double remove_weight, double* n, double* s1, double* s2, double* s11,
                        double* s22, double* s12) {
    if (active_isa() == MapInstructionSet::Avx512)
        update_column_sums_avx512(W, a, b, u, add_weight, ra, rb, ru, remove_weight, n, s1, s2, s11,
                                  s22, s12);
    else
        update_column_sums_body(W, a, b, u, add_weight, ra, rb, ru, remove_weight, n, s1, s2, s11,
                                s22, s12);
}

// The window's sums at each pixel of a row (2R + 1 column sums from c*[x], padded), then the
// pixel's ratio x1/x2, var(ln x1/x2) of one pixel (the delta method on the window's means,
// variances and covariance, docs/maps.md, in the form n²/(n − 1) · [Σx1²/(Σx1)² + Σx2²/(Σx2)²
// − 2 Σx1x2/(Σx1 Σx2)], one division for it and the ratio) and its state (PixelState).
[[gnu::always_inline]] inline void pixel_statistics_body(
    std::size_t W, const double* __restrict a, const double* __restrict b,
    const double* __restrict u, const double* __restrict cn, const double* __restrict cs1,
    const double* __restrict cs2, const double* __restrict cs11, const double* __restrict cs22,
    const double* __restrict cs12, double* __restrict ratio, double* __restrict var,
    double* __restrict state) {
    constexpr std::size_t kTaps = 2 * kPixelNoiseRadius + 1;
    for (std::size_t x = 0; x < W; ++x) {
        double n = 0, s1 = 0, s2 = 0, s11 = 0, s22 = 0, s12 = 0;
        for (std::size_t d = 0; d < kTaps; ++d) {
            n += cn[x + d];
            s1 += cs1[x + d];
            s2 += cs2[x + d];
            s11 += cs11[x + d];
            s22 += cs22[x + d];
            s12 += cs12[x + d];
        }
        const double s1s2 = s1 * s2;
        const double p = s1s2 * s1s2 * (n - 1.0);
        const double inv = 1.0 / (p * b[x]);
        const double bracket = s11 * s2 * s2 + s22 * s1 * s1 - 2.0 * s12 * s1s2;
        var[x] = std::max(0.0, n * n * bracket * b[x] * inv);
        // Running sums of ±1 stay exact integers in n. Without branches (and in doubles, for
        // the vectoriser): 1 missing, 2 no solution, 0 an estimate — whose ratio alone is a
        // number (NaN otherwise, which the look-ups carry through to the layers).
        const double missing = !(u[x] > 0.0) || n < 3.0 ? 1.0 : 0.0;
        const double no_solution =
            !(a[x] > 0.0) || !(b[x] > 0.0) || !(s1 > 0.0) || !(s2 > 0.0) ? 1.0 : 0.0;
        const double st = missing + 2.0 * (1.0 - missing) * no_solution;
        state[x] = st;
        ratio[x] = nan_where(a[x] * p * inv, mask_of(st != 0.0));
    }
}
// pixel_statistics_body for AVX2 (four lanes) and for the baseline (two), as write_flat_row.
[[gnu::target("avx2")]] void pixel_statistics_avx2(std::size_t W, const double* a, const double* b,
                                                   const double* u, const double* cn,
                                                   const double* cs1, const double* cs2,
                                                   const double* cs11, const double* cs22,
                                                   const double* cs12, double* ratio, double* var,
                                                   double* state) {
    pixel_statistics_body(W, a, b, u, cn, cs1, cs2, cs11, cs22, cs12, ratio, var, state);
}
[[gnu::target("avx512f,avx512dq,avx512vl,avx512bw")]] void pixel_statistics_avx512(
    std::size_t W, const double* a, const double* b, const double* u, const double* cn,
    const double* cs1, const double* cs2, const double* cs11, const double* cs22,
    const double* cs12, double* ratio, double* var, double* state) {
    pixel_statistics_body(W, a, b, u, cn, cs1, cs2, cs11, cs22, cs12, ratio, var, state);
}
void pixel_statistics(std::size_t W, const double* a, const double* b, const double* u,
                      const double* cn, const double* cs1, const double* cs2, const double* cs11,
                      const double* cs22, const double* cs12, double* ratio, double* var,
                      double* state) {
    switch (active_isa()) {
        case MapInstructionSet::Avx512:
            pixel_statistics_avx512(W, a, b, u, cn, cs1, cs2, cs11, cs22, cs12, ratio, var, state);
            return;
        case MapInstructionSet::Avx2:
            pixel_statistics_avx2(W, a, b, u, cn, cs1, cs2, cs11, cs22, cs12, ratio, var, state);
            return;
        case MapInstructionSet::Baseline:
            break;
    }
    pixel_statistics_body(W, a, b, u, cn, cs1, cs2, cs11, cs22, cs12, ratio, var, state);
}
static_assert(static_cast<int>(PixelState::Estimate) == 0 &&
              static_cast<int>(PixelState::Missing) == 1 &&
              static_cast<int>(PixelState::NoSolution) == 2);

// Per pixel: the pixel's ratio, the noise from the (2R + 1)² neighbourhood. Row by row, each
// step a loop over plain arrays of the row: the column sums over rows [r − R, r + R] (running:
// the new row added and the old one removed in one pass), the window's sums over 2R + 1 columns
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
                           col[0].data() + R, col[1].data() + R, col[2].data() + R,
                           col[3].data() + R, col[4].data() + R, col[5].data() + R);
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
                             col[0].data() + c, col[1].data() + c, col[2].data() + c,
                             col[3].data() + c, col[4].data() + c, col[5].data() + c, ratio.data(),
                             var.data(), state.data());
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

// σ/T of a region of a flat sample: the inverse at the mean of its cells' ln(E1/E2), with the
// standard error of that mean through the inverse's slope. Averaging the cells' σ/T instead is
// biased where the inverse is curved and the cells are noisy (large σ/T, where E1/E2 hardly
// changes with σ/T).
std::optional<Estimate> pooled_sigma_over_T(const RatioInverseTable& table,
                                            const Accumulator& log_ratio) {
    const auto mean = log_ratio.mean();
    if (!mean) return std::nullopt;
    const auto v = table.lookup(mean->value);
    if (!v) return std::nullopt;
    return Estimate{v->x, std::abs(v->dx_dlog_ratio) * mean->std_error};
}

void summarise(const Evaluator& tables, const MapOptions& o, RoughnessMap& map,
               const std::vector<std::int32_t>& cell_region,
               const std::vector<ClassSums>& row_classes) {
    ClassSums classes;
    for (const ClassSums& row : row_classes)
        for (std::size_t c = 0; c < 3; ++c) {
            classes[c].n += row[c].n;
            classes[c].sum += row[c].sum;
            classes[c].sum2 += row[c].sum2;
        }
    std::vector<RegionAccumulator> regions(o.region_names.size());
    const std::size_t cells = map.width * map.height;
    for (std::size_t i = 0; i < cells && !cell_region.empty(); ++i) {
        const std::uint8_t c = map.roughness_class[i];
        const std::int32_t region = cell_region[i];
        if (region < 0) continue;
        RegionAccumulator& ra = regions[static_cast<std::size_t>(region)];
        if (!map.T_um.empty() && std::isfinite(map.T_um[i])) ra.T.add(map.T_um[i]);
        if (std::isfinite(map.E1_over_E2[i]) && map.E1_over_E2[i] > 0.0f)
            ra.log_ratio.add(std::log(static_cast<double>(map.E1_over_E2[i])));
        if (c == kClassNone) {
            ++ra.missing;
            continue;
        }
        ++ra.classes[c];
        // (A normal map makes both layers; a flat sample pools ln E1/E2 below.)
        if (!map.sigma_over_T_gaussian.empty() && std::isfinite(map.sigma_over_T_gaussian[i]))
            ra.gaussian.add(map.sigma_over_T_gaussian[i]);
        if (!map.sigma_over_T_exponential.empty() && std::isfinite(map.sigma_over_T_exponential[i]))
            ra.exponential.add(map.sigma_over_T_exponential[i]);
    }
    for (std::size_t c = 0; c < 3; ++c) {
        ClassStatistics& s = map.classes[c];
        s.roughness_class = static_cast<RoughnessClass>(c);
        s.count = classes[c].n;
        s.fraction =
            map.valid > 0 ? static_cast<double>(s.count) / static_cast<double>(map.valid) : 0.0;
        s.mean_sigma_over_T = classes[c].mean();
    }
    // A flat sample with regions has both tables (Evaluator).
    const RatioInverseTable* table_g = tables.sigma_over_T_table(Correlation::Gaussian);
    const RatioInverseTable* table_e = tables.sigma_over_T_table(Correlation::Exponential);
    assert(!o.normal_map.empty() || regions.empty() || (table_g && table_e));
    for (std::size_t k = 0; k < regions.size(); ++k) {
        RegionMapStatistics s;
        s.name = o.region_names[k];
        const RegionAccumulator& ra = regions[k];
        s.count = ra.classes[0] + ra.classes[1] + ra.classes[2];
        s.missing = ra.missing;
        // A flat sample: pooled over the region (one geometry); a normal map: the mean of the
        // cells' σ/T (each cell has its own geometry).
        s.mean_sigma_over_T_gaussian =
            table_g ? pooled_sigma_over_T(*table_g, ra.log_ratio) : ra.gaussian.mean();
        s.mean_sigma_over_T_exponential =
            table_e ? pooled_sigma_over_T(*table_e, ra.log_ratio) : ra.exponential.mean();
        s.mean_T_um = ra.T.mean();
        s.class_counts = ra.classes;
        const auto unknown = [](const std::optional<Estimate>& e) {
            return e && std::isnan(e->std_error);
        };
        if (unknown(s.mean_sigma_over_T_gaussian) || unknown(s.mean_sigma_over_T_exponential) ||
            unknown(s.mean_T_um))
            map.warnings.push_back(concat("roughness map: region '", s.name, "' has ",
                                          std::to_string(s.count),
                                          " valid cell(s) without spread between them: the "
                                          "standard error of its mean is unknown (null)"));
        map.regions.push_back(std::move(s));
    }
}

}  // namespace

RoughnessMap roughness_map(const std::vector<MapCapture>& captures, const MapOptions& o) {
    check_map_input(captures, o);
    RoughnessMap map;
    const LinearImage& a = *captures[0].image;
    const LinearImage& b = *captures[1].image;
    map.window_px = o.window_px;
    map.image_width = a.width;
    map.image_height = a.height;
    map.width = (a.width + o.window_px - 1) / o.window_px;
    map.height = (a.height + o.window_px - 1) / o.window_px;
    if (captures.size() > 2)
        map.warnings.push_back(concat("roughness map: ", std::to_string(captures.size()),
                                      " captures given; the map uses the first two (",
                                      capture_name(captures[0], 0), ", ",
                                      capture_name(captures[1], 1), ") and ignores the others"));
    // The registration check runs beside the map (its own thread): its verdict, an error or a
    // warning in its place among the others, is applied when both are done.
    const bool register_pair = o.check_registration && a.width >= 16 && a.height >= 16;
    std::optional<Registration> registration;
    std::exception_ptr registration_error;
    std::jthread registration_worker;
    if (register_pair)
        registration_worker = std::jthread([&] {
            try {
                registration = estimate_misregistration(a, b, o.registration);
            } catch (...) {
                registration_error = std::current_exception();
            }
        });
    const std::size_t registration_warning_at = map.warnings.size();
    const std::size_t cells = map.width * map.height;
    // The layers without a fill: each band's thread writes every cell of its rows (clear_rows).
    // A flat sample's per-pixel map without σ makes only the layers asked for (and E1/E2 for
    // the regions' pooled σ/T, dropped after); the other maps make all of them and drop those
    // not asked for at the end (tiles are few; cells evaluated one by one write every layer).
    const bool lean = lean_pixel_map(o);
    MapLayerValues& primary = map.sigma_over_T(o.correlation);
    MapLayerValues& primary_stderr = map.sigma_over_T_stderr(o.correlation);
    MapLayerValues& other = map.sigma_over_T(other_correlation(o.correlation));
    MapLayerValues& other_stderr = map.sigma_over_T_stderr(other_correlation(o.correlation));
    resize_large_uninitialised(primary, cells);
    resize_large_uninitialised(primary_stderr, cells);
    if (!lean || o.both_correlations) {
        resize_large_uninitialised(other, cells);
        resize_large_uninitialised(other_stderr, cells);
    }
    if (!lean || o.ratio_layer || !o.region_labels.empty())
        resize_large_uninitialised(map.E1_over_E2, cells);
    resize_large_uninitialised(map.roughness_class, cells);
    if (o.sigma_um) {
        resize_large_uninitialised(map.T_um, cells);
        resize_large_uninitialised(map.T_um_stderr, cells);
        resize_large_uninitialised(map.roughness_class_g, cells);
    }
    std::vector<std::int32_t> cell_region;
    if (!o.region_labels.empty()) cell_region.assign(cells, -1);
    const Evaluator prototype(captures, o, map);
    // Bands of rows (pixel rows, or rows of tiles), one thread each; the result does not depend
    // on the number of threads (each cell is computed from its own pixels).
    const std::size_t rows = map.height;
    std::size_t threads =
        o.threads == 0 ? std::max(1u, std::thread::hardware_concurrency()) : o.threads;
    threads = std::clamp<std::size_t>(threads, 1, std::max<std::size_t>(1, rows / 16));
    if (!o.normal_map.empty() || cells < 65536) threads = std::min<std::size_t>(threads, 1);
    std::vector<Evaluator> evaluators(threads, prototype);
    std::vector<std::exception_ptr> errors(threads);
    std::vector<ClassSums> row_classes(rows);
    // A band's first row (a pixel map's bands start where its column sums restart).
    auto band_start = [&](std::size_t t) {
        const std::size_t r = rows * t / threads;
        return o.window_px == 1 && t < threads ? r / kSumRestartRows * kSumRestartRows : r;
    };
    auto run = [&](std::size_t t) {
        try {
            const std::size_t begin = band_start(t), end = band_start(t + 1);
            if (o.window_px == 1) {
                pixel_map(captures, o, evaluators[t], map, cell_region, row_classes, begin, end);
            } else {
                clear_rows(map, begin, end);
                tile_map(captures, o, evaluators[t], map, cell_region, row_classes, begin, end);
            }
        } catch (...) {
            errors[t] = std::current_exception();
        }
    };
    {
        std::vector<std::jthread> workers;
        for (std::size_t t = 1; t < threads; ++t) workers.emplace_back(run, t);
        run(0);
    }
    if (registration_worker.joinable()) registration_worker.join();
    if (registration_error) std::rethrow_exception(registration_error);
    if (registration) {
        const Registration& reg = *registration;
        map.registration = reg;
        if (reg.magnitude_px > o.max_shift_px) {
            const std::string shift = concat(
                capture_name(captures[1], 1), " is shifted by (",
                check::format_number(reg.shift_x_px), ", ", check::format_number(reg.shift_y_px),
                ") px = ", check::format_number(reg.magnitude_px), " px against ",
                capture_name(captures[0], 0), " (phase correlation, peak-to-sidelobe ",
                check::format_number(reg.peak_to_sidelobe), "); the threshold max_shift_px is ",
                check::format_number(o.max_shift_px), " px");
            const auto warn = [&](std::string text) {
                map.warnings.insert(
                    map.warnings.begin() + static_cast<std::ptrdiff_t>(registration_warning_at),
                    std::move(text));
            };
            if (reg.peak_to_sidelobe < o.min_peak_to_sidelobe)
                warn(concat("roughness map: ", shift, ", but the peak-to-sidelobe ratio is below ",
                            check::format_number(o.min_peak_to_sidelobe),
                            ": the images share too little structure to tell"));
            else if (!o.normal_map.empty())
                // A curved object's shading moves with the light, and phase correlation reads
                // that as a shift as confidently as a movement of the camera (docs/maps.md
                // "Registration"): no evidence of a movement, so no refusal.
                warn(concat("roughness map: ", shift,
                            ", but with a normal map the shading moves with the light, which "
                            "phase correlation cannot tell from a movement of the camera: not "
                            "refused; the map assumes the camera did not move"));
            else if (!o.allow_misregistration)
                throw DataError(concat("roughness map: ", shift,
                                       ": register the images (or allow the misregistration)"));
            else
                warn(concat("roughness map: ", shift,
                            " (allowed: ratios near edges are unreliable)"));
        }
    }
    for (const auto& e : errors)
        if (e) std::rethrow_exception(e);
    Counts counts;
    for (auto& ev : evaluators) counts.add(ev.counts());
    map.valid = counts.valid;
    map.missing = counts.missing;
    map.no_solution = counts.no_solution;
    if (o.both_correlations) map.no_solution_other = counts.no_solution_other;
    summarise(prototype, o, map, cell_region, row_classes);
    if (!o.both_correlations) {
        other = MapLayerValues();
        other_stderr = MapLayerValues();
    }
    if (!o.ratio_layer) map.E1_over_E2 = MapLayerValues();
    if (map.no_solution > 0)
        map.warnings.push_back(concat("roughness map: ", std::to_string(map.no_solution), " of ",
                                      std::to_string(cells),
                                      " pixels/tiles have a ratio E1/E2 the model does not produce "
                                      "(no σ/T)"));
    if (o.sigma_um && counts.no_solution_T > 0)
        map.warnings.push_back(concat("roughness map: ", std::to_string(counts.no_solution_T),
                                      " pixels/tiles with σ/T have no T given σ"));
    if (map.valid == 0) map.warnings.push_back("roughness map: no pixel or tile has an estimate");
    return map;
}

}  // namespace roughscope::image
