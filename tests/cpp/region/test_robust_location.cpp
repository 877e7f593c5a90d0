// The exact median and the Huber M-estimate of region_statistics (src/region/robust_location.hpp)
// against independent computations: std::nth_element for the median (random, duplicated,
// negative, signed-zero data, odd and even counts, both the radix path and the small-series copy),
// and the iteratively reweighted mean the estimate was first computed with (IRLS from the median,
// 10⁻¹⁵ S tolerance) for the Huber estimate on several distributions.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <span>
#include <vector>

#include <gtest/gtest.h>

#include "region/robust_location.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/region/region.hpp"
#include "roughscope/region/statistics.hpp"

namespace roughscope::image {
namespace {

// The median as std::nth_element selects it; the mean of the two middle values for an even count.
double nth_element_median(std::vector<float> v) {
    const std::size_t mid = v.size() / 2;
    const auto at = v.begin() + static_cast<std::ptrdiff_t>(mid);
    std::nth_element(v.begin(), at, v.end());
    const double upper = *at;
    if (v.size() % 2 == 1) return upper;
    return 0.5 * (static_cast<double>(*std::max_element(v.begin(), at)) + upper);
}

// Huber's estimate by iteratively reweighted means from the median, w = min(1, c / |v − μ|), with
// S = 1.4826 · MAD (√(π/2) · mean |v − median| when MAD = 0), iterated to 10⁻¹⁵ S.
double irls_huber(const std::vector<float>& v) {
    const double med = nth_element_median(v);
    std::vector<float> dev(v.size());
    double mean_abs = 0.0;
    for (std::size_t i = 0; i < v.size(); ++i) {
        const double d = std::abs(static_cast<double>(v[i]) - med);
        dev[i] = static_cast<float>(d);
        mean_abs += d;
    }
    double scale = 1.4826 * nth_element_median(dev);
    if (!(scale > 0.0)) scale = 1.2533141 * mean_abs / static_cast<double>(v.size());
    if (!(scale > 0.0)) return med;
    const double cut = 1.345 * scale;
    double mu = med;
    for (int iteration = 0; iteration < 10000; ++iteration) {
        double sum_w = 0.0, sum_wv = 0.0;
        for (const float x : v) {
            const double d = std::abs(x - mu);
            const double w = d <= cut ? 1.0 : cut / d;
            sum_w += w;
            sum_wv += w * x;
        }
        const double next = sum_wv / sum_w;
        const bool done = std::abs(next - mu) <= 1e-15 * scale;
        mu = next;
        if (done) break;
    }
    return mu;
}

std::vector<float> normal(std::size_t n, double mean, double sd, unsigned seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> d(mean, sd);
    std::vector<float> v(n);
    for (float& x : v) x = static_cast<float>(d(rng));
    return v;
}

TEST(RegionRobustLocation, MedianEqualsNthElement) {
    std::mt19937 rng(11);
    std::vector<std::vector<float>> cases;
    for (const std::size_t n : {20001U, 20000U, 4096U, 4097U}) {
        cases.push_back(normal(n, 0.35, 0.01, static_cast<unsigned>(n)));  // random
        std::uniform_int_distribution<int> level(0, 9);
        std::vector<float> dup(n);
        for (float& x : dup) x = 0.25F * static_cast<float>(level(rng));  // many equal values
        cases.push_back(dup);
        std::uniform_real_distribution<float> neg(-5.0F, -1.0F);
        std::vector<float> negative(n);
        for (float& x : negative) x = neg(rng);
        cases.push_back(negative);
        std::vector<float> mixed = normal(n, 0.0, 1e-3, 3);  // both signs, ±0
        for (std::size_t k = 0; k < n; k += 5) mixed[k] = k % 2 == 0 ? -0.0F : 0.0F;
        cases.push_back(mixed);
    }
    // Even count whose two middle values lie far apart (different high 16 bits of the key).
    std::vector<float> split(10000, 1.0F);
    std::fill(split.begin() + 5000, split.end(), 3.0F);
    split[17] = -2.0F;
    split[7000] = 1.5F;
    cases.push_back(split);
    cases.push_back({2.5F});
    cases.push_back({2.5F, -1.0F});
    cases.push_back(normal(101, 5.0, 2.0, 4));
    cases.push_back(normal(100, 5.0, 2.0, 5));
    for (const std::vector<float>& v : cases) {
        const double expected = nth_element_median(v);
        EXPECT_EQ(series_median(std::span<const float>(v)), expected) << v.size() << " values";
    }
    // The split case: the middle values
    // are 1.0 (rank 4999) and 1.5 (rank 5000), in different key buckets.
    EXPECT_EQ(series_median(std::span<const float>(split)), 1.25);
}

TEST(RegionRobustLocation, MedianOfRunsIsTheMedianOfTheirValues) {
    // Runs over a larger array: only the values in the runs count.
    std::vector<float> array = normal(30000, 10.0, 3.0, 6);
    const std::vector<ValueRun> runs = {{100, 9000}, {12000, 1}, {15000, 7000}};
    std::vector<float> selected;
    std::size_t count = 0;
    for (const ValueRun& r : runs) {
        selected.insert(selected.end(), array.begin() + r.start,
                        array.begin() + r.start + r.length);
        count += r.length;
    }
    const ValueSeries series{array.data(), runs, count};
    EXPECT_EQ(series_median(series), nth_element_median(selected));
    EXPECT_NEAR(huber_location(series).location, irls_huber(selected), 1e-12 * 10.0);
}

TEST(RegionRobustLocation, HuberEqualsReweightedMeans) {
    struct Case {
        const char* name;
        std::vector<float> values;
    };
    std::vector<Case> cases;
    cases.push_back({"normal", normal(20001, 0.35, 0.01, 7)});
    {
        std::vector<float> v = normal(20000, 0.35, 0.01, 8);  // 10 % outliers above
        std::mt19937 rng(9);
        std::uniform_real_distribution<double> high(0.5, 1.0);
        for (std::size_t k = 0; k < v.size(); k += 10) v[k] = static_cast<float>(high(rng));
        cases.push_back({"10 % outliers", v});
    }
    {
        std::mt19937 rng(10);
        std::student_t_distribution<double> t(1.5);  // heavy tails
        std::vector<float> v(12000);
        for (float& x : v) x = static_cast<float>(2.0 + 0.1 * t(rng));
        cases.push_back({"heavy-tailed", v});
    }
    {
        std::vector<float> v = normal(3000, 0.35, 0.01, 12);  // small series (copy path)
        v[3] = 50.0F;
        cases.push_back({"small", v});
    }
    cases.push_back({"constant", std::vector<float>(9000, 0.625F)});
    {
        std::vector<float> v(10000, 0.3F);  // two values, 60 % / 40 %: MAD = 0
        std::fill(v.begin() + 6000, v.end(), 0.7F);
        cases.push_back({"two-valued", v});
    }
    {
        std::vector<float> v(10001, 0.3F);  // two values, nearly half / half
        std::fill(v.begin() + 5000, v.end(), 0.7F);
        cases.push_back({"two-valued, even split", v});
    }
    for (const Case& c : cases) {
        const double expected = irls_huber(c.values);
        const HuberLocation h = huber_location(std::span<const float>(c.values));
        EXPECT_NEAR(h.location, expected, 1e-12 * std::abs(expected)) << c.name;
        EXPECT_EQ(h.median, nth_element_median(c.values)) << c.name;
        // The estimating equation itself: Σ ψ_c(v − μ) ≈ 0 relative to n c.
        if (h.scale > 0.0) {
            const double cut = 1.345 * h.scale;
            double psi = 0.0;
            for (const float x : c.values) psi += std::clamp(x - h.location, -cut, cut);
            EXPECT_LE(std::abs(psi), 1e-9 * cut * static_cast<double>(c.values.size())) << c.name;
            // Newton steps: a handful of reads, where the reweighted means take tens.
            EXPECT_LE(h.evaluations, 6) << c.name;
        } else {
            EXPECT_EQ(h.location, c.values[0]) << c.name;
        }
    }
}

TEST(RegionRobustLocation, RegionStatisticsOfALargeRegionUseTheSameEstimates) {
    // 160 x 120 grey with 5 % hot pixels and some saturated ones: the robust mean of the region
    // equals the reweighted means of the used values; a mask of the wrong size is invalid.
    LinearImage image;
    image.width = 160;
    image.height = 120;
    image.channels = 1;
    const std::vector<float> values = normal(std::size_t{160} * 120, 0.3, 0.01, 13);
    image.values.assign(values.begin(), values.end());
    image.flags.assign(std::size_t{160} * 120, 0);
    image.info.source = "large.tif";
    for (std::size_t k = 0; k < image.values.size(); k += 20) image.values[k] = 0.9F;
    for (std::size_t k = 7; k < image.values.size(); k += 101) image.flags[k] = kPixelSaturated;
    const auto mask = rasterize(CircleRegion{80, 60, 55}, 160, 120);
    const RegionStatistics s = region_statistics(image, mask);
    std::vector<float> used;
    for (std::size_t k = 0; k < mask.size(); ++k)
        if (mask[k] != 0 && image.flags[k] == 0) used.push_back(image.values[k]);
    ASSERT_GT(used.size(), 4096U);
    EXPECT_EQ(s.pixels_used, used.size());
    EXPECT_NEAR(s.average.robust_mean, irls_huber(used), 1e-12 * 0.3);
    EXPECT_THROW((void)region_statistics(image, std::vector<std::uint8_t>(mask.size() - 1, 1)),
                 InvalidArgument);
}

}  // namespace
}  // namespace roughscope::image
