// Regions (image/region.hpp): rasterisation against brute-force point-in-shape tests on the
// pixel centres (i + ½, j + ½) and against analytic areas; malformed, outside and empty regions.
#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/region/region.hpp"

namespace roughscope::image {
namespace {

using Vertices = std::vector<std::array<double, 2>>;

// Brute force: test every pixel centre with `inside(x, y)`.
template <class Inside>
std::vector<std::uint8_t> brute_force(std::size_t width, std::size_t height, Inside inside) {
    std::vector<std::uint8_t> mask(width * height, 0);
    for (std::size_t j = 0; j < height; ++j)
        for (std::size_t i = 0; i < width; ++i)
            mask[j * width + i] =
                inside(static_cast<double>(i) + 0.5, static_cast<double>(j) + 0.5) ? 1 : 0;
    return mask;
}

std::size_t count(const std::vector<std::uint8_t>& mask) {
    std::size_t n = 0;
    for (const auto b : mask) n += b != 0 ? 1 : 0;
    return n;
}

// Point in polygon by the crossing number (W. R. Franklin's PNPOLY), one point at a time.
bool pnpoly(const Vertices& v, double x, double y) {
    bool in = false;
    for (std::size_t i = 0, j = v.size() - 1; i < v.size(); j = i++)
        if (((v[i][1] > y) != (v[j][1] > y)) &&
            (x < (v[j][0] - v[i][0]) * (y - v[i][1]) / (v[j][1] - v[i][1]) + v[i][0]))
            in = !in;
    return in;
}

double shoelace_area(const Vertices& v) {
    double twice = 0.0;
    for (std::size_t i = 0, j = v.size() - 1; i < v.size(); j = i++)
        twice += v[j][0] * v[i][1] - v[i][0] * v[j][1];
    return std::abs(twice) / 2.0;
}

double perimeter(const Vertices& v) {
    double p = 0.0;
    for (std::size_t i = 0, j = v.size() - 1; i < v.size(); j = i++)
        p += std::hypot(v[i][0] - v[j][0], v[i][1] - v[j][1]);
    return p;
}

std::string message_of(const Region& region, std::size_t width, std::size_t height) {
    try {
        (void)rasterize(region, width, height);
    } catch (const InvalidArgument& e) {
        return e.what();
    }
    return "(no error)";
}

TEST(Region, IntegerRectangleHoldsExactlyItsPixels) {
    const auto mask = rasterize(RectangleRegion{2, 3, 4, 5}, 10, 12);
    for (std::size_t j = 0; j < 12; ++j)
        for (std::size_t i = 0; i < 10; ++i)
            EXPECT_EQ(mask[j * 10 + i], (i >= 2 && i <= 5 && j >= 3 && j <= 7) ? 1 : 0)
                << i << ", " << j;
    EXPECT_EQ(count(rasterize(RectangleRegion{0, 0, 10, 12}, 10, 12)), 120U);
}

TEST(Region, RectanglesMatchBruteForce) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int trial = 0; trial < 50; ++trial) {
        const double x = 30.0 * u(rng), y = 20.0 * u(rng);
        const double w = 0.6 + (40.0 - x - 0.6) * u(rng), h = 0.6 + (25.0 - y - 0.6) * u(rng);
        const auto expected = brute_force(40, 25, [&](double cx, double cy) {
            return x <= cx && cx < x + w && y <= cy && cy < y + h;
        });
        if (count(expected) == 0) continue;
        EXPECT_EQ(rasterize(RectangleRegion{x, y, w, h}, 40, 25), expected)
            << describe(RectangleRegion{x, y, w, h});
    }
}

TEST(Region, CirclesMatchBruteForceAndArea) {
    std::mt19937 rng(12);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int trial = 0; trial < 40; ++trial) {
        const double r = 1.0 + 25.0 * u(rng);
        const double cx = r + (80.0 - 2 * r) * u(rng), cy = r + (60.0 - 2 * r) * u(rng);
        const auto mask = rasterize(CircleRegion{cx, cy, r}, 80, 60);
        EXPECT_EQ(mask,
                  brute_force(80, 60,
                              [&](double x, double y) { return std::hypot(x - cx, y - cy) <= r; }))
            << describe(CircleRegion{cx, cy, r});
        EXPECT_NEAR(static_cast<double>(count(mask)), std::numbers::pi * r * r,
                    2.0 * std::numbers::pi * r);
    }
    // Centred on pixel (10, 10): radius 1 holds it and its four neighbours (distance exactly 1).
    EXPECT_EQ(count(rasterize(CircleRegion{10.5, 10.5, 1.0}, 20, 20)), 5U);
    // A circle touching the image edges is inside the image.
    EXPECT_EQ(count(rasterize(CircleRegion{10, 10, 10}, 20, 20)),
              count(brute_force(
                  20, 20, [](double x, double y) { return std::hypot(x - 10, y - 10) <= 10; })));
}

