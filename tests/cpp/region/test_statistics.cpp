// Region statistics (image/statistics.hpp) against direct computation on synthetic images with
// known mean and noise (seeded): flagged pixels left out, the tile rule, the Huber estimating
// equation, texture seen by the tile error; mostly saturated regions and invalid options.
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <span>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "region/robust_location.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/region/region.hpp"
#include "roughscope/region/statistics.hpp"

namespace roughscope::image {
namespace {

LinearImage noisy_image(std::size_t width, std::size_t height, std::size_t channels,
                        const std::vector<double>& means, double noise, unsigned seed) {
    LinearImage image;
    image.width = width;
    image.height = height;
    image.channels = channels;
    image.values.resize(channels * width * height);
    image.flags.assign(width * height, 0);
    image.info.source = "synthetic.tif";
    std::mt19937 rng(seed);
    std::normal_distribution<double> n(0.0, noise > 0.0 ? noise : 1.0);
    for (std::size_t c = 0; c < channels; ++c)
        for (std::size_t k = 0; k < width * height; ++k)
            image.values[c * width * height + k] =
                static_cast<float>(means[c] + (noise > 0.0 ? n(rng) : 0.0));
    return image;
}

struct Direct {
    double mean, std_dev;
    std::size_t n;
};

// Long-double two-pass mean and sample standard deviation of the selected values.
Direct direct(const std::vector<double>& v) {
    long double sum = 0;
    for (const double x : v) sum += x;
    const long double mean = sum / static_cast<long double>(v.size());
    long double ss = 0;
    for (const double x : v) ss += (x - mean) * (x - mean);
    return {static_cast<double>(mean),
            static_cast<double>(std::sqrt(ss / static_cast<long double>(v.size() - 1))), v.size()};
}

std::vector<double> selected(const LinearImage& image, std::size_t channel,
                             const std::vector<std::uint8_t>& mask) {
    std::vector<double> v;
    for (std::size_t k = 0; k < image.pixel_count(); ++k)
        if (mask[k] && image.flags[k] == 0) v.push_back(image.plane(channel)[k]);
    return v;
}

void expect_matches(const ChannelStatistics& s, const std::vector<double>& values) {
    const Direct d = direct(values);
    EXPECT_EQ(s.count, d.n);
    EXPECT_NEAR(s.mean, d.mean, 1e-12 * std::max(1.0, std::abs(d.mean)));
    EXPECT_NEAR(s.std_dev, d.std_dev, 1e-10 * d.std_dev);
    EXPECT_NEAR(s.stderr_pixel, d.std_dev / std::sqrt(static_cast<double>(d.n)), 1e-10 * d.std_dev);
}

TEST(RegionStatistics, GreyMeanAndNoiseMatchDirectComputation) {
    const LinearImage image = noisy_image(64, 48, 1, {0.3}, 0.02, 1);
    const auto mask = rasterize(CircleRegion{30, 22, 15}, 64, 48);
    const RegionStatistics s = region_statistics(image, mask);
    ASSERT_EQ(s.channels.size(), 1U);
    expect_matches(s.channels[0], selected(image, 0, mask));
    expect_matches(s.average, selected(image, 0, mask));
    std::size_t in = 0;
    for (const auto b : mask) in += b;
    EXPECT_EQ(s.pixels_in_region, in);
    EXPECT_EQ(s.pixels_used, in);
    EXPECT_EQ(s.pixels_saturated, 0U);
    EXPECT_TRUE(s.warnings.empty());
    // Against the truth: mean within 4 standard errors, σ within 10 %.
    EXPECT_NEAR(s.average.mean, 0.3, 4.0 * s.average.stderr_pixel);
    EXPECT_NEAR(s.average.std_dev, 0.02, 0.002);
    EXPECT_NEAR(s.average.robust_mean, 0.3, 5.0 * s.average.stderr_pixel);
}

TEST(RegionStatistics, RgbChannelsAndTheirAverage) {
    const LinearImage image = noisy_image(40, 40, 3, {0.2, 0.5, 0.8}, 0.03, 2);
    const auto mask = rasterize(RectangleRegion{5, 5, 30, 25}, 40, 40);
    const RegionStatistics s = region_statistics(image, mask);
    ASSERT_EQ(s.channels.size(), 3U);
    for (std::size_t c = 0; c < 3; ++c) expect_matches(s.channels[c], selected(image, c, mask));
    std::vector<double> average;
    for (std::size_t k = 0; k < image.pixel_count(); ++k)
        if (mask[k])
            average.push_back(
                (static_cast<double>(image.plane(0)[k]) + image.plane(1)[k] + image.plane(2)[k]) /
                3.0);
    expect_matches(s.average, average);
    EXPECT_NEAR(s.average.mean, 0.5, 4.0 * s.average.stderr_pixel);
    // The average of three independent noises: σ/√3.
    EXPECT_NEAR(s.average.std_dev, 0.03 / std::sqrt(3.0), 0.002);
}

TEST(RegionStatistics, FlaggedPixelsAreNeverAveragedIn) {
    LinearImage image = noisy_image(32, 32, 1, {0.4}, 0.01, 3);
    const auto mask = rasterize(RectangleRegion{0, 0, 32, 16}, 32, 32);
    // 40 saturated (value 1), 10 clipped low (value 0), 5 with another flag bit (e.g. no flat
    // field), 3 both saturated and clipped low; and flagged pixels outside the region.
    std::size_t k = 0;
    const auto flag = [&](std::uint8_t bits, float value, int n) {
        for (int i = 0; i < n; ++i, k += 7) {
            image.flags[k] = bits;
            image.values[k] = value;
        }
    };
    flag(kPixelSaturated, 1.0F, 40);
    flag(kPixelClippedLow, 0.0F, 10);
    flag(4, 50.0F, 5);
    flag(kPixelSaturated | kPixelClippedLow, 1.0F, 3);
    ASSERT_LT(k, 512U);
    image.flags[600] = kPixelSaturated;
    const RegionStatistics s = region_statistics(image, mask);
    expect_matches(s.channels[0], selected(image, 0, mask));
    EXPECT_EQ(s.pixels_in_region, 512U);
    EXPECT_EQ(s.pixels_used, 512U - 58U);
    EXPECT_EQ(s.pixels_saturated, 43U);
    EXPECT_EQ(s.pixels_clipped_low, 13U);
    EXPECT_NEAR(s.average.mean, 0.4, 4.0 * s.average.stderr_pixel);
    ASSERT_FALSE(s.warnings.empty());
    EXPECT_NE(s.warnings[0].find("58 of 512"), std::string::npos) << s.warnings[0];
    EXPECT_NE(s.warnings[0].find("43 saturated"), std::string::npos) << s.warnings[0];
    // Above the warning fraction (58 / 512 = 0.113): no warning.
    RegionStatisticsOptions quiet;
    quiet.warn_excluded_fraction = 0.2;
    EXPECT_TRUE(region_statistics(image, mask, quiet).warnings.empty());
}

TEST(RegionStatistics, MostlySaturatedRegionsAreInvalid) {
    LinearImage image = noisy_image(20, 20, 1, {0.4}, 0.01, 4);
    const auto mask = rasterize(RectangleRegion{0, 0, 10, 10}, 20, 20);
    for (std::size_t y = 0; y < 10; ++y)
        for (std::size_t x = 0; x < 6; ++x) image.flags[y * 20 + x] = kPixelSaturated;
    try {
        (void)region_statistics(image, mask);
        FAIL() << "60 % saturated accepted";
    } catch (const InvalidArgument& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("mostly saturated"), std::string::npos) << what;
        EXPECT_NE(what.find("60 of 100"), std::string::npos) << what;
        EXPECT_NE(what.find("synthetic.tif"), std::string::npos) << what;
    }
    RegionStatisticsOptions lenient;
    lenient.max_excluded_fraction = 0.7;
    const RegionStatistics s = region_statistics(image, mask, lenient);
    EXPECT_EQ(s.pixels_used, 40U);
    // No usable pixel at all is invalid even when every fraction is allowed.
    for (std::size_t y = 0; y < 10; ++y)
        for (std::size_t x = 0; x < 10; ++x) image.flags[y * 20 + x] = kPixelClippedLow;
    lenient.max_excluded_fraction = 1.0;
    EXPECT_THROW((void)region_statistics(image, mask, lenient), InvalidArgument);
}

TEST(RegionStatistics, TileErrorMatchesDirectTileMeans) {
    // Explicit 8-px tiles on a region [4, 21) × [0, 16): tile columns [0, 8) hold 4 × 8 = 32 of
    // 64 pixels (count: ≥ half), [8, 16) all, [16, 24) 5 × 8 = 40 (count); two tile rows.
    const LinearImage image = noisy_image(32, 24, 1, {0.5}, 0.05, 5);
    const auto mask = rasterize(RectangleRegion{4, 0, 17, 16}, 32, 24);
    RegionStatisticsOptions options;
    options.tile_size_px = 8;
    const RegionStatistics s = region_statistics(image, mask, options);
    EXPECT_EQ(s.tile_size_px, 8U);
    std::vector<double> means;
    for (std::size_t ty = 0; ty < 2; ++ty)
        for (const auto& [x0, x1] : {std::pair{4, 8}, std::pair{8, 16}, std::pair{16, 21}}) {
            double sum = 0;
            for (std::size_t y = ty * 8; y < ty * 8 + 8; ++y)
                for (int x = x0; x < x1; ++x)
                    sum += image.values[y * 32 + static_cast<std::size_t>(x)];
            means.push_back(sum / (8.0 * (x1 - x0)));
        }
    const Direct d = direct(means);
    EXPECT_EQ(s.average.tiles, 6U);
    EXPECT_NEAR(s.average.stderr_tiles, d.std_dev / std::sqrt(6.0), 1e-12);
    EXPECT_EQ(s.channels[0].stderr_tiles, s.average.stderr_tiles);

    // One column less in the first tile: 3 × 8 = 24 < 32 pixels, that tile no longer counts.
    const auto narrower = rasterize(RectangleRegion{5, 0, 16, 16}, 32, 24);
    EXPECT_EQ(region_statistics(image, narrower, options).average.tiles, 4U);
}

TEST(RegionStatistics, TileErrorSeesTextureThatPixelErrorMisses) {
    // White noise: both errors estimate σ/√n (the tile one within its sampling spread).
    const LinearImage flat = noisy_image(64, 64, 1, {0.5}, 0.02, 6);
    const auto mask = rasterize(RectangleRegion{0, 0, 64, 64}, 64, 64);
    const RegionStatistics f = region_statistics(flat, mask);
    EXPECT_GE(f.average.tiles, 16U);
    EXPECT_NEAR(f.average.stderr_tiles / f.average.stderr_pixel, 1.0, 0.5);
    // The same noise on a brightness gradient (shading): tile means spread far more than the
    // pixel noise averages down.
    LinearImage shaded = flat;
    for (std::size_t y = 0; y < 64; ++y)
        for (std::size_t x = 0; x < 64; ++x)
            shaded.values[y * 64 + x] += static_cast<float>(0.002 * static_cast<double>(x));
    const RegionStatistics g = region_statistics(shaded, mask);
    // (The ratio is at most the tile side, 11 px here: √(n / tiles).)
    EXPECT_GT(g.average.stderr_tiles, 5.0 * g.average.stderr_pixel);
    EXPECT_EQ(g.average.tiles, f.average.tiles);
}

TEST(RegionStatistics, ChosenTileSizeFollowsTheRule) {
    // 4096 used pixels: t0 = ⌊√(4096 / 32)⌋ = 11; 11-px tiles over 64 px: 5 full + one of 9
    // columns (99 ≥ 60.5 pixels: counts) in each direction → 36 tiles ≥ 16.
    const LinearImage image = noisy_image(64, 64, 1, {0.5}, 0.02, 7);
    const auto mask = rasterize(RectangleRegion{0, 0, 64, 64}, 64, 64);
    const RegionStatistics s = region_statistics(image, mask);
    EXPECT_EQ(s.tile_size_px, 11U);
    EXPECT_EQ(s.average.tiles, 36U);
    // A frame 2 px wide around a 128 x 128 image: 1008 pixels, t0 = 5; a 5-px tile holds at most
    // 2 x 5 = 10 < 12.5 of its pixels, so none counts; 4-px tiles hold 8 of 16 and count.
    const LinearImage large = noisy_image(128, 128, 1, {0.5}, 0.02, 7);
    std::vector<std::uint8_t> frame(std::size_t{128} * 128, 1);
    for (std::size_t y = 2; y < 126; ++y)
        for (std::size_t x = 2; x < 126; ++x) frame[y * 128 + x] = 0;
    const RegionStatistics r = region_statistics(large, frame);
    EXPECT_EQ(r.tile_size_px, 4U);
    EXPECT_GE(r.average.tiles, 16U);
    RegionStatisticsOptions five;
    five.tile_size_px = 5;
    EXPECT_LT(region_statistics(large, frame, five).average.tiles, 16U);
    // A region too small for two tiles: stderr_tiles 0 and a warning.
    const auto tiny = rasterize(RectangleRegion{1, 1, 3, 3}, 64, 64);
    const RegionStatistics t = region_statistics(image, tiny);
    EXPECT_LT(t.average.tiles, 2U);
    EXPECT_EQ(t.average.stderr_tiles, 0.0);
    ASSERT_FALSE(t.warnings.empty());
    EXPECT_NE(t.warnings.back().find("stderr_tiles"), std::string::npos);
}

TEST(RegionStatistics, RobustMeanSolvesHuberEquationAndResistsOutliers) {
    LinearImage image = noisy_image(50, 40, 1, {0.3}, 0.01, 8);
    // 5 % hot pixels far above the level.
    for (std::size_t k = 0; k < image.pixel_count(); k += 20) image.values[k] = 0.9F;
    const auto mask = rasterize(RectangleRegion{0, 0, 50, 40}, 50, 40);
    const RegionStatistics s = region_statistics(image, mask);
    const double mu = s.average.robust_mean;
    // Independent scale: 1.4826 · median |v − median|.
    std::vector<double> v = selected(image, 0, mask);
    std::vector<double> sorted = v;
    std::sort(sorted.begin(), sorted.end());
    const double med = 0.5 * (sorted[sorted.size() / 2 - 1] + sorted[sorted.size() / 2]);
    std::vector<double> dev;
    dev.reserve(v.size());
    for (const double x : v) dev.push_back(std::abs(x - med));
    std::sort(dev.begin(), dev.end());
    const double scale = 1.4826 * 0.5 * (dev[dev.size() / 2 - 1] + dev[dev.size() / 2]);
    double psi = 0;
    for (const double x : v) psi += std::clamp((x - mu) / scale, -1.345, 1.345);
    EXPECT_NEAR(psi / static_cast<double>(v.size()), 0.0, 1e-9);
    // The plain mean is pulled up by 0.05 · 0.6 = 0.03; the robust one stays near 0.3.
    EXPECT_NEAR(s.average.mean, 0.33, 0.002);
    EXPECT_NEAR(mu, 0.3, 0.002);
}

TEST(RegionStatistics, RobustMeanOfMostlyEqualValues) {
    // More than half the values equal (MAD = 0): the mean-absolute-deviation scale is used.
    LinearImage image = noisy_image(10, 10, 1, {0.5}, 0.0, 9);
    for (std::size_t k = 0; k < 30; ++k) image.values[k] = 0.5F + 0.01F * static_cast<float>(k % 3);
    const auto mask = rasterize(RectangleRegion{0, 0, 10, 10}, 10, 10);
    const RegionStatistics s = region_statistics(image, mask);
    EXPECT_GE(s.average.robust_mean, 0.5);
    EXPECT_LE(s.average.robust_mean, s.average.mean + 1e-12);
    // All equal: every estimate is the value, every spread 0.
    const LinearImage flat = noisy_image(10, 10, 1, {0.25}, 0.0, 9);
    const RegionStatistics f = region_statistics(flat, mask);
    EXPECT_DOUBLE_EQ(f.average.robust_mean, 0.25);
    EXPECT_EQ(f.average.std_dev, 0.0);
    EXPECT_EQ(f.average.stderr_tiles, 0.0);
}

TEST(RegionStatistics, SpansAndMaskGiveTheSameStatistics) {
    // The spans overload (what measure uses: no mask read) against the mask overload on the same
    // pixels, grey and RGB, with flagged pixels inside and outside the region: the same numbers
    // bit for bit, the same counts and warnings.
    for (const std::size_t channels : {std::size_t{1}, std::size_t{3}}) {
        LinearImage image = noisy_image(61, 47, channels, {0.3, 0.5, 0.7}, 0.02, 21);
        std::mt19937 rng(8);
        for (auto& f : image.flags)
            if (rng() % 50 == 0) f = rng() % 2 == 0 ? kPixelSaturated : kPixelClippedLow;
        for (const Region& region :
             {Region{RectangleRegion{3.0, 2.0, 50.0, 40.0}}, Region{CircleRegion{30, 22, 19.5}}}) {
            const RegionStatistics a = region_statistics(image, rasterize(region, 61, 47));
            const RegionStatistics b = region_statistics(image, region_spans(region, 61, 47));
            EXPECT_EQ(a.pixels_in_region, b.pixels_in_region);
            EXPECT_EQ(a.pixels_used, b.pixels_used);
            EXPECT_EQ(a.pixels_saturated, b.pixels_saturated);
            EXPECT_EQ(a.pixels_clipped_low, b.pixels_clipped_low);
            EXPECT_EQ(a.tile_size_px, b.tile_size_px);
            EXPECT_EQ(a.warnings, b.warnings);
            ASSERT_EQ(a.channels.size(), b.channels.size());
            for (std::size_t c = 0; c < a.channels.size(); ++c) {
                EXPECT_EQ(a.channels[c].mean, b.channels[c].mean);
                EXPECT_EQ(a.channels[c].robust_mean, b.channels[c].robust_mean);
                EXPECT_EQ(a.channels[c].std_dev, b.channels[c].std_dev);
                EXPECT_EQ(a.channels[c].stderr_tiles, b.channels[c].stderr_tiles);
            }
            EXPECT_EQ(a.average.mean, b.average.mean);
            EXPECT_GT(a.pixels_saturated + a.pixels_clipped_low, 0U);
        }
    }
    // Spans of an image of another size are refused.
    const LinearImage image = noisy_image(8, 8, 1, {0.5}, 0.01, 10);
    EXPECT_THROW((void)region_statistics(image, region_spans(RectangleRegion{0, 0, 4, 4}, 9, 8)),
                 InvalidArgument);
}

TEST(RegionStatistics, InvalidInputs) {
    const LinearImage image = noisy_image(8, 8, 1, {0.5}, 0.01, 10);
    const auto mask = rasterize(RectangleRegion{0, 0, 4, 4}, 8, 8);
    EXPECT_THROW((void)region_statistics(image, std::vector<std::uint8_t>(63, 1)), InvalidArgument);
    EXPECT_THROW((void)region_statistics(image, std::vector<std::uint8_t>(64, 0)), InvalidArgument);
    LinearImage broken = image;
    broken.flags.pop_back();
    EXPECT_THROW((void)region_statistics(broken, mask), InvalidArgument);
    for (const double bad : {-0.1, 1.5, std::nan("")}) {
        RegionStatisticsOptions o;
        o.max_excluded_fraction = bad;
        EXPECT_THROW(check_region_statistics_options(o), InvalidArgument);
        EXPECT_THROW((void)region_statistics(image, mask, o), InvalidArgument);
        o = {};
        o.warn_excluded_fraction = bad;
        EXPECT_THROW(check_region_statistics_options(o), InvalidArgument);
    }
    EXPECT_NO_THROW(check_region_statistics_options({}));
    EXPECT_NO_THROW((void)region_statistics(image, mask));
}

}  // namespace
}  // namespace roughscope::image

