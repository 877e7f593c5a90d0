// Misregistration by phase correlation (image/registration.hpp) against images shifted by a
// known amount: an analytic pattern sampled at shifted positions (sub-pixel exact) and a
// synthetic capture whose regions are moved by whole pixels.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "map_captures.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/maps/registration.hpp"

namespace roughscope::image {
namespace {

// A pattern with detail at every scale the sampling resolves: a sum of Gaussian blobs of 1.2 to 4
// px (fixed seed), sampled at (x − dx, y − dy).
LinearImage blobs(std::size_t w, std::size_t h, double dx, double dy, std::size_t channels = 1) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> ux(0.0, static_cast<double>(w)),
        uy(0.0, static_cast<double>(h)), us(1.2, 4.0), ua(0.2, 1.0);
    struct Blob {
        double x, y, s, a;
    };
    std::vector<Blob> list(600);
    for (auto& b : list) b = {ux(rng), uy(rng), us(rng), ua(rng)};
    LinearImage im;
    im.width = w;
    im.height = h;
    im.channels = channels;
    im.values.assign(channels * w * h, 0.0f);
    im.flags.assign(w * h, 0);
    std::vector<double> v(w * h, 0.1);
    for (const auto& b : list) {
        // Each blob over its ±5 s box (beyond, below 4e-6 of its height).
        const double reach = 5.0 * b.s;
        const auto lo_x = static_cast<std::ptrdiff_t>(std::floor(b.x + dx - reach));
        const auto lo_y = static_cast<std::ptrdiff_t>(std::floor(b.y + dy - reach));
        const auto hi_x = static_cast<std::ptrdiff_t>(std::ceil(b.x + dx + reach));
        const auto hi_y = static_cast<std::ptrdiff_t>(std::ceil(b.y + dy + reach));
        for (std::ptrdiff_t r = std::max<std::ptrdiff_t>(0, lo_y);
             r < std::min<std::ptrdiff_t>(static_cast<std::ptrdiff_t>(h), hi_y); ++r)
            for (std::ptrdiff_t x = std::max<std::ptrdiff_t>(0, lo_x);
                 x < std::min<std::ptrdiff_t>(static_cast<std::ptrdiff_t>(w), hi_x); ++x) {
                const double ex = static_cast<double>(x) - dx - b.x;
                const double ey = static_cast<double>(r) - dy - b.y;
                v[static_cast<std::size_t>(r) * w + static_cast<std::size_t>(x)] +=
                    b.a * std::exp(-(ex * ex + ey * ey) / (2.0 * b.s * b.s));
            }
    }
    for (std::size_t c = 0; c < channels; ++c)
        for (std::size_t i = 0; i < w * h; ++i)
            im.values[c * w * h + i] = static_cast<float>(v[i] * (1.0 + 0.1 * c));
    im.info.source = "blobs";
    return im;
}

TEST(Registration, RecoversKnownShifts) {
    const LinearImage a = blobs(200, 160, 0.0, 0.0);
    for (const auto& [dx, dy] : std::vector<std::pair<double, double>>{
             {0.0, 0.0}, {3.0, -2.0}, {-5.0, 4.0}, {1.25, 0.5}, {-0.4, 2.7}}) {
        const LinearImage b = blobs(200, 160, dx, dy);
        const Registration r = estimate_misregistration(a, b);
        std::printf("shift (%.2f, %.2f): measured (%.3f, %.3f), response %.3f, PSR %.1f\n", dx, dy,
                    r.shift_x_px, r.shift_y_px, r.response, r.peak_to_sidelobe);
        EXPECT_NEAR(r.shift_x_px, dx, 0.1);
        EXPECT_NEAR(r.shift_y_px, dy, 0.1);
        EXPECT_NEAR(r.magnitude_px, std::hypot(dx, dy), 0.1);
        EXPECT_GT(r.peak_to_sidelobe, 20.0);
    }
    // Identical images: exactly no shift, full response.
    const Registration same = estimate_misregistration(a, a);
    EXPECT_NEAR(same.magnitude_px, 0.0, 1e-6);
    EXPECT_GT(same.response, 0.95);
    // Odd sides (no Nyquist column in the half spectrum the upsampling sums over).
    const Registration odd =
        estimate_misregistration(blobs(201, 157, 0.0, 0.0), blobs(201, 157, 1.25, -0.5));
    EXPECT_NEAR(odd.shift_x_px, 1.25, 0.1);
    EXPECT_NEAR(odd.shift_y_px, -0.5, 0.1);
    // RGB: the channel average.
    const Registration rgb =
        estimate_misregistration(blobs(200, 160, 0, 0, 3), blobs(200, 160, 2.0, 1.0, 3));
    EXPECT_NEAR(rgb.shift_x_px, 2.0, 0.1);
    EXPECT_NEAR(rgb.shift_y_px, 1.0, 0.1);
}

TEST(Registration, LargeImagesUseTheCentralCrop) {
    const LinearImage a = blobs(300, 260, 0.0, 0.0);
    const LinearImage b = blobs(300, 260, 2.0, -3.0);
    RegistrationOptions o;
    o.max_side_px = 128;
    const Registration r = estimate_misregistration(a, b, o);
    EXPECT_EQ(r.crop_width_px, 128u);
    EXPECT_EQ(r.crop_height_px, 128u);
    EXPECT_NEAR(r.shift_x_px, 2.0, 0.1);
    EXPECT_NEAR(r.shift_y_px, -3.0, 0.1);
}

// A synthetic capture (two regions of different roughness, lit differently in the two images):
// the region border moved by whole pixels.
TEST(Registration, SyntheticCaptureShiftedByWholePixels) {
    namespace sim = roughscope::simulation;
    const std::size_t W = 128, H = 96;
    auto labels = [&](int sx, int sy) {
        std::vector<std::int32_t> l(W * H);
        for (std::size_t r = 0; r < H; ++r)
            for (std::size_t x = 0; x < W; ++x) {
                const double cx = static_cast<double>(x) - sx - 64.0;
                const double cy = static_cast<double>(r) - sy - 48.0;
                l[r * W + x] = cx * cx + cy * cy < 30.0 * 30.0 ? 1 : 0;
            }
        return l;
    };
    sim::Scene scene;
    scene.width = W;
    scene.height = H;
    const std::vector<sim::SurfaceTruth> truths{roughscope::testing::very_rough_truth(0.3),
                                                roughscope::testing::very_rough_truth(1.5)};
    const auto p = roughscope::testing::render_lit_pair(scene, truths, labels(0, 0), labels(3, -2),
                                                        deg_to_rad(30.0), deg_to_rad(45.0), 5);
    const Registration r = estimate_misregistration(p.a, p.b);
    std::printf("capture shifted by (3, -2): measured (%.3f, %.3f), PSR %.1f\n", r.shift_x_px,
                r.shift_y_px, r.peak_to_sidelobe);
    EXPECT_GT(r.peak_to_sidelobe, 20.0);
    EXPECT_NEAR(r.shift_x_px, 3.0, 0.1);
    EXPECT_NEAR(r.shift_y_px, -2.0, 0.1);
    // Noise only (a uniform surface): a low response.
    const auto u = roughscope::testing::render_lit_pair(scene, {truths[0]}, {}, {},
                                                        deg_to_rad(30.0), deg_to_rad(45.0), 9);
    const Registration n = estimate_misregistration(u.a, u.b);
    std::printf("noise only: (%.3f, %.3f), PSR %.2f\n", n.shift_x_px, n.shift_y_px,
                n.peak_to_sidelobe);
    EXPECT_LT(n.peak_to_sidelobe, 6.0);
}

TEST(Registration, BadInput) {
    const LinearImage a = blobs(64, 64, 0, 0);
    EXPECT_THROW(estimate_misregistration(a, blobs(64, 48, 0, 0)), InvalidArgument);
    EXPECT_THROW(estimate_misregistration(a, blobs(64, 64, 0, 0, 3)), InvalidArgument);
    EXPECT_THROW(estimate_misregistration(blobs(8, 64, 0, 0), blobs(8, 64, 0, 0)), InvalidArgument);
    RegistrationOptions o;
    o.max_side_px = 4;
    EXPECT_THROW(estimate_misregistration(a, a, o), InvalidArgument);
    LinearImage broken = a;
    broken.values.pop_back();
    EXPECT_THROW(estimate_misregistration(a, broken), InvalidArgument);
}

}  // namespace
}  // namespace roughscope::image