TEST(Region, PolygonsMatchCrossingNumberAndArea) {
    const std::vector<Vertices> polygons = {
        {{1, 1}, {30, 4}, {12, 27}},                                       // triangle
        {{2.2, 3.1}, {35.7, 2.9}, {38.1, 28.4}, {20.5, 18}, {4.4, 29.9}},  // concave
        {{20, 2}, {25, 28}, {3, 10}, {37, 10}, {15, 28}},                  // self-intersecting star
        {{0, 0}, {40, 0}, {40, 30}, {0, 30}},                              // the whole image
    };
    for (const Vertices& v : polygons) {
        const auto mask = rasterize(PolygonRegion{v}, 40, 30);
        EXPECT_EQ(mask, brute_force(40, 30, [&](double x, double y) { return pnpoly(v, x, y); }))
            << describe(PolygonRegion{v});
    }
    // Simple polygons: the pixel count is the area within a perimeter-sized tolerance.
    for (std::size_t k : {0U, 1U, 3U}) {
        const auto mask = rasterize(PolygonRegion{polygons[k]}, 40, 30);
        EXPECT_NEAR(static_cast<double>(count(mask)), shoelace_area(polygons[k]),
                    perimeter(polygons[k]) / 2.0);
    }
    // Even-odd: the star's centre pentagon is outside.
    const auto star = rasterize(PolygonRegion{polygons[2]}, 40, 30);
    EXPECT_EQ(star[14 * 40 + 20], 0);
    EXPECT_EQ(star[9 * 40 + 20], 1);
    EXPECT_EQ(count(rasterize(PolygonRegion{polygons[3]}, 40, 30)), 1200U);
}

TEST(Region, PolygonsSharingAnEdgeShareNoPixel) {
    // A rectangle cut along a slanted line through pixel centres (x = 12.5 − (y − 1.5) / 2;
    // dyadic numbers, so both parts compute the same crossings): every pixel of the whole is in
    // exactly one part.
    const Vertices whole = {{1, 1}, {21, 1}, {21, 17}, {1, 17}};
    const Vertices left = {{1, 1}, {12.75, 1}, {4.75, 17}, {1, 17}};
    const Vertices right = {{12.75, 1}, {21, 1}, {21, 17}, {4.75, 17}};
    const auto a = rasterize(PolygonRegion{left}, 24, 20);
    const auto b = rasterize(PolygonRegion{right}, 24, 20);
    const auto all = rasterize(PolygonRegion{whole}, 24, 20);
    for (std::size_t k = 0; k < all.size(); ++k) {
        EXPECT_EQ(a[k] + b[k], all[k]) << k;
    }
    EXPECT_EQ(count(all), 20U * 16U);
}

TEST(Region, MasksAreCopiedAsZeroOrOne) {
    MaskRegion m{3, 2, {0, 7, 0, 255, 0, 1}};
    EXPECT_EQ(rasterize(m, 3, 2), (std::vector<std::uint8_t>{0, 1, 0, 1, 0, 1}));
    EXPECT_EQ(describe(m), "mask [3 x 2, 3 pixels in]");
    EXPECT_THROW((void)rasterize(m, 2, 3), InvalidArgument);
    EXPECT_NE(message_of(m, 4, 2).find("4 x 2"), std::string::npos);
    EXPECT_THROW((void)rasterize(MaskRegion{3, 2, std::vector<std::uint8_t>(6, 0)}, 3, 2),
                 InvalidArgument);
}