namespace roughscope::image {
namespace {

// Above 2^20 used pixels the robust mean comes from a regular subsample: on symmetric noise it
// still estimates the centre (within 5 standard errors of the subsample, ~2^-10 of the noise),
// and a contamination of 5 % large outliers moves the mean but hardly the robust mean.
TEST(RegionStatistics, LargeRegionsGetARobustMeanFromASubsample) {
    LinearImage image = noisy_image(1600, 800, 3, {0.3, 0.5, 0.7}, 0.01, 9);           // 1.28 MP
    for (std::size_t k = 0; k < image.pixel_count(); k += 20) image.values[k] = 0.9F;  // R only
    const std::vector<std::uint8_t> mask(image.pixel_count(), 1);
    const RegionStatistics s = region_statistics(image, mask);
    const double tolerance = 5.0 * 0.01 / std::sqrt(static_cast<double>(1u << 19));
    EXPECT_NEAR(s.channels[1].robust_mean, 0.5, tolerance);
    EXPECT_NEAR(s.channels[2].robust_mean, 0.7, tolerance);
    EXPECT_GT(s.channels[0].mean - 0.3, 0.02);                    // the outliers pull the mean
    EXPECT_LT(std::abs(s.channels[0].robust_mean - 0.3), 0.002);  // not the robust mean
    EXPECT_EQ(s.channels[0].count, image.pixel_count());
}

}  // namespace
}  // namespace roughscope::image

