// LinearImage invariants (image/image.hpp) and the shared tone responses (core/response.hpp).
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/response.hpp"
#include "roughscope/photo/image.hpp"

namespace roughscope::image {
namespace {

LinearImage grey(std::size_t width, std::size_t height) {
    LinearImage image;
    image.width = width;
    image.height = height;
    image.channels = 1;
    image.values.assign(width * height, 0.5F);
    image.flags.assign(width * height, 0);
    image.info.source = "grey.png";
    return image;
}

TEST(LinearImage, LayoutIsPlanarRowMajor) {
    LinearImage image = grey(4, 3);
    image.channels = 3;
    image.values.resize(3 * 12);
    for (std::size_t k = 0; k < image.values.size(); ++k) image.values[k] = static_cast<float>(k);
    EXPECT_EQ(image.value(2, 1, 3), static_cast<float>((2 * 3 + 1) * 4 + 3));
    EXPECT_EQ(image.plane(1)[0], 12.0F);
    EXPECT_NO_THROW(check_linear_image(image));
}

TEST(LinearImage, InconsistentImagesAreInvalidArguments) {
    LinearImage empty = grey(0, 3);
    EXPECT_THROW(check_linear_image(empty), InvalidArgument);
    LinearImage two = grey(2, 2);
    two.channels = 2;
    two.values.resize(8);
    EXPECT_THROW(check_linear_image(two), InvalidArgument);
    LinearImage short_values = grey(2, 2);
    short_values.values.pop_back();
    EXPECT_THROW(check_linear_image(short_values), InvalidArgument);
    LinearImage short_flags = grey(2, 2);
    short_flags.flags.pop_back();
    EXPECT_THROW(check_linear_image(short_flags), InvalidArgument);
    LinearImage nan = grey(2, 2);
    nan.values[3] = std::numeric_limits<float>::quiet_NaN();
    try {
        check_linear_image(nan);
        FAIL() << "NaN accepted";
    } catch (const InvalidArgument& e) {
        EXPECT_NE(std::string(e.what()).find("grey.png"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("sample 3"), std::string::npos) << e.what();
    }
}

TEST(LinearImage, CountFlaggedCountsPixelsWithAnyBitOfTheMask) {
    LinearImage image = grey(3, 1);
    image.flags = {kPixelSaturated, kPixelClippedLow, kPixelSaturated | kPixelClippedLow};
    EXPECT_EQ(count_flagged(image, kPixelSaturated), 2U);
    EXPECT_EQ(count_flagged(image, kPixelClippedLow), 2U);
    EXPECT_EQ(count_flagged(image, kPixelSaturated | kPixelClippedLow), 3U);
}

TEST(Response, NamesRoundTripAndUnknownNamesAreInvalid) {
    for (const Response r : {Response::Linear, Response::Srgb, Response::Gamma})
        EXPECT_EQ(parse_response(to_string(r)), r);
    EXPECT_EQ(parse_response(" SRGB "), Response::Srgb);
    EXPECT_THROW((void)parse_response("log"), InvalidArgument);
}

}  // namespace
}  // namespace roughscope::image
