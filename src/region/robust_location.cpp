#include "robust_location.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

namespace roughscope::image {
namespace {

constexpr double kHuberK = 1.345;              // 95 % efficiency at the normal distribution
constexpr double kMadToSigma = 1.4826;         // 1 / Φ⁻¹(3/4): MAD → σ for normal data
constexpr double kMeanAbsToSigma = 1.2533141;  // √(π/2): mean |v − median| → σ for normal data
constexpr int kHuberMaxIterations = 100;
constexpr double kHuberTolerance = 1e-12;  // of S

// Below this count a copy and std::nth_element cost less than clearing the radix histograms.
constexpr std::size_t kRadixMinCount = 4096;
constexpr std::size_t kBuckets = std::size_t{1} << 16;
constexpr std::size_t kLanes = 4;  // histograms filled in turn: no chain of increments of one cell
constexpr std::size_t kLaneStride = kBuckets + 1;  // the last cell of a lane counts misses

// Order-preserving key: a < b ⇔ key(a) < key(b) for finite floats; −0 and +0 get the same key.
std::uint32_t order_key(float v) {
    const auto bits = std::bit_cast<std::uint32_t>(v + 0.0F);  // −0 + 0 = +0
    return (bits & 0x8000'0000U) != 0 ? ~bits : bits | 0x8000'0000U;
}

float key_value(std::uint32_t key) {
    return std::bit_cast<float>((key & 0x8000'0000U) != 0 ? key & 0x7FFF'FFFFU : ~key);
}

struct Identity {
    float operator()(float v) const { return v; }
};

// |v − m| rounded to float, as the MAD series is.
struct AbsDeviation {
    double m;
    float operator()(float v) const {
        return static_cast<float>(std::abs(static_cast<double>(v) - m));
    }
};

// Calls f(lane, value) for every value; lanes 0..kLanes−1 in turn within each run.
template <class F>
void for_each_laned(const ValueSeries& series, F&& f) {
    for_each_span(series, [&](const float* p, std::size_t n) {
        std::size_t i = 0;
        for (; i + kLanes <= n; i += kLanes)
            for (std::size_t lane = 0; lane < kLanes; ++lane) f(lane, p[i + lane]);
        for (; i < n; ++i) f(0, p[i]);
    });
}

// Adds the lanes into lane 0 (cells 0..kBuckets−1).
void merge_lanes(std::vector<std::uint32_t>& table) {
    for (std::size_t lane = 1; lane < kLanes; ++lane)
        for (std::size_t b = 0; b < kBuckets; ++b) table[b] += table[lane * kLaneStride + b];
}

// The values of rank lo and hi (0-based, lo ≤ hi ≤ lo + 1 < count) of transform(v) over the
// series: radix selection on the keys, 16 bits at a time.
template <class T>
std::pair<float, float> select_ranks_radix(const ValueSeries& series, T transform, std::size_t lo,
                                           std::size_t hi) {
    assert(lo <= hi && hi <= lo + 1 && hi < series.count);
    std::vector<std::uint32_t> table(kLanes * kLaneStride, 0);
    // Pass 1: the high 16 bits.
    for_each_laned(series, [&](std::size_t lane, float v) {
        ++table[lane * kLaneStride + (order_key(transform(v)) >> 16)];
    });
    merge_lanes(table);
    std::size_t cum = 0, before_hi = 0;
    std::uint32_t bucket_lo = 0, bucket_hi = 0;
    bool found_lo = false;
    for (std::uint32_t b = 0; b < kBuckets; ++b) {
        const std::size_t next = cum + table[b];
        if (!found_lo && next > lo) {
            bucket_lo = b;
            found_lo = true;
        }
        if (next > hi) {
            bucket_hi = b;
            before_hi = cum;
            break;
        }
        cum = next;
    }
    assert(found_lo && before_hi <= hi);
    // Pass 2: the low 16 bits within the bucket of rank hi. When rank lo lies in an earlier
    // bucket it is that bucket's last value: its largest key.
    std::fill(table.begin(), table.end(), 0U);
    std::array<std::uint32_t, kLanes> lo_max{};
    for_each_laned(series, [&](std::size_t lane, float v) {
        const std::uint32_t key = order_key(transform(v));
        const std::uint32_t high = key >> 16;
        const std::size_t cell = high == bucket_hi ? (key & 0xFFFFU) : kBuckets;
        ++table[lane * kLaneStride + cell];
        lo_max[lane] = std::max(lo_max[lane], high == bucket_lo ? key : 0U);
    });
    merge_lanes(table);
    const auto key_of_rank = [&](std::size_t rank) {
        std::size_t c = before_hi;
        for (std::uint32_t b = 0; b < kBuckets; ++b) {
            c += table[b];
            if (c > rank) return (bucket_hi << 16) | b;
        }
        assert(false && "rank not in its bucket");
        return 0U;
    };
    const std::uint32_t key_hi = key_of_rank(hi);
    std::uint32_t key_lo = key_hi;
    if (lo != hi) {
        if (bucket_lo == bucket_hi) {
            key_lo = key_of_rank(lo);
        } else {
            assert(before_hi == lo + 1);
            key_lo = *std::max_element(lo_max.begin(), lo_max.end());
        }
    }
    return {key_value(key_lo), key_value(key_hi)};
}

// The same on a copy with std::nth_element (small series).
template <class T>
std::pair<float, float> select_ranks_copy(const ValueSeries& series, T transform, std::size_t lo,
                                          std::size_t hi) {
    std::vector<float> work;
    work.reserve(series.count);
    for_each_span(series, [&](const float* p, std::size_t n) {
        for (std::size_t i = 0; i < n; ++i) work.push_back(transform(p[i]));
    });
    const auto at = [&](std::size_t rank) {
        return work.begin() + static_cast<std::ptrdiff_t>(rank);
    };
    std::nth_element(work.begin(), at(hi), work.end());
    const float upper = work[hi];
    const float lower = lo == hi ? upper : *std::max_element(work.begin(), at(hi));
    return {lower, upper};
}

// Median of transform(v): the middle value, or the mean of the two middle values.
template <class T>
double median_of(const ValueSeries& series, T transform) {
    assert(series.count > 0);
    const std::size_t mid = series.count / 2;
    const std::size_t lo = series.count % 2 == 1 ? mid : mid - 1;
    const auto [lower, upper] = series.count < kRadixMinCount
                                    ? select_ranks_copy(series, transform, lo, mid)
                                    : select_ranks_radix(series, transform, lo, mid);
    if (lo == mid) return upper;
    return 0.5 * (static_cast<double>(lower) + static_cast<double>(upper));
}

// Σ ψ_c(v − μ) and the counts of values below μ − c and above μ + c.
struct PsiSum {
    double psi = 0;
    std::size_t low = 0, high = 0;
};

PsiSum psi_sum(const ValueSeries& series, double mu, double cut) {
    std::array<double, kLanes> psi{};
    std::array<std::size_t, kLanes> low{}, high{};
    for_each_laned(series, [&](std::size_t lane, float v) {
        const double r = static_cast<double>(v) - mu;
        low[lane] += r < -cut ? 1 : 0;
        high[lane] += r > cut ? 1 : 0;
        psi[lane] += std::min(std::max(r, -cut), cut);
    });
    PsiSum s;
    for (std::size_t lane = 0; lane < kLanes; ++lane) {
        s.psi += psi[lane];
        s.low += low[lane];
        s.high += high[lane];
    }
    return s;
}

ValueSeries whole(std::span<const float> values, ValueRun& run) {
    assert(values.size() <= std::numeric_limits<std::uint32_t>::max());
    run = {0, static_cast<std::uint32_t>(values.size())};
    return {values.data(), std::span<const ValueRun>(&run, 1), values.size()};
}

}  // namespace

double series_median(const ValueSeries& series) { return median_of(series, Identity{}); }

HuberLocation huber_location(const ValueSeries& series) {
    assert(series.count > 0);
    HuberLocation h;
    h.median = series_median(series);
    h.scale = kMadToSigma * median_of(series, AbsDeviation{h.median});
    if (!(h.scale > 0.0)) {
        // More than half the values equal: the mean absolute deviation.
        double sum_abs = 0.0;
        for_each_span(series, [&](const float* p, std::size_t n) {
            for (std::size_t i = 0; i < n; ++i)
                sum_abs += std::abs(static_cast<double>(p[i]) - h.median);
        });
        h.scale = kMeanAbsToSigma * (sum_abs / static_cast<double>(series.count));
    }
    h.location = h.median;
    if (!(h.scale > 0.0)) return h;

    const double cut = kHuberK * h.scale;
    const auto n = static_cast<double>(series.count);
    double mu = h.median;
    PsiSum e = psi_sum(series, mu, cut);
    h.evaluations = 1;
    // The root lies in (a, b): Σψ(a) = fa > 0 > fb = Σψ(b).
    double a = -std::numeric_limits<double>::infinity(), fa = 0.0;
    double b = std::numeric_limits<double>::infinity(), fb = 0.0;
    for (int iteration = 0; iteration < kHuberMaxIterations && e.psi != 0.0; ++iteration) {
        if (e.psi > 0.0) {
            a = mu;
            fa = e.psi;
        } else {
            b = mu;
            fb = e.psi;
        }
        const std::size_t inliers = series.count - e.low - e.high;
        double next = inliers > 0 ? mu + e.psi / static_cast<double>(inliers) : mu;
        const bool newton = inliers > 0 && next > a && next < b;
        if (!newton)
            next = std::isfinite(a) && std::isfinite(b) ? a + fa * (b - a) / (fa - fb)
                                                        : mu + e.psi / n;
        const PsiSum at_next = psi_sum(series, next, cut);
        ++h.evaluations;
        const bool same_sets = at_next.low == e.low && at_next.high == e.high;
        const bool small = std::abs(next - mu) <= kHuberTolerance * h.scale;
        mu = next;
        e = at_next;
        if ((newton && same_sets) || small) break;
    }
    h.location = mu;
    return h;
}

double series_median(std::span<const float> values) {
    ValueRun run;
    return series_median(whole(values, run));
}

HuberLocation huber_location(std::span<const float> values) {
    ValueRun run;
    return huber_location(whole(values, run));
}

}  // namespace roughscope::image