namespace roughscope::image {
namespace {

// A non-finite value is an error where it would be averaged in (a used pixel of any plane) and
// is ignored where it is not (outside the region, or flagged): the values are checked where they
// are read.
TEST(RegionStatistics, NonFiniteValuesAreRefusedOnlyWhereTheyAreUsed) {
    const LinearImage image = noisy_image(32, 32, 3, {0.2, 0.5, 0.8}, 0.01, 11);
    const auto mask = rasterize(RectangleRegion{4, 4, 20, 20}, 32, 32);
    const RegionStatistics clean = region_statistics(image, mask);
    const std::size_t plane = image.pixel_count();
    for (const float bad :
         {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
          -std::numeric_limits<float>::infinity()}) {
        for (const std::size_t c : {0U, 2U}) {
            LinearImage used = image;
            used.values[c * plane + 10 * 32 + 10] = bad;  // inside the region
            try {
                (void)region_statistics(used, mask);
                ADD_FAILURE() << "non-finite value accepted in plane " << c;
            } catch (const InvalidArgument& e) {
                const std::string what = e.what();
                EXPECT_NE(what.find("synthetic.tif"), std::string::npos) << what;
                EXPECT_NE(what.find(concat("at sample ", std::to_string(c * plane + 330))),
                          std::string::npos)
                    << what;
                EXPECT_NE(what.find("is not finite"), std::string::npos) << what;
            }
            LinearImage unused = image;
            unused.values[c * plane + 1] = bad;  // outside the region
            unused.values[c * plane + 12 * 32 + 12] = bad;
            unused.flags[12 * 32 + 12] = kPixelSaturated;  // inside, but flagged
            RegionStatistics s = region_statistics(unused, mask);
            EXPECT_EQ(s.pixels_used + 1, clean.pixels_used);
            EXPECT_TRUE(std::isfinite(s.channels[c].mean));
            EXPECT_TRUE(std::isfinite(s.average.std_dev));
        }
    }
}

// The robust means of a large region (more than 2^20 used pixels, runs of many lengths) are the
// Huber estimates of exactly the subsample the documentation names: every ⌈n / 2^20⌉-th used
// pixel in scan order, per plane and for the per-pixel average (rounded to float).
TEST(RegionStatistics, TheRobustSubsampleIsEveryStrideThUsedPixel) {
    LinearImage image = noisy_image(1300, 1300, 3, {0.3, 0.5, 0.7}, 0.02, 12);
    for (std::size_t k = 0; k < image.pixel_count(); k += 97) image.flags[k] = kPixelSaturated;
    const auto mask = rasterize(CircleRegion{650, 650, 640}, 1300, 1300);
    const RegionStatistics s = region_statistics(image, mask);
    const std::size_t n = s.pixels_used;
    ASSERT_GT(n, std::size_t{1} << 20);
    const std::size_t stride = (n + (std::size_t{1} << 20) - 1) >> 20;
    ASSERT_GE(stride, 2U);
    std::vector<std::vector<float>> sample(4);
    std::size_t index = 0;
    for (std::size_t k = 0; k < image.pixel_count(); ++k) {
        if (mask[k] == 0 || image.flags[k] != 0) continue;
        if (index++ % stride != 0) continue;
        double sum = 0.0;
        for (std::size_t c = 0; c < 3; ++c) {
            sample[c].push_back(image.plane(c)[k]);
            sum += image.plane(c)[k];
        }
        sample[3].push_back(static_cast<float>(sum / 3.0));
    }
    for (std::size_t c = 0; c < 3; ++c)
        EXPECT_EQ(s.channels[c].robust_mean,
                  huber_location(std::span<const float>(sample[c])).location)
            << c;
    EXPECT_EQ(s.average.robust_mean, huber_location(std::span<const float>(sample[3])).location);
    // And the moments over all used pixels, against the direct two-pass sums.
    for (std::size_t c = 0; c < 3; ++c) {
        std::vector<double> v;
        for (std::size_t k = 0; k < image.pixel_count(); ++k)
            if (mask[k] != 0 && image.flags[k] == 0) v.push_back(image.plane(c)[k]);
        expect_matches(s.channels[c], v);
    }
}

}  // namespace
}  // namespace roughscope::image