TEST(Region, RegionsReachingOutsideTheImageAreInvalid) {
    EXPECT_THROW((void)rasterize(RectangleRegion{-1, 0, 3, 3}, 10, 12), InvalidArgument);
    EXPECT_THROW((void)rasterize(RectangleRegion{8, 0, 3, 3}, 10, 12), InvalidArgument);
    EXPECT_THROW((void)rasterize(RectangleRegion{0, 10, 3, 2.5}, 10, 12), InvalidArgument);
    EXPECT_THROW((void)rasterize(CircleRegion{5, 5, 5.1}, 10, 12), InvalidArgument);
    EXPECT_THROW((void)rasterize(CircleRegion{5, 11, 2}, 10, 12), InvalidArgument);
    EXPECT_THROW((void)rasterize(PolygonRegion{{{1, 1}, {10.5, 2}, {3, 9}}}, 10, 12),
                 InvalidArgument);
    const std::string message = message_of(CircleRegion{5, 11, 2}, 10, 12);
    EXPECT_NE(message.find("circle [5, 11, 2]"), std::string::npos) << message;
    EXPECT_NE(message.find("10 x 12"), std::string::npos) << message;
    // The same shapes inside succeed.
    EXPECT_EQ(count(rasterize(RectangleRegion{7, 9, 3, 3}, 10, 12)), 9U);
    EXPECT_GT(count(rasterize(CircleRegion{5, 5, 5}, 10, 12)), 0U);
}

TEST(Region, MalformedAndEmptyRegionsAreInvalid) {
    EXPECT_THROW(check_region(RectangleRegion{0, 0, -1, 2}), InvalidArgument);
    EXPECT_THROW(check_region(RectangleRegion{0, 0, 0, 2}), InvalidArgument);
    EXPECT_THROW(check_region(RectangleRegion{NAN, 0, 1, 2}), InvalidArgument);
    EXPECT_THROW(check_region(CircleRegion{1, 1, -2}), InvalidArgument);
    EXPECT_THROW(check_region(CircleRegion{1, INFINITY, 2}), InvalidArgument);
    EXPECT_THROW(check_region(PolygonRegion{{{0, 0}, {1, 1}}}), InvalidArgument);
    EXPECT_THROW(check_region(PolygonRegion{{{0, 0}, {1, 1}, {NAN, 2}}}), InvalidArgument);
    EXPECT_THROW(check_region(MaskRegion{2, 2, {1, 1, 1}}), InvalidArgument);
    EXPECT_THROW(check_region(MaskRegion{0, 0, {}}), InvalidArgument);
    EXPECT_NO_THROW(check_region(RectangleRegion{0, 0, 1, 2}));
    EXPECT_NO_THROW(check_region(PolygonRegion{{{0, 0}, {1, 1}, {0, 2}}}));
    // Well formed but holding no pixel centre.
    EXPECT_THROW((void)rasterize(CircleRegion{1, 1, 0.3}, 4, 4), InvalidArgument);
    EXPECT_THROW((void)rasterize(RectangleRegion{1.6, 1, 0.8, 2}, 4, 4), InvalidArgument);
    EXPECT_THROW((void)rasterize(PolygonRegion{{{0, 0}, {2, 2}, {4, 4}}}, 4, 4), InvalidArgument);
    EXPECT_NE(message_of(CircleRegion{1, 1, 0.3}, 4, 4).find("no pixel"), std::string::npos);
    EXPECT_THROW((void)rasterize(RectangleRegion{0, 0, 1, 1}, 0, 4), InvalidArgument);
    // The nearby region that does hold a centre.
    EXPECT_EQ(count(rasterize(CircleRegion{1, 1, 0.75}, 4, 4)), 4U);
}

TEST(Region, DescriptionsNameTheShape) {
    EXPECT_EQ(describe(RectangleRegion{1, 2.5, 3, 4}), "rect [1, 2.5, 3, 4]");
    EXPECT_EQ(describe(CircleRegion{10.5, 20, 0.25}), "circle [10.5, 20, 0.25]");
    EXPECT_EQ(describe(PolygonRegion{{{0, 0}, {1, 0}, {0, 1}}}),
              "polygon [(0, 0), (1, 0), (0, 1)]");
    Vertices many;
    for (int k = 0; k < 12; ++k) many.push_back({static_cast<double>(k), 1.0});
    const std::string text = describe(PolygonRegion{many});
    EXPECT_NE(text.find("(7, 1), ... (12 vertices)]"), std::string::npos) << text;
    EXPECT_EQ(text.find("(8, 1)"), std::string::npos) << text;
}

