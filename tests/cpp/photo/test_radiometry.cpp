// Dark frame, flat field and scale (image/radiometry.hpp) against sample-by-sample arithmetic,
// and the dark/flat correction of synthetic captures against their noise-free signal.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/photo/radiometry.hpp"
#include "roughscope/photo/read.hpp"
#include "roughscope/simulation/capture.hpp"

namespace roughscope::image {
namespace {

LinearImage make(std::size_t width, std::size_t height, std::size_t channels,
                 const std::string& source, float (*value)(std::size_t, std::size_t)) {
    LinearImage image;
    image.width = width;
    image.height = height;
    image.channels = channels;
    image.info.source = source;
    image.values.resize(channels * width * height);
    for (std::size_t c = 0; c < channels; ++c)
        for (std::size_t i = 0; i < width * height; ++i)
            image.values[c * width * height + i] = value(c, i);
    image.flags.assign(width * height, 0);
    return image;
}

template <class Body>
void expect_invalid(Body&& body, std::initializer_list<const char*> parts) {
    try {
        body();
        ADD_FAILURE() << "no InvalidArgument";
    } catch (const InvalidArgument& e) {
        for (const char* part : parts)
            EXPECT_NE(std::string(e.what()).find(part), std::string::npos)
                << "'" << part << "' not in: " << e.what();
    }
}

TEST(DarkFrame, SubtractsSampleBySampleOrsFlagsAndFlagsResultsAtOrBelowZero) {
    LinearImage image = make(3, 2, 3, "light.tif", [](std::size_t c, std::size_t i) {
        return 0.1F * static_cast<float>(i) + 0.01F * static_cast<float>(c);
    });
    const LinearImage dark =
        make(3, 2, 3, "dark.tif", [](std::size_t, std::size_t i) { return i == 2 ? 0.5F : 0.05F; });
    LinearImage flagged_dark = dark;
    flagged_dark.flags[4] = kPixelSaturated;
    const LinearImage before = image;
    image.flags[5] = kPixelSaturated;
    subtract_dark_frame(image, flagged_dark);
    for (std::size_t k = 0; k < image.values.size(); ++k)
        EXPECT_EQ(image.values[k], before.values[k] - dark.values[k]) << k;
    // Pixel 0: 0 − 0.05 < 0 in R and G, B = 0.02 - 0.05 < 0; pixel 2: 0.2 − 0.5 < 0.
    EXPECT_EQ(image.flags[0], kPixelClippedLow);
    EXPECT_EQ(image.flags[1], 0);
    EXPECT_EQ(image.flags[2], kPixelClippedLow);
    EXPECT_EQ(image.flags[4], kPixelSaturated);
    EXPECT_EQ(image.flags[5], kPixelSaturated);
    EXPECT_LT(image.values[0], 0.0F);  // kept negative, not clamped
}

TEST(DarkFrame, SizeOrChannelMismatchIsAnInvalidArgumentNamingBoth) {
    LinearImage image = make(3, 2, 1, "light.tif", [](std::size_t, std::size_t) { return 1.0F; });
    const LinearImage wide =
        make(4, 2, 1, "dark.tif", [](std::size_t, std::size_t) { return 0.0F; });
    expect_invalid([&] { subtract_dark_frame(image, wide); },
                   {"light.tif", "dark.tif", "4 x 2 x 1"});
    const LinearImage rgb =
        make(3, 2, 3, "dark_rgb.tif", [](std::size_t, std::size_t) { return 0.0F; });
    expect_invalid([&] { subtract_dark_frame(image, rgb); }, {"light.tif", "dark_rgb.tif"});
    EXPECT_EQ(std::vector<float>(image.values.begin(), image.values.end()),
              std::vector<float>(6, 1.0F));  // untouched
}

TEST(DarkFrame, DifferencesBeyondTheFloatRangeAreRefusedBeforeAnyChange) {
    LinearImage image = make(2, 1, 1, "light.tif",
                             [](std::size_t, std::size_t i) { return i == 0 ? 1.0F : 3e38F; });
    const LinearImage dark = make(
        2, 1, 1, "dark.tif", [](std::size_t, std::size_t i) { return i == 0 ? 0.5F : -3e38F; });
    expect_invalid([&] { subtract_dark_frame(image, dark); },
                   {"dark.tif", "light.tif", "sample 1", "float range"});
    EXPECT_EQ(image.values[0], 1.0F);
}

TEST(FlatField, DividesByTheFlatOverItsMeanAndMarksUnusablePixels) {
    LinearImage image = make(4, 1, 1, "light.tif", [](std::size_t, std::size_t) { return 1.0F; });
    LinearImage flat = make(4, 1, 1, "flat.tif", [](std::size_t, std::size_t i) {
        const float v[4] = {0.5F, 1.5F, 0.0F, 4.0F};
        return v[i];
    });
    flat.flags[3] = kPixelSaturated;
    divide_flat_field(image, flat);
    // Usable: 0.5 and 1.5, mean 1.
    EXPECT_FLOAT_EQ(image.values[0], 2.0F);
    EXPECT_FLOAT_EQ(image.values[1], 1.0F / 1.5F);
    EXPECT_FLOAT_EQ(image.values[2], 1.0F);  // flat 0: left as it was
    EXPECT_FLOAT_EQ(image.values[3], 1.0F);  // flat flagged
    EXPECT_EQ(image.flags, (std::vector<std::uint8_t>{0, 0, kPixelNoFlatField, kPixelNoFlatField}));
}

TEST(FlatField, EachChannelIsNormalisedToItsOwnMean) {
    LinearImage image = make(2, 1, 3, "light.tif", [](std::size_t, std::size_t) { return 3.0F; });
    const LinearImage flat = make(2, 1, 3, "flat.tif", [](std::size_t c, std::size_t i) {
        return static_cast<float>((c + 1) * (i + 1));  // channel c: c+1, 2(c+1); mean 1.5(c+1)
    });
    divide_flat_field(image, flat);
    for (std::size_t c = 0; c < 3; ++c) {
        EXPECT_FLOAT_EQ(image.plane(c)[0], 3.0F * 1.5F);
        EXPECT_FLOAT_EQ(image.plane(c)[1], 3.0F * 0.75F);
    }
}

TEST(FlatField, MismatchOrNoUsablePixelIsAnInvalidArgument) {
    LinearImage image = make(2, 2, 1, "light.tif", [](std::size_t, std::size_t) { return 1.0F; });
    const LinearImage tall =
        make(2, 3, 1, "flat.tif", [](std::size_t, std::size_t) { return 1.0F; });
    expect_invalid([&] { divide_flat_field(image, tall); }, {"light.tif", "flat.tif"});
    const LinearImage dead =
        make(2, 2, 1, "dead.tif", [](std::size_t, std::size_t) { return 0.0F; });
    expect_invalid([&] { divide_flat_field(image, dead); }, {"dead.tif", "no usable pixel"});
}

TEST(Scale, MultipliesEveryValueAndRefusesBadFactors) {
    LinearImage image = make(2, 1, 1, "light.tif", [](std::size_t, std::size_t i) {
        return 0.5F + static_cast<float>(i);
    });
    scale(image, 4.0);
    EXPECT_EQ(std::vector<float>(image.values.begin(), image.values.end()),
              (std::vector<float>{2.0F, 6.0F}));
    for (const double bad :
         {0.0, -1.0, std::nan(""), std::numeric_limits<double>::infinity(), 1e300})
        expect_invalid([&] { scale(image, bad); }, {"scale factor", "light.tif"});
    EXPECT_EQ(std::vector<float>(image.values.begin(), image.values.end()),
              (std::vector<float>{2.0F, 6.0F}));
}

// A capture of a plane seen through vignetting, its dark frame (no light) and its flat field (the
// same camera on a uniform target), all noise-free: dark subtraction and the flat field bring
// every pixel of the light frame back to one value.
TEST(Radiometry, DarkAndFlatFramesUndoVignettingOfACapture) {
    namespace sim = roughscope::simulation;
    sim::Scene scene;
    scene.width = 24;
    scene.height = 16;
    sim::SurfaceTruth lambert;
    lambert.model = sim::BrightnessModel::Lambert;
    sim::CameraModel camera;
    camera.bit_depth = 16;
    camera.vignetting = 0.4;
    camera.shot_noise = false;
    camera.read_noise_e = 0.0;
    camera.black_level_dn = 500.0;
    camera.electrons_per_unit_s = 40000.0;
    auto read = [&](double exposure_s) {
        sim::CameraModel c = camera;
        c.exposure_s = exposure_s;
        const sim::Capture capture = sim::render_capture(scene, {lambert}, {}, c);
        const std::string bytes = sim::encode_capture_tiff_float(capture);
        ReadOptions options;
        options.white_level_dn = 65535.0;
        return decode_image(std::span<const std::uint8_t>(
                                reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()),
                            "capture.tif", options);
    };
    LinearImage light = read(1.0);
    const LinearImage dark = read(1e-30);  // exposure ~0: the black level alone
    LinearImage flat = read(0.5);
    subtract_dark_frame(flat, dark);
    subtract_dark_frame(light, dark);
    const float centre_before = light.values[8 * 24 + 12];
    const float corner_before = light.values[0];
    EXPECT_LT(corner_before, 0.9F * centre_before);  // the vignetting is there
    divide_flat_field(light, flat);
    double mean = 0.0;
    for (const float v : light.values) mean += v;
    mean /= static_cast<double>(light.values.size());
    for (const float v : light.values) EXPECT_NEAR(v, mean, 1e-4 * mean);
    EXPECT_EQ(count_flagged(light, kPixelNoFlatField), 0U);
}

}  // namespace
}  // namespace roughscope::image
