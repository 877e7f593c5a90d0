// The image reader (image/read.hpp) against files written by independent writers: libpng and
// byte-built TIFF/DNG structures (image_files.hpp), libtiff for tiled and planar TIFF, OpenCV's
// JPEG encoder with a hand-built EXIF segment, and the simulation topic's capture writer, whose
// DN (the quantised linear signal) is the truth the linear values must recover.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <png.h>
#include <tiffio.h>
#include <zlib.h>

#include "image_files.hpp"
#include "photo/decode.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/photo/read.hpp"
#include "roughscope/simulation/capture.hpp"

namespace roughscope::image {
namespace {

namespace fs = std::filesystem;
namespace sim = roughscope::simulation;
using roughscope::testing::ByteVector;

LinearImage decode(const ByteVector& bytes, const ReadOptions& options = {},
                   const std::string& name = "test.img") {
    return decode_image(std::span<const std::uint8_t>(bytes), name, options);
}

ByteVector as_bytes(const std::string& s) { return ByteVector(s.begin(), s.end()); }

template <class E, class Body>
void expect_error(Body&& body, std::initializer_list<const char*> parts) {
    try {
        body();
        ADD_FAILURE() << "no exception";
    } catch (const E& e) {
        for (const char* part : parts)
            EXPECT_NE(std::string(e.what()).find(part), std::string::npos)
                << "'" << part << "' not in: " << e.what();
    }
}

bool contains(const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
}

// The largest distance, in linear units, between the sRGB code `code` (of 255) and the codes
// half a step either side: the quantisation of an 8-bit sRGB file.
double srgb_half_step(int code) {
    using roughscope::testing::srgb_to_linear;
    const double at = srgb_to_linear(code / 255.0);
    return std::max(srgb_to_linear(std::min(code + 0.5, 255.0) / 255.0) - at,
                    at - srgb_to_linear(std::max(code - 0.5, 0.0) / 255.0));
}

// A 14-bit capture of a sphere bright enough to saturate its centre, on a black background
// (read noise around the black level gives codes at and below it).
sim::Capture bright_sphere(int bits, sim::CameraModel& camera) {
    sim::Scene scene;
    scene.shape = sim::SceneShape::Sphere;
    scene.width = 40;
    scene.height = 30;
    sim::SurfaceTruth truth;
    camera.bit_depth = bits;
    camera.black_level_dn = 64.0;
    camera.gain_dn_per_e = 0.5;
    camera.electrons_per_unit_s = 2e6;
    camera.seed = 5;
    return sim::render_capture(scene, {truth}, {}, camera);
}

// ---- PNG ---------------------------------------------------------------------------------------

TEST(ReadPng, EightBitSrgbRgbRecoversTheLinearTruthToQuantisation) {
    using roughscope::testing::linear_to_srgb;
    testing::PngSpec spec;
    spec.width = 16;
    spec.height = 2;
    spec.color_type = PNG_COLOR_TYPE_RGB;
    spec.srgb_chunk = true;
    std::vector<double> truth;
    for (std::uint32_t r = 0; r < spec.height; ++r)
        for (std::uint32_t x = 0; x < spec.width; ++x)
            for (int c = 0; c < 3; ++c) {
                const double u = c == 0 ? x / 15.0 : c == 1 ? 1.0 - x / 15.0 : 0.2 + 0.1 * r;
                truth.push_back(u);
                spec.samples.push_back(
                    static_cast<std::uint16_t>(std::lround(255.0 * linear_to_srgb(u))));
            }
    const LinearImage image = decode(testing::png_bytes(spec), {}, "rgb.png");
    ASSERT_EQ(image.channels, 3U);
    ASSERT_EQ(image.width, 16U);
    ASSERT_EQ(image.height, 2U);
    EXPECT_NO_THROW(check_linear_image(image));
    EXPECT_EQ(image.info.source, "rgb.png");
    EXPECT_EQ(image.info.format, "png");
    EXPECT_EQ(image.info.bits_per_sample, 8);
    EXPECT_EQ(image.info.response, Response::Srgb);
    EXPECT_EQ(image.info.file_response, Response::Srgb);
    EXPECT_TRUE(contains(image.info.file_response_evidence, "sRGB chunk"));
    EXPECT_EQ(image.info.white_level_dn, 255.0);
    EXPECT_TRUE(image.info.warnings.empty());
    for (std::size_t r = 0; r < 2; ++r)
        for (std::size_t x = 0; x < 16; ++x)
            for (std::size_t c = 0; c < 3; ++c) {
                const std::size_t i = (r * 16 + x) * 3 + c;
                const int code = spec.samples[i];
                EXPECT_NEAR(image.value(c, r, x), testing::srgb_to_linear(code / 255.0), 2e-7);
                EXPECT_LE(std::abs(image.value(c, r, x) - truth[i]), srgb_half_step(code) + 1e-6);
            }
    // Column 0 has R = 0 and G = 255, column 15 the reverse: both clipped low and saturated.
    for (std::size_t r = 0; r < 2; ++r) {
        EXPECT_EQ(image.flags[r * 16], kPixelSaturated | kPixelClippedLow);
        EXPECT_EQ(image.flags[r * 16 + 15], kPixelSaturated | kPixelClippedLow);
        EXPECT_EQ(image.flags[r * 16 + 7], 0);
    }
}

TEST(ReadPng, EightBitWithoutChunksIsSrgbAndAlphaIsDropped) {
    testing::PngSpec spec;
    spec.width = 3;
    spec.color_type = PNG_COLOR_TYPE_GRAY_ALPHA;
    spec.samples = {10, 0, 128, 77, 254, 255};
    const LinearImage image = decode(testing::png_bytes(spec));
    ASSERT_EQ(image.channels, 1U);
    EXPECT_FALSE(image.info.file_response.has_value());
    EXPECT_EQ(image.info.response, Response::Srgb);
    EXPECT_NEAR(image.values[0], testing::srgb_to_linear(10 / 255.0), 2e-7);
    EXPECT_NEAR(image.values[1], testing::srgb_to_linear(128 / 255.0), 2e-7);
    EXPECT_NEAR(image.values[2], testing::srgb_to_linear(254 / 255.0), 2e-7);
    EXPECT_EQ(count_flagged(image, 0xff), 0U);
}

TEST(ReadPng, SixteenBitCaptureGivesTheWrittenDnOnTheLinearScale) {
    sim::CameraModel camera;
    const sim::Capture capture = bright_sphere(14, camera);
    const std::string bytes = sim::encode_capture_png(capture);
    ReadOptions options;
    options.black_level_dn = std::vector<double>{64.0};
    const LinearImage image = decode(as_bytes(bytes), options, "capture.png");
    EXPECT_EQ(image.info.bits_per_sample, 16);
    EXPECT_EQ(image.info.white_level_dn, 16383.0);  // sBIT 14, codes stored unscaled
    EXPECT_EQ(image.info.response, Response::Linear);
    EXPECT_EQ(image.info.black_level_dn, std::vector<double>{64.0});
    ASSERT_EQ(image.values.size(), capture.dn.size());
    std::size_t saturated = 0;
    std::size_t clipped = 0;
    for (std::size_t i = 0; i < capture.dn.size(); ++i) {
        const double dn = capture.dn[i];
        EXPECT_FLOAT_EQ(image.values[i], static_cast<float>((dn - 64.0) / (16383.0 - 64.0)));
        const std::uint8_t expected =
            (dn >= 16383.0 ? kPixelSaturated : 0) | (dn <= 64.0 ? kPixelClippedLow : 0);
        EXPECT_EQ(image.flags[i], expected) << i;
        saturated += dn >= 16383.0 ? 1 : 0;
        clipped += dn <= 64.0 ? 1 : 0;
    }
    EXPECT_GT(saturated, 0U);
    EXPECT_GT(clipped, 0U);
}

TEST(ReadPng, SignificantBitsScaledAsTheSpecificationSaysAreShiftedBack) {
    testing::PngSpec spec;
    spec.width = 64;
    spec.depth = 16;
    spec.significant_bits = 12;
    spec.shift_to_depth = true;  // libpng stores code << 4 | code >> 8
    for (std::uint32_t x = 0; x < spec.width; ++x)
        spec.samples.push_back(static_cast<std::uint16_t>(x * 65));  // 0 .. 4095
    const LinearImage image = decode(testing::png_bytes(spec));
    EXPECT_EQ(image.info.white_level_dn, 4095.0);
    for (std::uint32_t x = 0; x < spec.width; ++x)
        EXPECT_FLOAT_EQ(image.values[x], static_cast<float>(x * 65 / 4095.0));
    EXPECT_EQ(image.flags[63], kPixelSaturated);
    EXPECT_EQ(image.flags[0], kPixelClippedLow);
}

TEST(ReadPng, InterlacedSixteenBitRgbaReadsLikeTheSamePixelsPlain) {
    testing::PngSpec spec;
    spec.width = 13;
    spec.height = 11;
    spec.depth = 16;
    spec.color_type = PNG_COLOR_TYPE_RGB_ALPHA;
    for (std::uint32_t i = 0; i < spec.width * spec.height * 4; ++i)
        spec.samples.push_back(static_cast<std::uint16_t>((i * 7919U) % 65536U));
    const LinearImage plain = decode(testing::png_bytes(spec));
    spec.interlaced = true;
    const LinearImage interlaced = decode(testing::png_bytes(spec));
    EXPECT_EQ(plain.values, interlaced.values);
    EXPECT_EQ(plain.flags, interlaced.flags);
    for (std::size_t r = 0; r < spec.height; ++r)
        for (std::size_t x = 0; x < spec.width; ++x)
            for (std::size_t c = 0; c < 3; ++c)
                EXPECT_FLOAT_EQ(plain.value(c, r, x),
                                spec.samples[(r * spec.width + x) * 4 + c] / 65535.0F);
}

TEST(ReadPng, GamaChunkGivesAGammaResponseAndAnExplicitGammaIsInverted) {
    testing::PngSpec spec;
    spec.width = 32;
    spec.gama = 1.0 / 2.2;
    std::vector<double> truth;
    for (std::uint32_t x = 0; x < spec.width; ++x) {
        const double u = x / 31.0;
        truth.push_back(u);
        spec.samples.push_back(
            static_cast<std::uint16_t>(std::lround(255.0 * std::pow(u, 1 / 2.2))));
    }
    const LinearImage image = decode(testing::png_bytes(spec));
    EXPECT_EQ(image.info.response, Response::Gamma);
    EXPECT_EQ(image.info.file_response, Response::Gamma);
    EXPECT_NEAR(image.info.gamma, 2.2, 1e-4);
    EXPECT_TRUE(contains(image.info.file_response_evidence, "gAMA"));
    for (std::uint32_t x = 0; x < spec.width; ++x) {
        const double code = spec.samples[x];
        // Quantisation: half a code either side, through the power law.
        const double half =
            std::pow(std::min(code + 0.5, 255.0) / 255.0, 2.2) - std::pow(code / 255.0, 2.2);
        EXPECT_NEAR(image.values[x], truth[x], half + 1e-6) << x;
    }

    testing::PngSpec plain = spec;
    plain.gama.reset();
    ReadOptions options;
    options.response = Response::Gamma;
    options.gamma = 1.8;
    const LinearImage explicit_gamma = decode(testing::png_bytes(plain), options);
    EXPECT_EQ(explicit_gamma.info.response, Response::Gamma);
    EXPECT_EQ(explicit_gamma.info.gamma, 1.8);
    EXPECT_TRUE(explicit_gamma.info.warnings.empty());
    for (std::uint32_t x = 0; x < spec.width; ++x)
        EXPECT_NEAR(explicit_gamma.values[x], std::pow(plain.samples[x] / 255.0, 1.8), 2e-7);
}

TEST(ReadPng, LinearAskedOfAnSrgbTaggedFileIsDoneWithAWarning) {
    testing::PngSpec spec;
    spec.width = 3;
    spec.srgb_chunk = true;
    spec.samples = {0, 51, 255};
    ReadOptions options;
    options.response = Response::Linear;
    const LinearImage image = decode(testing::png_bytes(spec), options);
    EXPECT_EQ(image.info.response, Response::Linear);
    EXPECT_EQ(image.info.file_response, Response::Srgb);
    ASSERT_EQ(image.info.warnings.size(), 1U);
    EXPECT_TRUE(contains(image.info.warnings[0], "linear"));
    EXPECT_TRUE(contains(image.info.warnings[0], "sRGB chunk"));
    EXPECT_FLOAT_EQ(image.values[1], 0.2F);
    // Asking for what the file says gives no warning.
    options.response = Response::Srgb;
    EXPECT_TRUE(decode(testing::png_bytes(spec), options).info.warnings.empty());
}

TEST(ReadPng, BlackAndWhiteLevelsScaleAndFlag) {
    testing::PngSpec spec;
    spec.width = 7;
    spec.samples = {0, 10, 11, 100, 199, 200, 255};
    ReadOptions options;
    options.response = Response::Linear;
    options.black_level_dn = std::vector<double>{10.0};
    options.white_level_dn = 200.0;
    const LinearImage image = decode(testing::png_bytes(spec), options);
    EXPECT_EQ(image.info.white_level_dn, 200.0);
    const std::vector<std::uint8_t> flags = {kPixelClippedLow, kPixelClippedLow, 0, 0, 0,
                                             kPixelSaturated,  kPixelSaturated};
    EXPECT_EQ(image.flags, flags);
    for (std::size_t x = 0; x < 7; ++x)
        EXPECT_FLOAT_EQ(image.values[x], static_cast<float>((spec.samples[x] - 10.0) / 190.0));
}

// A minimal ICC.1 v2 grey display profile: header, a tag table with 'kTRC' (a 'curv' of the
// given entries) and 'wtpt', the D50 illuminant.
ByteVector icc_profile(const std::vector<std::uint16_t>& curve) {
    ByteVector p(128 + 4 + 2 * 12, 0);  // header and a tag table of 2 tags
    auto be32 = [](ByteVector& b, std::size_t at, std::uint32_t v) {
        for (int k = 0; k < 4; ++k) b[at + k] = static_cast<std::uint8_t>(v >> (24 - 8 * k));
    };
    auto tag4 = [](ByteVector& b, std::size_t at, const char* s) {
        for (int k = 0; k < 4; ++k) b[at + k] = static_cast<std::uint8_t>(s[k]);
    };
    be32(p, 8, 0x02100000);  // version 2.1
    tag4(p, 12, "mntr");
    tag4(p, 16, "GRAY");
    tag4(p, 20, "XYZ ");
    tag4(p, 36, "acsp");
    be32(p, 68, 0x0000F6D6);  // D50 X, Y, Z (s15Fixed16)
    be32(p, 72, 0x00010000);
    be32(p, 76, 0x0000D32D);
    be32(p, 128, 2);
    const std::size_t wtpt_at = p.size();
    ByteVector wtpt(20, 0);
    tag4(wtpt, 0, "XYZ ");
    be32(wtpt, 8, 0x0000F6D6);
    be32(wtpt, 12, 0x00010000);
    be32(wtpt, 16, 0x0000D32D);
    for (const std::uint8_t byte : wtpt) p.push_back(byte);
    const std::size_t trc_at = p.size();
    ByteVector trc(12 + 2 * curve.size(), 0);
    tag4(trc, 0, "curv");
    be32(trc, 8, static_cast<std::uint32_t>(curve.size()));
    for (std::size_t k = 0; k < curve.size(); ++k) {
        trc[12 + 2 * k] = static_cast<std::uint8_t>(curve[k] >> 8);
        trc[13 + 2 * k] = static_cast<std::uint8_t>(curve[k] & 0xff);
    }
    for (const std::uint8_t byte : trc) p.push_back(byte);
    while (p.size() % 4 != 0) p.push_back(0);
    tag4(p, 132, "kTRC");
    be32(p, 136, static_cast<std::uint32_t>(trc_at));
    be32(p, 140, static_cast<std::uint32_t>(trc.size()));
    tag4(p, 144, "wtpt");
    be32(p, 148, static_cast<std::uint32_t>(wtpt_at));
    be32(p, 152, 20);
    be32(p, 0, static_cast<std::uint32_t>(p.size()));
    return p;
}

TEST(ReadPng, IccProfileToneCurveIsTheEvidence) {
    testing::PngSpec spec;
    spec.width = 2;
    spec.samples = {0, 128};
    spec.icc_profile = icc_profile({});  // identity curve
    spec.icc_name = "linear grey";
    LinearImage image = decode(testing::png_bytes(spec));
    EXPECT_EQ(image.info.file_response, Response::Linear);
    EXPECT_EQ(image.info.response, Response::Linear);  // overrides the 8-bit sRGB default
    EXPECT_TRUE(contains(image.info.file_response_evidence, "iCCP"))
        << image.info.file_response_evidence;
    EXPECT_FLOAT_EQ(image.values[1], 128.0F / 255.0F);

    spec.icc_profile = icc_profile({static_cast<std::uint16_t>(2.2 * 256)});  // u8Fixed8 γ
    image = decode(testing::png_bytes(spec));
    EXPECT_EQ(image.info.file_response, Response::Gamma);
    EXPECT_NEAR(image.info.gamma, 563.0 / 256.0, 1e-12);
    EXPECT_NEAR(image.values[1], std::pow(128.0 / 255.0, 563.0 / 256.0), 2e-7);
}

// ---- TIFF --------------------------------------------------------------------------------------

TEST(ReadTiff, SixteenBitCaptureGivesTheWrittenDn) {
    sim::CameraModel camera;
    const sim::Capture capture = bright_sphere(16, camera);
    ReadOptions options;
    options.black_level_dn = std::vector<double>{64.0};
    const LinearImage image =
        decode(as_bytes(sim::encode_capture_tiff(capture)), options, "capture.tiff");
    EXPECT_EQ(image.info.format, "tiff");
    EXPECT_EQ(image.info.bits_per_sample, 16);
    EXPECT_EQ(image.info.white_level_dn, 65535.0);
    EXPECT_EQ(image.info.response, Response::Linear);
    ASSERT_EQ(image.values.size(), capture.dn.size());
    for (std::size_t i = 0; i < capture.dn.size(); ++i) {
        EXPECT_FLOAT_EQ(image.values[i],
                        static_cast<float>((capture.dn[i] - 64.0) / (65535.0 - 64.0)));
        EXPECT_EQ((image.flags[i] & kPixelClippedLow) != 0, capture.dn[i] <= 64);
    }
}

TEST(ReadTiff, FloatCaptureGivesTheLinearSignalAtTheGivenLevels) {
    sim::CameraModel camera;
    const sim::Capture capture = bright_sphere(14, camera);
    ReadOptions options;
    options.black_level_dn = std::vector<double>{64.0};
    options.white_level_dn = 16383.0;
    const LinearImage image =
        decode(as_bytes(sim::encode_capture_tiff_float(capture)), options, "float.tiff");
    EXPECT_TRUE(image.info.is_float);
    EXPECT_EQ(image.info.bits_per_sample, 32);
    EXPECT_EQ(image.info.response, Response::Linear);
    std::size_t saturated = 0;
    for (std::size_t i = 0; i < capture.expected_dn.size(); ++i) {
        const double s = capture.expected_dn[i];
        EXPECT_NEAR(image.values[i], (s - 64.0) / (16383.0 - 64.0), 1e-6);
        EXPECT_EQ((image.flags[i] & kPixelSaturated) != 0, s >= 16383.0);
        saturated += s >= 16383.0 ? 1 : 0;
    }
    EXPECT_GT(saturated, 0U);
}

TEST(ReadTiff, RgbWithExifGivesPlanesInOrderAndTheExposure) {
    const std::uint32_t w = 5;
    const std::uint32_t h = 2;
    std::vector<std::uint16_t> samples;
    for (std::uint32_t i = 0; i < w * h; ++i)
        for (std::uint32_t c = 0; c < 3; ++c)
            samples.push_back(static_cast<std::uint16_t>(1000 * (c + 1) + i));
    const ByteVector file = testing::tiff_image(w, h, 3, 16, 1, testing::raw_bytes(samples), {},
                                                testing::exif_exposure(125, 56, 200, 0xffff));
    const LinearImage image = decode(file, {}, "exif.tif");
    ASSERT_EQ(image.channels, 3U);
    EXPECT_EQ(image.info.response, Response::Linear);
    EXPECT_FALSE(image.info.file_response.has_value());
    ASSERT_TRUE(image.info.exposure_s.has_value());
    // libtiff 4.5 hands EXIF rationals out as floats.
    EXPECT_NEAR(*image.info.exposure_s, 1.0 / 125.0, 1e-9);
    EXPECT_NEAR(image.info.f_number.value_or(0), 5.6, 1e-6);
    EXPECT_DOUBLE_EQ(image.info.iso.value_or(0), 200.0);
    for (std::size_t c = 0; c < 3; ++c)
        for (std::size_t i = 0; i < w * h; ++i)
            EXPECT_FLOAT_EQ(image.plane(c)[i], samples[i * 3 + c] / 65535.0F);
}

TEST(ReadTiff, ExifColorSpaceSrgbMakesAnEightBitTiffSrgbAndOrientationIsWarned) {
    const ByteVector file =
        testing::tiff_image(2, 1, 1, 8, 1, {0, 200}, {testing::shorts(274, {3})},
                            testing::exif_exposure(30, 28, 100, 1));
    const LinearImage image = decode(file);
    EXPECT_EQ(image.info.file_response, Response::Srgb);
    EXPECT_TRUE(contains(image.info.file_response_evidence, "EXIF ColorSpace"));
    EXPECT_NEAR(image.values[1], testing::srgb_to_linear(200 / 255.0), 2e-7);
    ASSERT_EQ(image.info.warnings.size(), 1U);
    EXPECT_TRUE(contains(image.info.warnings[0], "orientation 3"));
}

// libtiff writes the same RGB 16-bit pixels tiled (16 x 16 tiles over 20 x 18) and in separate
// planes; both read as the contiguous strips do.
ByteVector libtiff_file(std::uint32_t w, std::uint32_t h, const std::vector<std::uint16_t>& rgb,
                        bool tiled, bool separate) {
    const fs::path path = roughscope::testing::fresh_dir("imgread_libtiff") / "t.tif";
    TIFF* tif = TIFFOpen(path.c_str(), "w");
    EXPECT_NE(tif, nullptr);
    TIFFSetField(tif, TIFFTAG_IMAGEWIDTH, w);
    TIFFSetField(tif, TIFFTAG_IMAGELENGTH, h);
    TIFFSetField(tif, TIFFTAG_BITSPERSAMPLE, 16);
    TIFFSetField(tif, TIFFTAG_SAMPLESPERPIXEL, 3);
    TIFFSetField(tif, TIFFTAG_PHOTOMETRIC, PHOTOMETRIC_RGB);
    TIFFSetField(tif, TIFFTAG_COMPRESSION, COMPRESSION_ADOBE_DEFLATE);
    TIFFSetField(tif, TIFFTAG_PLANARCONFIG, separate ? PLANARCONFIG_SEPARATE : PLANARCONFIG_CONTIG);
    if (tiled) {
        TIFFSetField(tif, TIFFTAG_TILEWIDTH, 16);
        TIFFSetField(tif, TIFFTAG_TILELENGTH, 16);
        std::vector<std::uint16_t> tile(16 * 16 * 3);
        for (std::uint32_t y0 = 0; y0 < h; y0 += 16)
            for (std::uint32_t x0 = 0; x0 < w; x0 += 16) {
                std::fill(tile.begin(), tile.end(), 0);
                for (std::uint32_t r = 0; r < 16 && y0 + r < h; ++r)
                    for (std::uint32_t x = 0; x < 16 && x0 + x < w; ++x)
                        for (std::uint32_t c = 0; c < 3; ++c)
                            tile[(r * 16 + x) * 3 + c] = rgb[((y0 + r) * w + x0 + x) * 3 + c];
                TIFFWriteTile(tif, tile.data(), x0, y0, 0, 0);
            }
    } else {
        TIFFSetField(tif, TIFFTAG_ROWSPERSTRIP, 4);
        std::vector<std::uint16_t> line(w);
        for (std::uint16_t c = 0; c < 3; ++c)
            for (std::uint32_t r = 0; r < h; ++r) {
                for (std::uint32_t x = 0; x < w; ++x) line[x] = rgb[(r * w + x) * 3 + c];
                TIFFWriteScanline(tif, line.data(), r, c);
            }
    }
    TIFFClose(tif);
    const std::string bytes = roughscope::testing::slurp(path);
    return as_bytes(bytes);
}

TEST(ReadTiff, TiledAndSeparatePlanesReadAsThePixelsWritten) {
    const std::uint32_t w = 20;
    const std::uint32_t h = 18;
    std::vector<std::uint16_t> rgb(w * h * 3);
    for (std::size_t i = 0; i < rgb.size(); ++i)
        rgb[i] = static_cast<std::uint16_t>((i * 977U) % 65536U);
    for (const bool tiled : {true, false}) {
        SCOPED_TRACE(tiled ? "tiled" : "separate planes");
        const LinearImage image = decode(libtiff_file(w, h, rgb, tiled, !tiled));
        ASSERT_EQ(image.channels, 3U);
        for (std::size_t r = 0; r < h; ++r)
            for (std::size_t x = 0; x < w; ++x)
                for (std::size_t c = 0; c < 3; ++c)
                    ASSERT_FLOAT_EQ(image.value(c, r, x), rgb[(r * w + x) * 3 + c] / 65535.0F);
    }
}

// ---- camera RAW --------------------------------------------------------------------------------

TEST(ReadRaw, LinearDngCaptureGivesTheWrittenDnInEveryPlane) {
    sim::CameraModel camera;
    const sim::Capture capture = bright_sphere(14, camera);
    const LinearImage image =
        decode(as_bytes(sim::encode_capture_dng(capture, camera)), {}, "capture.dng");
    EXPECT_EQ(image.info.format, "raw");
    EXPECT_TRUE(contains(image.info.raw_format, "roughscope")) << image.info.raw_format;
    EXPECT_EQ(image.info.file_response, Response::Linear);
    EXPECT_EQ(image.info.white_level_dn, 16383.0);
    EXPECT_EQ(image.info.black_level_dn, (std::vector<double>{64.0, 64.0, 64.0}));
    ASSERT_EQ(image.channels, 3U);
    ASSERT_EQ(image.width, capture.width);
    ASSERT_EQ(image.height, capture.height);
    std::size_t saturated = 0;
    for (std::size_t i = 0; i < capture.dn.size(); ++i) {
        const double dn = capture.dn[i];
        for (std::size_t c = 0; c < 3; ++c)
            EXPECT_FLOAT_EQ(image.plane(c)[i], static_cast<float>((dn - 64.0) / (16383.0 - 64.0)));
        const std::uint8_t expected =
            (dn >= 16383.0 ? kPixelSaturated : 0) | (dn <= 64.0 ? kPixelClippedLow : 0);
        EXPECT_EQ(image.flags[i], expected);
        saturated += dn >= 16383 ? 1 : 0;
    }
    EXPECT_GT(saturated, 0U);
}

TEST(ReadRaw, BayerDngIsBinnedToHalfSizeWithPerSiteBlackLevels) {
    // 24 x 22 RGGB sites (LibRaw reads no image under 22 x 22); black levels per site of the
    // 2 x 2 pattern: R 60, G 62, G 64, B 66.
    const std::uint32_t w = 24;
    const std::uint32_t h = 22;
    const std::uint32_t white = 4095;
    std::vector<std::uint16_t> sites(w * h);
    for (std::uint32_t r = 0; r < h; ++r)
        for (std::uint32_t x = 0; x < w; ++x)
            sites[r * w + x] =
                static_cast<std::uint16_t>(100 + 37 * r + 11 * x + 500 * (r % 2) + 700 * (x % 2));
    sites[0] = 4095;    // a saturated red site in block (0, 0)
    sites[w + 1] = 50;  // a blue site below its black level in block (0, 0)
    const ByteVector file = testing::bayer_dng(w, h, sites, {60, 62, 64, 66}, white);
    const LinearImage image = decode(file, {}, "bayer.dng");
    ASSERT_EQ(image.channels, 3U);
    ASSERT_EQ(image.width, 12U);
    ASSERT_EQ(image.height, 11U);
    EXPECT_EQ(image.info.white_level_dn, 4095.0);
    EXPECT_EQ(image.info.black_level_dn, (std::vector<double>{60.0, 63.0, 66.0}));
    EXPECT_NEAR(image.info.exposure_s.value_or(0), 1.0 / 250.0, 1e-9);  // LibRaw: float
    EXPECT_NEAR(image.info.f_number.value_or(0), 8.0, 1e-6);
    EXPECT_NEAR(image.info.iso.value_or(0), 400.0, 1e-6);
    for (std::size_t by = 0; by < 11; ++by)
        for (std::size_t bx = 0; bx < 12; ++bx) {
            const auto at = [&](std::size_t i, std::size_t j) {
                return static_cast<double>(sites[(2 * by + i) * w + 2 * bx + j]);
            };
            EXPECT_NEAR(image.value(0, by, bx), (at(0, 0) - 60.0) / (white - 60.0), 1e-6);
            EXPECT_NEAR(image.value(1, by, bx),
                        ((at(0, 1) - 62.0) + (at(1, 0) - 64.0)) / 2.0 / (white - 63.0), 1e-6);
            EXPECT_NEAR(image.value(2, by, bx), (at(1, 1) - 66.0) / (white - 66.0), 1e-6);
            const std::uint8_t expected =
                by == 0 && bx == 0 ? kPixelSaturated | kPixelClippedLow : 0;
            EXPECT_EQ(image.flags[by * 12 + bx], expected);
        }
}

TEST(ReadRaw, BlackLevelsRepeatingOverFourColumnsFollowEverySite) {
    // BlackLevelRepeatDim 1 x 4: the black level of a site depends on its column modulo 4 (60,
    // 61, 62, 63), across the Bayer blocks: R sites (even columns) alternate 60/62, mean 61; G
    // sites 61/63 and 60/62, mean 61.5; B sites 61/63, mean 62.
    const std::uint32_t w = 24;
    const std::uint32_t h = 22;
    std::vector<std::uint16_t> sites(w * h);
    for (std::uint32_t i = 0; i < w * h; ++i)
        sites[i] = static_cast<std::uint16_t>(200 + (i * 37) % 1500);
    const double white = 4000;
    const ByteVector file =
        testing::bayer_dng(w, h, sites, {60, 61, 62, 63}, 4000, {{1, 1}, {1, 1}, {1, 1}}, {1, 4});
    const LinearImage image = decode(file);
    EXPECT_EQ(image.info.black_level_dn, (std::vector<double>{61.0, 61.5, 62.0}));
    for (std::size_t by = 0; by < 11; ++by)
        for (std::size_t bx = 0; bx < 12; ++bx) {
            const auto at = [&](std::size_t i, std::size_t j) {
                const std::size_t col = 2 * bx + j;
                return static_cast<double>(sites[(2 * by + i) * w + col]) - (60.0 + col % 4);
            };
            EXPECT_NEAR(image.value(0, by, bx), at(0, 0) / (white - 61.0), 1e-6);
            EXPECT_NEAR(image.value(1, by, bx), (at(0, 1) + at(1, 0)) / 2.0 / (white - 61.5), 1e-6);
            EXPECT_NEAR(image.value(2, by, bx), at(1, 1) / (white - 62.0), 1e-6);
        }
}

TEST(ReadRaw, WhiteBalanceIsOffUnlessAskedThenTheAsShotMultipliers) {
    const std::uint32_t w = 22;
    const std::uint32_t h = 22;
    const std::vector<std::uint16_t> sites(w * h, 1000);
    // AsShotNeutral (0.5, 1, 0.8): multipliers 1/neutral = (2, 1, 1.25).
    const ByteVector file = testing::bayer_dng(w, h, sites, {0}, 4000, {{1, 2}, {1, 1}, {4, 5}});
    const LinearImage plain = decode(file);
    for (std::size_t c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(plain.plane(c)[0], 0.25F);
    ReadOptions options;
    options.white_balance = true;
    const LinearImage balanced = decode(file, options);
    EXPECT_FLOAT_EQ(balanced.plane(0)[0], 0.5F);
    EXPECT_FLOAT_EQ(balanced.plane(1)[0], 0.25F);
    EXPECT_FLOAT_EQ(balanced.plane(2)[0], 0.3125F);
    // Given levels replace LibRaw's.
    options.white_balance = false;
    options.black_level_dn = std::vector<double>{200.0};
    options.white_level_dn = 1800.0;
    const LinearImage levels = decode(file, options);
    EXPECT_FLOAT_EQ(levels.plane(1)[0], 0.5F);
    EXPECT_EQ(levels.info.black_level_dn, (std::vector<double>{200.0, 200.0, 200.0}));
}

// ---- JPEG and EXIF -----------------------------------------------------------------------------

// A JPEG of a flat colour (OpenCV's encoder, quality 100) with an APP1 EXIF segment spliced in
// after SOI.
ByteVector jpeg_with_exif(const cv::Scalar& bgr, const ByteVector& exif_tiff) {
    const cv::Mat image(16, 24, CV_8UC3, bgr);
    std::vector<std::uint8_t> jpeg;
    cv::imencode(".jpg", image, jpeg, {cv::IMWRITE_JPEG_QUALITY, 100});
    ByteVector app1 = {0xff, 0xe1, 0, 0, 'E', 'x', 'i', 'f', 0, 0};
    app1.insert(app1.end(), exif_tiff.begin(), exif_tiff.end());
    const std::size_t length = app1.size() - 2;
    app1[2] = static_cast<std::uint8_t>(length >> 8);
    app1[3] = static_cast<std::uint8_t>(length & 0xff);
    // push_back, not insert: GCC 12 warns falsely (-Warray-bounds) on inserting ranges here.
    ByteVector out = {jpeg[0], jpeg[1]};
    for (const std::uint8_t byte : app1) out.push_back(byte);
    for (std::size_t i = 2; i < jpeg.size(); ++i) out.push_back(jpeg[i]);
    return out;
}

TEST(ReadJpeg, ExifExposureAndSrgbValuesToAFewCodes) {
    const ByteVector exif =
        testing::tiff_file({testing::shorts(274, {6})}, {}, testing::exif_exposure(125, 56, 200));
    const ByteVector file = jpeg_with_exif(cv::Scalar(40, 120, 200), exif);  // B, G, R
    const LinearImage image = decode(file, {}, "photo.jpg");
    EXPECT_EQ(image.info.format, "jpeg");
    ASSERT_EQ(image.channels, 3U);
    EXPECT_EQ(image.width, 24U);
    EXPECT_EQ(image.info.response, Response::Srgb);
    EXPECT_EQ(image.info.file_response, Response::Srgb);
    EXPECT_TRUE(contains(image.info.file_response_evidence, "EXIF ColorSpace sRGB"));
    EXPECT_DOUBLE_EQ(image.info.exposure_s.value_or(0), 1.0 / 125.0);
    EXPECT_DOUBLE_EQ(image.info.f_number.value_or(0), 5.6);
    EXPECT_DOUBLE_EQ(image.info.iso.value_or(0), 200.0);
    ASSERT_EQ(image.info.warnings.size(), 1U);
    EXPECT_TRUE(contains(image.info.warnings[0], "orientation 6"));
    const double codes[3] = {200, 120, 40};  // R, G, B
    for (std::size_t c = 0; c < 3; ++c)
        for (std::size_t i = 0; i < image.pixel_count(); ++i) {
            EXPECT_GE(image.plane(c)[i], testing::srgb_to_linear((codes[c] - 3) / 255.0));
            EXPECT_LE(image.plane(c)[i], testing::srgb_to_linear((codes[c] + 3) / 255.0));
        }
}

TEST(ReadJpeg, CorruptDataIsADataErrorAndNothingIsPrinted) {
    const ByteVector good = jpeg_with_exif(cv::Scalar(10, 20, 30), testing::tiff_file({}, {}, {}));
    // Three stray bytes before the start-of-scan marker: libjpeg warns ("extraneous bytes").
    ByteVector stray;
    for (std::size_t i = 0; i < good.size(); ++i) {
        if (i + 1 < good.size() && good[i] == 0xff && good[i + 1] == 0xda)
            for (int k = 0; k < 3; ++k) stray.push_back(0);
        stray.push_back(good[i]);
    }
    ByteVector truncated(good.begin(),
                         good.begin() + static_cast<std::ptrdiff_t>(good.size() - 40));
    ::testing::internal::CaptureStderr();
    expect_error<DataError>([&] { decode(stray, {}, "stray.jpg"); }, {"stray.jpg", "libjpeg"});
    expect_error<DataError>([&] { decode(truncated, {}, "cut.jpg"); }, {"cut.jpg", "libjpeg"});
    EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
    EXPECT_NO_THROW(decode(good));
}

TEST(ReadPng, ExifChunkGivesTheExposure) {
    testing::PngSpec spec;
    spec.samples = {90};
    spec.exif = testing::tiff_file({}, {}, testing::exif_exposure(4, 20, 800));
    const LinearImage image = decode(testing::png_bytes(spec));
    EXPECT_DOUBLE_EQ(image.info.exposure_s.value_or(0), 0.25);
    EXPECT_DOUBLE_EQ(image.info.f_number.value_or(0), 2.0);
    EXPECT_DOUBLE_EQ(image.info.iso.value_or(0), 800.0);
}

// ---- files and dispatch ------------------------------------------------------------------------

TEST(ReadImage, ReadsFromAFileAndTheFormatComesFromTheBytesNotTheName) {
    testing::PngSpec spec;
    spec.samples = {51};
    spec.srgb_chunk = true;
    const fs::path path =
        roughscope::testing::write_bytes(testing::png_bytes(spec), "imgread_magic", "photo.tif");
    const LinearImage image = read_image(path.string());
    EXPECT_EQ(image.info.format, "png");
    EXPECT_EQ(image.info.source, path.string());
    EXPECT_NEAR(image.values[0], testing::srgb_to_linear(0.2), 2e-7);
}

// ---- failures ----------------------------------------------------------------------------------

TEST(ReadImage, MissingDirectoryAndEmptyFilesAreDataErrorsNamingThePath) {
    const fs::path dir = roughscope::testing::fresh_dir("imgread_missing");
    const std::string missing = (dir / "nothing.png").string();
    expect_error<DataError>([&] { read_image(missing); }, {"nothing.png", "no such file"});
    expect_error<DataError>([&] { read_image(dir.string()); }, {"directory"});
    const fs::path empty = roughscope::testing::write_bytes({}, "imgread_empty", "empty.png");
    expect_error<DataError>([&] { read_image(empty.string()); }, {"empty.png", "empty"});
}

TEST(ReadImage, TruncatedAndCorruptFilesAreDataErrorsNamingTheFile) {
    testing::PngSpec spec;
    spec.width = 64;
    spec.height = 64;
    spec.depth = 16;
    for (int i = 0; i < 64 * 64; ++i) spec.samples.push_back(static_cast<std::uint16_t>(i * 13));
    ByteVector png = testing::png_bytes(spec);
    png.resize(png.size() * 3 / 5);
    const fs::path path = roughscope::testing::write_bytes(png, "imgread_trunc", "cut.png");
    expect_error<DataError>([&] { read_image(path.string()); }, {"cut.png", "PNG"});

    const std::vector<std::uint16_t> samples(32 * 32, 500);
    ByteVector tiff = testing::tiff_image(32, 32, 1, 16, 1, testing::raw_bytes(samples));
    tiff.resize(1000);  // the IFD (after the pixels) is gone
    expect_error<DataError>([&] { decode(tiff, {}, "cut.tif"); }, {"cut.tif", "TIFF"});

    ByteVector jpeg = jpeg_with_exif(cv::Scalar(1, 2, 3), testing::tiff_file({}, {}, {}));
    jpeg.resize(jpeg.size() / 2);
    expect_error<DataError>([&] { decode(jpeg, {}, "cut.jpg"); }, {"cut.jpg", "JPEG"});

    const ByteVector garbage = as_bytes("this is not a photograph, just some text\n");
    expect_error<DataError>([&] { decode(garbage, {}, "notes.png"); },
                            {"notes.png", "not a PNG, JPEG, TIFF or camera RAW"});
}

TEST(ReadImage, UnsupportedDepthsLayoutsAndHugeImagesAreDataErrors) {
    testing::PngSpec four_bit;
    four_bit.depth = 4;
    four_bit.samples = {3};
    expect_error<DataError>([&] { decode(testing::png_bytes(four_bit), {}, "g4.png"); },
                            {"g4.png", "4-bit", "valid: 8 or 16"});

    const ByteVector signed16 = testing::tiff_image(1, 1, 1, 16, 2, {1, 0});
    expect_error<DataError>([&] { decode(signed16, {}, "s16.tif"); },
                            {"s16.tif", "sample format 2"});

    // A 1 x 1 PNG whose header is patched to 20001 x 20000 pixels (CRC recomputed).
    testing::PngSpec one;
    one.samples = {0};
    ByteVector huge = testing::png_bytes(one);
    auto be32 = [&](std::size_t at, std::uint32_t v) {
        for (int k = 0; k < 4; ++k) huge[at + k] = static_cast<std::uint8_t>(v >> (24 - 8 * k));
    };
    be32(16, 20001);  // IHDR width, height
    be32(20, 20000);
    be32(29, static_cast<std::uint32_t>(crc32(0, huge.data() + 12, 17)));
    expect_error<DataError>([&] { decode(huge, {}, "huge.png"); },
                            {"huge.png", "20001 x 20000", "400000000"});
}

TEST(ReadImage, NaNFloatSamplesAreMissingAndInfiniteOnesDataErrors) {
    // NaN marks a missing value in float rasters: the pixel is flagged kPixelMissing, value 0.
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const std::vector<float> grey = {0.5F, nan, 0.25F};
    const LinearImage g =
        decode(testing::tiff_image(3, 1, 1, 32, 3, testing::raw_bytes(grey)), {}, "nan.tif");
    EXPECT_EQ(g.flags, (std::vector<std::uint8_t>{0, kPixelMissing, 0}));
    EXPECT_EQ(std::vector<float>(g.values.begin(), g.values.end()),
              (std::vector<float>{0.5F, 0.0F, 0.25F}));
    // RGB (interleaved): one NaN channel flags the pixel; its other channels are kept.
    const std::vector<float> rgb = {0.1F, 0.2F, 0.3F, 0.4F, nan, 0.6F};
    const LinearImage c =
        decode(testing::tiff_image(2, 1, 3, 32, 3, testing::raw_bytes(rgb)), {}, "nan3.tif");
    EXPECT_EQ(c.flags, (std::vector<std::uint8_t>{0, kPixelMissing}));
    EXPECT_EQ(std::vector<float>(c.values.begin(), c.values.end()),
              (std::vector<float>{0.1F, 0.4F, 0.2F, 0.0F, 0.3F, 0.6F}));  // planar
    const std::vector<float> inf = {0.5F, -std::numeric_limits<float>::infinity()};
    const ByteVector file = testing::tiff_image(2, 1, 1, 32, 3, testing::raw_bytes(inf));
    expect_error<DataError>([&] { decode(file, {}, "inf.tif"); },
                            {"inf.tif", "column 1", "is infinite", "NaN for a missing one"});
}

TEST(ReadImage, ValuesBeyondTheFloatRangeAreRefused) {
    // A float sample of 1e30 through gamma 2.2 is 1e66: a DataError naming the sample.
    const std::vector<float> samples = {0.5F, 1e30F};
    ReadOptions gamma;
    gamma.response = Response::Gamma;
    gamma.gamma = 2.2;
    const ByteVector file = testing::tiff_image(2, 1, 1, 32, 3, testing::raw_bytes(samples));
    EXPECT_NO_THROW(decode(file));  // linear: 1e30 fits a float
    expect_error<DataError>([&] { decode(file, gamma, "big.tif"); },
                            {"big.tif", "column 1", "beyond the float range"});
    // Integer codes: a white level of 1e-40 DN would make 255 into 2.55e42.
    testing::PngSpec spec;
    spec.samples = {255};
    ReadOptions tiny_white;
    tiny_white.white_level_dn = 1e-40;
    expect_error<InvalidArgument>([&] { decode(testing::png_bytes(spec), tiny_white, "w.png"); },
                                  {"w.png", "white level 1e-40", "beyond the float range"});
}

TEST(ReadOptionsCheck, BadOptionsAreInvalidArgumentsNamingTheField) {
    ReadOptions gamma_without_response;
    gamma_without_response.gamma = 2.2;
    expect_error<InvalidArgument>([&] { check_read_options(gamma_without_response); },
                                  {"gamma", "response gamma"});
    ReadOptions bad_gamma;
    bad_gamma.response = Response::Gamma;
    bad_gamma.gamma = -1.0;
    expect_error<InvalidArgument>([&] { check_read_options(bad_gamma); }, {"gamma = -1", "> 0"});
    ReadOptions nan_black;
    nan_black.black_level_dn = std::vector<double>{std::nan("")};
    expect_error<InvalidArgument>([&] { check_read_options(nan_black); },
                                  {"black_level_dn[0]", ">= 0"});
    ReadOptions two_blacks;
    two_blacks.black_level_dn = std::vector<double>{1.0, 2.0};
    expect_error<InvalidArgument>([&] { check_read_options(two_blacks); },
                                  {"black_level_dn has 2 values"});
    ReadOptions zero_white;
    zero_white.white_level_dn = 0.0;
    expect_error<InvalidArgument>([&] { check_read_options(zero_white); },
                                  {"white_level_dn = 0", "> 0"});
    ReadOptions crossed;
    crossed.black_level_dn = std::vector<double>{100.0};
    crossed.white_level_dn = 100.0;
    expect_error<InvalidArgument>([&] { check_read_options(crossed); },
                                  {"black_level_dn[0] = 100", "white_level_dn = 100"});
    // Options are checked before the file is touched.
    expect_error<InvalidArgument>([&] { read_image("/nonexistent/x.png", bad_gamma); }, {"gamma"});
    ReadOptions ok;
    ok.response = Response::Gamma;
    ok.gamma = 2.2;
    ok.black_level_dn = std::vector<double>{1.0, 2.0, 3.0};
    ok.white_level_dn = 4.0;
    EXPECT_NO_THROW(check_read_options(ok));
}

TEST(ReadOptionsCheck, PerPlaneBlackLevelsMustMatchThePlanes) {
    testing::PngSpec spec;
    spec.samples = {9};
    ReadOptions options;
    options.black_level_dn = std::vector<double>{1.0, 2.0, 3.0};
    expect_error<InvalidArgument>([&] { decode(testing::png_bytes(spec), options, "grey.png"); },
                                  {"black_level_dn has 3 values", "grey.png", "1 plane"});
    options.black_level_dn = std::vector<double>{300.0};  // above the 8-bit full scale
    expect_error<InvalidArgument>([&] { decode(testing::png_bytes(spec), options, "grey.png"); },
                                  {"grey.png", "not below the white level 255"});
}

TEST(Linearizer, AnImageIsHandedOutOnlyWhenEveryRowOfEveryPlaneWasWritten) {
    // The values are allocated without a fill: finish() names the first row no put() wrote, so a
    // decoder that stops early never passes uninitialised values on.
    detail::Layout layout;
    layout.width = 4;
    layout.height = 3;
    layout.channels = 3;
    layout.bits = 16;
    layout.full_scale = 65535.0;
    const std::vector<std::uint16_t> row(12, 1000);
    {
        LinearImage image;
        image.info.source = "rows.tif";
        detail::Linearizer lin(image, layout, {}, {});
        lin.put_pixels(row.data(), 0, 3, {0, 1, 2});
        lin.put_pixels(row.data(), 2, 3, {0, 1, 2});
        expect_error<DataError>([&] { lin.finish(); }, {"rows.tif", "row 1 of plane 0"});
        lin.put_pixels(row.data(), 1, 3, {0, 1, 2});
        EXPECT_NO_THROW(lin.finish());
        EXPECT_FLOAT_EQ(image.value(2, 1, 3), 1000.0F / 65535.0F);
    }
    {
        // Planes one at a time (a planar TIFF): a plane left out is named.
        LinearImage image;
        image.info.source = "planar.tif";
        detail::Linearizer lin(image, layout, {}, {});
        for (std::size_t r = 0; r < 3; ++r) {
            lin.put(row.data(), r, 1, 0, 0);
            lin.put(row.data(), r, 1, 0, 2);
        }
        expect_error<DataError>([&] { lin.finish(); }, {"planar.tif", "row 0 of plane 1"});
    }
}

}  // namespace
}  // namespace roughscope::image
