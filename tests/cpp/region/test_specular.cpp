// The specular highlight measurement (image/specular.hpp) on synthetic Gaussian spots over a flat
// diffuse level with seeded noise: the centre, the width, E_tot and E_dif against the noise-free
// model averaged over the same pixels; given radii and centre; saturated cores; failures.
#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/region/region.hpp"
#include "roughscope/region/specular.hpp"

namespace roughscope::image {
namespace {

struct Spot {
    double cx = 47.3, cy = 50.8, sigma = 3.0, amplitude = 0.6, diffuse = 0.2;
    // The noise-free brightness at a point (pixel centres are (i + ½, j + ½)).
    double at(double x, double y) const {
        const double r2 = (x - cx) * (x - cx) + (y - cy) * (y - cy);
        return diffuse + amplitude * std::exp(-r2 / (2.0 * sigma * sigma));
    }
    double hwhm() const { return sigma * std::sqrt(2.0 * std::log(2.0)); }
};

constexpr std::size_t kSize = 96;

// Channel c holds gains[c] · spot + noise; values ≥ clip are set to clip and flagged saturated.
LinearImage spot_image(const Spot& spot, double noise, unsigned seed,
                       const std::vector<double>& gains = {1.0}, double clip = HUGE_VAL) {
    LinearImage image;
    image.width = kSize;
    image.height = kSize;
    image.channels = gains.size();
    image.values.resize(gains.size() * kSize * kSize);
    image.flags.assign(kSize * kSize, 0);
    image.info.source = "highlight.png";
    std::mt19937 rng(seed);
    std::normal_distribution<double> n(0.0, noise > 0.0 ? noise : 1.0);
    for (std::size_t c = 0; c < gains.size(); ++c)
        for (std::size_t y = 0; y < kSize; ++y)
            for (std::size_t x = 0; x < kSize; ++x) {
                double v =
                    gains[c] * spot.at(static_cast<double>(x) + 0.5, static_cast<double>(y) + 0.5);
                if (noise > 0.0) v += n(rng);
                if (v >= clip) {
                    v = clip;
                    image.flags[y * kSize + x] = kPixelSaturated;
                }
                image.values[(c * kSize + y) * kSize + x] = static_cast<float>(v);
            }
    return image;
}

std::vector<std::uint8_t> whole() {
    return rasterize(RectangleRegion{0, 0, kSize, kSize}, kSize, kSize);
}

// The noise-free model (channel average of gains · spot) averaged over the pixels whose centres
// lie at distance (lo, hi] (lo < 0: [0, hi]) from (cx, cy), unflagged, inside `region`.
struct Truth {
    double mean;
    std::size_t pixels;
};
Truth model_mean(const Spot& spot, const LinearImage& image,
                 const std::vector<std::uint8_t>& region, double cx, double cy, double lo,
                 double hi, double gain = 1.0) {
    double sum = 0;
    std::size_t n = 0;
    for (std::size_t y = 0; y < kSize; ++y)
        for (std::size_t x = 0; x < kSize; ++x) {
            const double px = static_cast<double>(x) + 0.5, py = static_cast<double>(y) + 0.5;
            const double d = std::hypot(px - cx, py - cy);
            if (!region[y * kSize + x] || image.flags[y * kSize + x] || d > hi || d <= lo) continue;
            sum += gain * spot.at(px, py);
            ++n;
        }
    return {sum / static_cast<double>(n), n};
}

std::string error_of(const LinearImage& image, const std::vector<std::uint8_t>& mask,
                     const HighlightOptions& options = {}) {
    try {
        (void)measure_highlight(image, mask, options);
    } catch (const InvalidArgument& e) {
        return e.what();
    }
    return "(no error)";
}

TEST(Highlight, GaussianSpotCentreWidthAndLevels) {
    const Spot spot;
    const double noise = 0.005;
    const LinearImage image = spot_image(spot, noise, 21);
    const auto region = whole();
    const HighlightMeasurement m = measure_highlight(image, region);
    EXPECT_NEAR(m.centre_x_px, spot.cx, 0.5);
    EXPECT_NEAR(m.centre_y_px, spot.cy, 0.5);
    EXPECT_NEAR(m.width_px, spot.hwhm(), 0.1 * spot.hwhm());
    // The documented radii rule from the measured width.
    EXPECT_DOUBLE_EQ(m.core_radius_px, std::max(1.5, m.width_px / 4));
    EXPECT_DOUBLE_EQ(m.annulus_inner_px, std::max(3 * m.width_px, m.core_radius_px + 2));
    EXPECT_DOUBLE_EQ(m.annulus_outer_px, std::max(4 * m.width_px, m.annulus_inner_px + 3));

    const Truth core =
        model_mean(spot, image, region, m.centre_x_px, m.centre_y_px, -1, m.core_radius_px);
    const Truth annulus = model_mean(spot, image, region, m.centre_x_px, m.centre_y_px,
                                     m.annulus_inner_px, m.annulus_outer_px);
    EXPECT_EQ(m.core.pixels_used, core.pixels);
    EXPECT_EQ(m.annulus.pixels_used, annulus.pixels);
    EXPECT_NEAR(m.E_tot, core.mean, 3.0 * m.E_tot_relative_stderr * m.E_tot);
    EXPECT_NEAR(m.E_dif, annulus.mean, 3.0 * m.E_dif_relative_stderr * m.E_dif);
    // Tighter: only the pixel noise separates them.
    EXPECT_NEAR(m.E_tot, core.mean, 4.0 * noise / std::sqrt(static_cast<double>(core.pixels)));
    EXPECT_NEAR(m.E_dif, annulus.mean,
                4.0 * noise / std::sqrt(static_cast<double>(annulus.pixels)));
    EXPECT_NEAR(m.E_dif, spot.diffuse, 0.002);
    EXPECT_GT(m.E_tot, spot.diffuse + 0.9 * spot.amplitude);
    EXPECT_EQ(m.E_tot, m.core.average.mean);
    EXPECT_DOUBLE_EQ(
        m.E_dif_relative_stderr,
        std::max(m.annulus.average.stderr_pixel, m.annulus.average.stderr_tiles) / m.E_dif);
    // Nothing flagged, the annulus whole, and the core's "too few tiles" is not passed on.
    EXPECT_TRUE(m.warnings.empty()) << m.warnings.front();
    EXPECT_FALSE(m.core.warnings.empty());
    EXPECT_TRUE(m.annulus.warnings.empty());
}

TEST(Highlight, WiderSpotAndNoSmoothing) {
    Spot spot;
    spot.sigma = 5.0;
    spot.cx = 40.9;
    spot.cy = 44.1;
    const LinearImage image = spot_image(spot, 0.001, 22);
    HighlightOptions options;
    options.smoothing_sigma_px = 0.0;
    const HighlightMeasurement m = measure_highlight(image, whole(), options);
    EXPECT_NEAR(m.centre_x_px, spot.cx, 0.5);
    EXPECT_NEAR(m.centre_y_px, spot.cy, 0.5);
    EXPECT_NEAR(m.width_px, spot.hwhm(), 0.1 * spot.hwhm());
    EXPECT_NEAR(m.E_dif, spot.diffuse, 0.002);
}

TEST(Highlight, GivenRadiiAndCentreAreHonoured) {
    const Spot spot;
    const LinearImage image = spot_image(spot, 0.005, 23);
    const auto region = whole();
    HighlightOptions options;
    options.core_radius_px = 3.0;
    options.annulus_inner_px = 12.0;
    options.annulus_outer_px = 20.0;
    options.centre_px = std::array<double, 2>{spot.cx, spot.cy};
    const HighlightMeasurement m = measure_highlight(image, region, options);
    EXPECT_EQ(m.centre_x_px, spot.cx);
    EXPECT_EQ(m.centre_y_px, spot.cy);
    EXPECT_EQ(m.core_radius_px, 3.0);
    EXPECT_EQ(m.annulus_inner_px, 12.0);
    EXPECT_EQ(m.annulus_outer_px, 20.0);
    const Truth core = model_mean(spot, image, region, spot.cx, spot.cy, -1, 3.0);
    const Truth annulus = model_mean(spot, image, region, spot.cx, spot.cy, 12.0, 20.0);
    EXPECT_EQ(m.core.pixels_in_region, core.pixels);
    EXPECT_EQ(m.annulus.pixels_in_region, annulus.pixels);
    EXPECT_NEAR(m.E_tot, core.mean, 3.0 * m.E_tot_relative_stderr * m.E_tot);
    EXPECT_NEAR(m.E_dif, annulus.mean, 3.0 * m.E_dif_relative_stderr * m.E_dif);
    // The width is still measured.
    EXPECT_NEAR(m.width_px, spot.hwhm(), 0.1 * spot.hwhm());
}

TEST(Highlight, RgbUsesTheChannelAverage) {
    const Spot spot;
    const std::vector<double> gains = {0.5, 1.0, 1.5};
    const LinearImage image = spot_image(spot, 0.004, 24, gains);
    const auto region = whole();
    const HighlightMeasurement m = measure_highlight(image, region);
    EXPECT_NEAR(m.centre_x_px, spot.cx, 0.5);
    EXPECT_NEAR(m.centre_y_px, spot.cy, 0.5);
    ASSERT_EQ(m.core.channels.size(), 3U);
    EXPECT_NEAR(m.E_tot,
                (m.core.channels[0].mean + m.core.channels[1].mean + m.core.channels[2].mean) / 3,
                1e-12);
    // The average of gains 0.5, 1, 1.5 is the spot itself.
    const Truth core =
        model_mean(spot, image, region, m.centre_x_px, m.centre_y_px, -1, m.core_radius_px);
    EXPECT_NEAR(m.E_tot, core.mean, 3.0 * m.E_tot_relative_stderr * m.E_tot);
    const Truth red = model_mean(spot, image, region, m.centre_x_px, m.centre_y_px,
                                 m.annulus_inner_px, m.annulus_outer_px, 0.5);
    EXPECT_NEAR(m.annulus.channels[0].mean, red.mean, 0.002);
}

TEST(Highlight, SaturatedCoreLocatesButNeverEntersTheStatistics) {
    Spot spot;
    spot.amplitude = 1.5;  // saturated (at 1) within r ≈ 3.4 px
    const LinearImage image = spot_image(spot, 0.004, 25, {1.0}, 1.0);
    const auto region = whole();
    // The default core (small) is all saturated.
    const std::string message = error_of(image, region);
    EXPECT_NE(message.find("mostly saturated"), std::string::npos) << message;
    EXPECT_NE(message.find("highlight core"), std::string::npos) << message;
    // A core of 6 px is about one third saturated: measured, with a warning.
    HighlightOptions options;
    options.core_radius_px = 6.0;
    const HighlightMeasurement m = measure_highlight(image, region, options);
    EXPECT_NEAR(m.centre_x_px, spot.cx, 0.5);
    EXPECT_NEAR(m.centre_y_px, spot.cy, 0.5);
    std::size_t saturated = 0, in_core = 0;
    for (std::size_t y = 0; y < kSize; ++y)
        for (std::size_t x = 0; x < kSize; ++x)
            if (std::hypot(static_cast<double>(x) + 0.5 - m.centre_x_px,
                           static_cast<double>(y) + 0.5 - m.centre_y_px) <= 6.0) {
                ++in_core;
                saturated += image.flags[y * kSize + x] != 0 ? 1 : 0;
            }
    EXPECT_GT(saturated, 0U);
    EXPECT_EQ(m.core.pixels_saturated, saturated);
    EXPECT_EQ(m.core.pixels_used, in_core - saturated);
    EXPECT_LT(m.E_tot, 1.0);  // only unsaturated pixels averaged
    const Truth core = model_mean(spot, image, region, m.centre_x_px, m.centre_y_px, -1, 6.0);
    EXPECT_NEAR(m.E_tot, core.mean, 3.0 * m.E_tot_relative_stderr * m.E_tot);
    bool warned = false;
    for (const auto& w : m.warnings) warned = warned || w.find("saturated") != std::string::npos;
    EXPECT_TRUE(warned);
}

TEST(Highlight, AnnulusCutByTheRegionIsWarnedAbout) {
    const Spot spot;
    const LinearImage image = spot_image(spot, 0.005, 26);
    // Annulus ≈ 10.6..14.1 px; the region (radius 12) keeps its inner part only.
    const auto region = rasterize(CircleRegion{spot.cx, spot.cy, 12.0}, kSize, kSize);
    const HighlightMeasurement m = measure_highlight(image, region);
    const Truth annulus = model_mean(spot, image, region, m.centre_x_px, m.centre_y_px,
                                     m.annulus_inner_px, m.annulus_outer_px);
    EXPECT_EQ(m.annulus.pixels_used, annulus.pixels);
    ASSERT_FALSE(m.warnings.empty());
    EXPECT_NE(m.warnings.front().find("lie in the region"), std::string::npos)
        << m.warnings.front();
}

TEST(Highlight, FailuresAreInvalidArguments) {
    const Spot spot;
    const LinearImage image = spot_image(spot, 0.005, 27);
    // A region that cuts through the highlight: its brightest pixel is on its border.
    const auto cut =
        rasterize(RectangleRegion{spot.cx + 2, 0, kSize - spot.cx - 2, kSize}, kSize, kSize);
    EXPECT_NE(error_of(image, cut).find("border"), std::string::npos) << error_of(image, cut);
    // A region too small for the annulus.
    const auto small = rasterize(CircleRegion{spot.cx, spot.cy, 8.0}, kSize, kSize);
    EXPECT_NE(error_of(image, small).find("annulus"), std::string::npos) << error_of(image, small);
    // A flat image: the maximum is at the region's corner; with a given centre, no highlight.
    const LinearImage flat = spot_image(Spot{0, 0, 1, 0, 0.3}, 0.0, 28);
    EXPECT_NE(error_of(flat, whole()).find("border"), std::string::npos);
    HighlightOptions at_centre;
    at_centre.centre_px = std::array<double, 2>{48, 48};
    EXPECT_NE(error_of(flat, whole(), at_centre).find("no highlight"), std::string::npos)
        << error_of(flat, whole(), at_centre);
    // A given centre outside the image.
    HighlightOptions outside;
    outside.centre_px = std::array<double, 2>{-1, 40};
    EXPECT_THROW((void)measure_highlight(image, whole(), outside), InvalidArgument);
    // Mask size and empty mask.
    EXPECT_THROW((void)measure_highlight(image, std::vector<std::uint8_t>(10, 1)), InvalidArgument);
    EXPECT_THROW((void)measure_highlight(image, std::vector<std::uint8_t>(kSize * kSize, 0)),
                 InvalidArgument);
    // A given inner radius below the chosen core.
    HighlightOptions inverted;
    inverted.annulus_inner_px = 1.0;
    EXPECT_THROW((void)measure_highlight(image, whole(), inverted), InvalidArgument);
    // The same image and region succeed with valid options.
    EXPECT_NO_THROW((void)measure_highlight(image, whole()));
}

TEST(Highlight, InvalidOptions) {
    const auto bad = [](auto edit) {
        HighlightOptions o;
        edit(o);
        EXPECT_THROW(check_highlight_options(o), InvalidArgument);
    };
    bad([](HighlightOptions& o) { o.smoothing_sigma_px = -1; });
    bad([](HighlightOptions& o) { o.smoothing_sigma_px = NAN; });
    bad([](HighlightOptions& o) { o.core_radius_px = 0.0; });
    bad([](HighlightOptions& o) { o.annulus_outer_px = -3.0; });
    bad([](HighlightOptions& o) { o.annulus_inner_px = INFINITY; });
    bad([](HighlightOptions& o) {
        o.core_radius_px = 5.0;
        o.annulus_inner_px = 4.0;
    });
    bad([](HighlightOptions& o) {
        o.annulus_inner_px = 8.0;
        o.annulus_outer_px = 8.0;
    });
    bad([](HighlightOptions& o) {
        o.core_radius_px = 8.0;
        o.annulus_outer_px = 6.0;
    });
    bad([](HighlightOptions& o) { o.centre_px = std::array<double, 2>{NAN, 1}; });
    bad([](HighlightOptions& o) { o.statistics.max_excluded_fraction = 2; });
    HighlightOptions good;
    good.core_radius_px = 2.0;
    good.annulus_inner_px = 2.0;
    good.annulus_outer_px = 9.0;
    good.smoothing_sigma_px = 0.0;
    EXPECT_NO_THROW(check_highlight_options(good));
}

}  // namespace
}  // namespace roughscope::image
