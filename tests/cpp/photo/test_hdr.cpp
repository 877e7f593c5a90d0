// Response recovery from an exposure bracket and HDR merging (image/hdr.hpp), checked against a
// bracket rendered through a known response: the recovered curve must follow the known inverse
// response, and the merged image the scene's radiance, each up to the one scale the method leaves
// free.
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/photo/hdr.hpp"

namespace roughscope::image {
namespace {

constexpr std::size_t kWidth = 256, kHeight = 24;

// Scene radiance: three decades along x, a small variation down the rows.
double radiance(std::size_t row, std::size_t col) {
    const double x = (static_cast<double>(col) + 0.5) / kWidth;
    return std::pow(10.0, -3.0 + 3.0 * x) * (1.0 + 0.02 * static_cast<double>(row % 5));
}

// The camera: u = E t (clipped at 1), code = round(255 u^(1/γ)); the image read on the code
// scale (linear, black 0, white 255), as read_image gives an 8-bit file read linear.
LinearImage shot(double exposure, double gamma, std::size_t channels = 1) {
    LinearImage image;
    image.width = kWidth;
    image.height = kHeight;
    image.channels = channels;
    image.values.resize(channels * kWidth * kHeight);
    image.flags.assign(kWidth * kHeight, 0);
    image.info.source = "bracket.png";
    image.info.format = "png";
    image.info.bits_per_sample = 8;
    image.info.white_level_dn = 255.0;
    image.info.black_level_dn.assign(channels, 0.0);
    image.info.response = Response::Linear;
    for (std::size_t c = 0; c < channels; ++c)
        for (std::size_t r = 0; r < kHeight; ++r)
            for (std::size_t x = 0; x < kWidth; ++x) {
                // Channels differ in sensitivity (a colour camera under one light).
                const double u = std::min(1.0, radiance(r, x) * exposure * (1.0 - 0.2 * c));
                const double code = std::round(255.0 * std::pow(u, 1.0 / gamma));
                image.values[(c * kHeight + r) * kWidth + x] = static_cast<float>(code / 255.0);
            }
    return image;
}

struct Bracket {
    std::vector<LinearImage> images;
    std::vector<double> exposures;
};

Bracket bracket(double gamma, std::size_t channels = 1) {
    Bracket b;
    for (const double t : {1.0, 4.0, 16.0, 64.0, 256.0}) {
        b.images.push_back(shot(t, gamma, channels));
        b.exposures.push_back(t);
    }
    return b;
}

TEST(ResponseCurve, DebevecRecoversAKnownGamma) {
    const double gamma = 2.2;
    const Bracket b = bracket(gamma, 3);
    const ResponseCurve curve = recover_response_debevec(b.images, b.exposures);
    ASSERT_EQ(curve.light.size(), 3u);
    for (std::size_t c = 0; c < 3; ++c) {
        EXPECT_DOUBLE_EQ(curve.light[c][255], 1.0);
        // Relative to code 128, X(z) must follow (z/128)^γ: within 6 % over the codes that
        // the bracket sees well.
        for (int z = 24; z <= 232; z += 16) {
            const double expected = std::pow(z / 128.0, gamma);
            const double got = curve.light[c][static_cast<std::size_t>(z)] / curve.light[c][128];
            EXPECT_NEAR(got / expected, 1.0, 0.06) << "channel " << c << " code " << z;
        }
    }
}

// Not vacuous: the curve of a different camera (γ = 1, linear) is told apart.
TEST(ResponseCurve, DebevecTellsALinearCameraFromAGammaOne) {
    const Bracket b = bracket(1.0);
    const ResponseCurve curve = recover_response_debevec(b.images, b.exposures);
    const double got = curve.light[0][64] / curve.light[0][128];
    EXPECT_NEAR(got, 0.5, 0.03);                         // linear: half the code, half the light
    EXPECT_GT(std::abs(got - std::pow(0.5, 2.2)), 0.2);  // not the γ = 2.2 value 0.218
}

TEST(ResponseCurve, AppliedCurveMakesRatiosLinear) {
    const double gamma = 2.2;
    const Bracket b = bracket(gamma);
    const ResponseCurve curve = recover_response_debevec(b.images, b.exposures);
    LinearImage image = shot(16.0, gamma);
    apply_response_curve(image, curve);
    // Two pixels one decade apart in radiance (both unsaturated at t = 16): ratio 10.
    const std::size_t a = 60, c = 60 + kWidth / 3;  // x differs by one decade
    const double ratio = image.value(0, 0, c) / image.value(0, 0, a);
    EXPECT_NEAR(ratio / (radiance(0, c) / radiance(0, a)), 1.0, 0.08);
    EXPECT_FALSE(image.info.warnings.empty());
}

TEST(HdrMerge, MergedImageFollowsTheRadianceOverThreeDecades) {
    const double gamma = 2.2;
    const Bracket b = bracket(gamma);
    const ResponseCurve curve = recover_response_debevec(b.images, b.exposures);
    const LinearImage hdr = merge_hdr(b.images, b.exposures, curve);
    ASSERT_EQ(hdr.width, kWidth);
    // merged / radiance is one constant (the free scale) within 6 % everywhere not flagged.
    std::vector<double> ratios;
    for (std::size_t r = 0; r < kHeight; ++r)
        for (std::size_t x = 8; x < kWidth; ++x)
            if (hdr.flags[r * kWidth + x] == 0)
                ratios.push_back(hdr.value(0, r, x) / radiance(r, x));
    ASSERT_GT(ratios.size(), kWidth * kHeight / 2);
    double mean = 0.0;
    for (const double q : ratios) mean += q;
    mean /= static_cast<double>(ratios.size());
    double worst = 0.0;
    for (const double q : ratios) worst = std::max(worst, std::abs(q / mean - 1.0));
    EXPECT_LT(worst, 0.06);
    EXPECT_EQ(hdr.info.exposure_s, 1.0);
    // The brightest column is clipped (or next to clipping) in every exposure: flagged, never a
    // number.
    EXPECT_EQ(hdr.flags[kWidth - 1], kPixelSaturated);
    EXPECT_EQ(hdr.value(0, 0, kWidth - 1), 0.0F);
}

// Failures: each names the input and the valid range.

TEST(ResponseCurve, OneImageIsNotABracket) {
    const Bracket b = bracket(2.2);
    EXPECT_THROW((void)recover_response_debevec({b.images[0]}, {1.0}), InvalidArgument);
}

TEST(ResponseCurve, ExposuresMustMatchAndDiffer) {
    const Bracket b = bracket(2.2);
    EXPECT_THROW((void)recover_response_debevec(b.images, {1.0, 2.0}), InvalidArgument);
    std::vector<double> equal(b.images.size(), 1.0);
    EXPECT_THROW((void)recover_response_debevec(b.images, equal), InvalidArgument);
    std::vector<double> negative = b.exposures;
    negative[1] = -1.0;
    EXPECT_THROW((void)recover_response_debevec(b.images, negative), InvalidArgument);
}

TEST(ResponseCurve, SixteenBitImagesAreRefused) {
    Bracket b = bracket(2.2);
    for (auto& image : b.images) {
        image.info.bits_per_sample = 16;
        image.info.white_level_dn = 65535.0;
    }
    try {
        (void)recover_response_debevec(b.images, b.exposures);
        FAIL() << "no error";
    } catch (const InvalidArgument& e) {
        EXPECT_NE(std::string(e.what()).find("8-bit"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("bracket.png"), std::string::npos) << e.what();
    }
}

TEST(ResponseCurve, ImagesOfDifferentSizesAreRefused) {
    Bracket b = bracket(2.2);
    LinearImage& small = b.images[2];
    small.width = 128;
    small.values.resize(small.channels * small.width * small.height);
    small.flags.resize(small.width * small.height);
    EXPECT_THROW((void)recover_response_debevec(b.images, b.exposures), InvalidArgument);
}

TEST(ResponseCurve, ACurveWithTooFewChannelsIsRefused) {
    const Bracket grey = bracket(2.2);
    const ResponseCurve curve = recover_response_debevec(grey.images, grey.exposures);
    LinearImage colour = shot(4.0, 2.2, 3);
    EXPECT_THROW(apply_response_curve(colour, curve), InvalidArgument);
}

}  // namespace
}  // namespace roughscope::image