LinearImage image_of(std::size_t width, std::size_t height, std::size_t channels,
                     const std::vector<float>& values) {
    LinearImage image;
    image.width = width;
    image.height = height;
    image.channels = channels;
    image.values.assign(values.begin(), values.end());
    image.flags.assign(width * height, 0);
    image.info.source = "mask.png";
    return image;
}

TEST(Region, SpansAreTheMaskRowByRow) {
    // Every shape's spans against its mask (itself checked against brute force above), and the
    // spans of random masks: sorted, disjoint, non-empty, maximal, and back to the same mask.
    const std::size_t w = 37, h = 23;
    const std::vector<Region> shapes = {
        RectangleRegion{2.5, 1.25, 30.0, 20.5}, CircleRegion{18.0, 11.0, 9.7},
        PolygonRegion{{{{1.0, 1.0}}, {{35.0, 4.0}}, {{5.0, 21.0}}, {{30.0, 20.0}}}}};
    std::mt19937 rng(3);
    std::vector<std::vector<std::uint8_t>> masks;
    for (const Region& r : shapes) masks.push_back(rasterize(r, w, h));
    for (int k = 0; k < 20; ++k) {
        std::vector<std::uint8_t> m(w * h);
        std::bernoulli_distribution in(0.1 + 0.04 * k);
        for (auto& b : m) b = in(rng) ? static_cast<std::uint8_t>(1 + rng() % 255) : 0;
        masks.push_back(m);
    }
    for (std::size_t i = 0; i < masks.size(); ++i) {
        const std::vector<std::uint8_t>& m = masks[i];
        const RegionSpans spans =
            i < shapes.size() ? region_spans(shapes[i], w, h) : region_spans(m, w, h);
        EXPECT_EQ(spans.width, w);
        EXPECT_EQ(spans.height, h);
        EXPECT_EQ(spans.pixel_count, count(m)) << i;
        for (std::size_t s = 0; s < spans.spans.size(); ++s) {
            const PixelSpan& p = spans.spans[s];
            ASSERT_LT(p.x_begin, p.x_end);
            ASSERT_LE(p.x_end, w);
            if (s > 0) {
                const PixelSpan& q = spans.spans[s - 1];
                ASSERT_TRUE(q.row < p.row || (q.row == p.row && q.x_end < p.x_begin)) << i;
            }
        }
        std::vector<std::uint8_t> binary(m.size());
        for (std::size_t k = 0; k < m.size(); ++k) binary[k] = m[k] != 0 ? 1 : 0;
        EXPECT_EQ(rasterize(spans), binary) << i;
    }
    EXPECT_THROW((void)region_spans(std::vector<std::uint8_t>(w * h - 1, 1), w, h),
                 InvalidArgument);
    EXPECT_EQ(message_of(CircleRegion{5, 5, 0.1}, 10, 10), [&] {
        try {
            (void)region_spans(CircleRegion{5, 5, 0.1}, 10, 10);
        } catch (const InvalidArgument& e) {
            return std::string(e.what());
        }
        return std::string("(no error)");
    }());
}

TEST(Region, MaskFromImageThresholdsChannelZero) {
    const LinearImage grey = image_of(4, 1, 1, {0.0F, 0.5F, 0.5001F, 1.0F});
    const MaskRegion m = mask_region_from_image(grey);
    EXPECT_EQ(m.width, 4U);
    EXPECT_EQ(m.height, 1U);
    EXPECT_EQ(m.inside, (std::vector<std::uint8_t>{0, 0, 1, 1}));
    // Only channel 0 (red) counts.
    const LinearImage rgb = image_of(2, 1, 3, {1.0F, 0.0F, 0.0F, 1.0F, 0.0F, 1.0F});
    EXPECT_EQ(mask_region_from_image(rgb).inside, (std::vector<std::uint8_t>{1, 0}));
    EXPECT_EQ(rasterize(mask_region_from_image(grey), 4, 1),
              (std::vector<std::uint8_t>{0, 0, 1, 1}));
}

TEST(Region, MaskFromInconsistentImageIsInvalid) {
    LinearImage bad = image_of(4, 1, 1, {0.0F, 0.5F, 1.0F});
    EXPECT_THROW((void)mask_region_from_image(bad), InvalidArgument);
    bad = image_of(2, 1, 1, {0.0F, NAN});
    EXPECT_THROW((void)mask_region_from_image(bad), InvalidArgument);
}

}  // namespace
}  // namespace roughscope::image
