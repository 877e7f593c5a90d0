// Map files (image/map_files.hpp): the float TIFF read back by the project's reader and by
// libtiff directly, the .npy header parsed from the NumPy format specification, the PNGs decoded
// by libpng.
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <png.h>
#include <tiffio.h>

#include "../io/test_files.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/io/output_file.hpp"
#include "roughscope/maps/map_files.hpp"
#include "roughscope/maps/maps.hpp"
#include "roughscope/photo/read.hpp"

namespace roughscope::image {
namespace {

namespace fs = std::filesystem;

std::vector<float> ramp(std::size_t w, std::size_t h) {
    std::vector<float> v(w * h);
    for (std::size_t i = 0; i < v.size(); ++i)
        v[i] = static_cast<float>(0.001 * static_cast<double>(i) + 1.0 / 3.0);
    return v;
}

std::vector<float> read_tiff_with_libtiff(const fs::path& path, std::size_t& w, std::size_t& h) {
    TIFF* tif = TIFFOpen(path.c_str(), "r");
    EXPECT_NE(tif, nullptr);
    std::uint32_t width = 0, height = 0;
    std::uint16_t bits = 0, format = 0, samples = 0;
    TIFFGetField(tif, TIFFTAG_IMAGEWIDTH, &width);
    TIFFGetField(tif, TIFFTAG_IMAGELENGTH, &height);
    TIFFGetField(tif, TIFFTAG_BITSPERSAMPLE, &bits);
    TIFFGetField(tif, TIFFTAG_SAMPLEFORMAT, &format);
    TIFFGetField(tif, TIFFTAG_SAMPLESPERPIXEL, &samples);
    EXPECT_EQ(bits, 32);
    EXPECT_EQ(format, SAMPLEFORMAT_IEEEFP);
    EXPECT_EQ(samples, 1);
    w = width;
    h = height;
    std::vector<float> out(static_cast<std::size_t>(width) * height);
    for (std::uint32_t r = 0; r < height; ++r)
        EXPECT_EQ(TIFFReadScanline(tif, out.data() + static_cast<std::size_t>(r) * width, r, 0), 1);
    TIFFClose(tif);
    return out;
}

bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(MapFiles, FloatTiffReadsBackBitExactly) {
    const fs::path dir = roughscope::testing::fresh_dir("map_files_tiff");
    const std::size_t W = 37, H = 23;
    const std::vector<float> layer = ramp(W, H);
    const fs::path path = dir / "layer.tiff";
    io::write_file_atomic(path, encode_map_tiff_float(layer, W, H));
    // libtiff directly.
    std::size_t w = 0, h = 0;
    const std::vector<float> direct = read_tiff_with_libtiff(path, w, h);
    ASSERT_EQ(w, W);
    ASSERT_EQ(h, H);
    // The project's reader (a float TIFF is read unscaled: white level 1, black 0).
    const LinearImage image = read_image(path.string());
    ASSERT_EQ(image.width, W);
    ASSERT_EQ(image.height, H);
    ASSERT_EQ(image.channels, 1u);
    for (std::size_t i = 0; i < layer.size(); ++i) {
        EXPECT_TRUE(same_bits(direct[i], layer[i])) << i;
        EXPECT_TRUE(same_bits(image.values[i], layer[i])) << i;
    }
    // Missing values stay NaN in the file (libtiff); the photograph reader flags them missing
    // (value 0) and reads every other cell bit for bit.
    std::vector<float> holes = layer;
    holes[5] = std::numeric_limits<float>::quiet_NaN();
    holes[W * 3 + 7] = std::numeric_limits<float>::quiet_NaN();
    const fs::path hpath = dir / "holes.tiff";
    io::write_file_atomic(hpath, encode_map_tiff_float(holes, W, H));
    const std::vector<float> back = read_tiff_with_libtiff(hpath, w, h);
    EXPECT_TRUE(std::isnan(back[5]));
    EXPECT_TRUE(same_bits(back[6], holes[6]));
    const LinearImage with_holes = read_image(hpath.string());
    EXPECT_EQ(count_flagged(with_holes, kPixelMissing), 2u);
    for (std::size_t i = 0; i < holes.size(); ++i) {
        if (std::isnan(holes[i])) {
            EXPECT_EQ(with_holes.flags[i], kPixelMissing) << i;
            EXPECT_EQ(with_holes.values[i], 0.0F) << i;
        } else {
            EXPECT_EQ(with_holes.flags[i] & kPixelMissing, 0) << i;
            EXPECT_TRUE(same_bits(with_holes.values[i], holes[i])) << i;
        }
    }
    // An infinite sample is not a missing value: refused, naming it.
    std::vector<float> inf = layer;
    inf[9] = std::numeric_limits<float>::infinity();
    const fs::path ipath = dir / "inf.tiff";
    io::write_file_atomic(ipath, encode_map_tiff_float(inf, W, H));
    try {
        (void)read_image(ipath.string());
        FAIL() << "expected DataError";
    } catch (const DataError& e) {
        EXPECT_NE(std::string(e.what()).find("is infinite"), std::string::npos) << e.what();
    }
}

TEST(MapFiles, NpyFollowsTheFormatSpecification) {
    const std::size_t W = 5, H = 3;
    std::vector<float> layer = ramp(W, H);
    layer[7] = std::numeric_limits<float>::quiet_NaN();
    const std::string npy = encode_npy(layer, W, H);
    // Magic string, version 1.0.
    ASSERT_GE(npy.size(), 10u);
    EXPECT_EQ(npy.substr(0, 6), std::string("\x93NUMPY", 6));
    EXPECT_EQ(npy[6], '\x01');
    EXPECT_EQ(npy[7], '\x00');
    const std::size_t header_len =
        static_cast<unsigned char>(npy[8]) |
        (static_cast<std::size_t>(static_cast<unsigned char>(npy[9])) << 8);
    const std::size_t data_start = 10 + header_len;
    EXPECT_EQ(data_start % 64, 0u);  // the spec: total header a multiple of 64 (numpy ≥ 1.9)
    const std::string header = npy.substr(10, header_len);
    EXPECT_EQ(header.back(), '\n');
    EXPECT_NE(header.find("'descr': '<f4'"), std::string::npos) << header;
    EXPECT_NE(header.find("'fortran_order': False"), std::string::npos) << header;
    EXPECT_NE(header.find("'shape': (3, 5)"), std::string::npos) << header;
    ASSERT_EQ(npy.size(), data_start + 4 * W * H);
    for (std::size_t i = 0; i < layer.size(); ++i) {
        std::uint32_t bits = 0;
        for (int b = 0; b < 4; ++b)
            bits |=
                static_cast<std::uint32_t>(static_cast<unsigned char>(npy[data_start + 4 * i + b]))
                << (8 * b);
        float v = 0.0f;
        std::memcpy(&v, &bits, 4);
        EXPECT_TRUE(same_bits(v, layer[i])) << i;
    }
}

struct DecodedPng {
    std::uint32_t width = 0, height = 0;
    int color_type = 0, depth = 0;
    std::vector<std::uint8_t> rgb;
    std::array<std::uint8_t, 3> at(std::uint32_t x, std::uint32_t y) const {
        const std::size_t i = (static_cast<std::size_t>(y) * width + x) * 3;
        return {rgb[i], rgb[i + 1], rgb[i + 2]};
    }
};

DecodedPng decode_png(const std::string& bytes) {
    png_image image{};
    image.version = PNG_IMAGE_VERSION;
    EXPECT_NE(png_image_begin_read_from_memory(&image, bytes.data(), bytes.size()), 0);
    DecodedPng out;
    out.width = image.width;
    out.height = image.height;
    out.color_type = (image.format & PNG_FORMAT_FLAG_COLOR) ? PNG_COLOR_TYPE_RGB : 0;
    image.format = PNG_FORMAT_RGB;
    out.rgb.resize(PNG_IMAGE_SIZE(image));
    EXPECT_NE(png_image_finish_read(&image, nullptr, out.rgb.data(), 0, nullptr), 0);
    // Bit depth from IHDR (byte 24 of the file).
    out.depth = static_cast<unsigned char>(bytes[24]);
    return out;
}

TEST(MapFiles, FalseColourPngHasTheColourMapAndABar) {
    const std::size_t W = 64, H = 32;
    std::vector<float> layer(W * H);
    for (std::size_t r = 0; r < H; ++r)
        for (std::size_t x = 0; x < W; ++x) layer[r * W + x] = static_cast<float>(x) / (W - 1);
    layer[0] = std::numeric_limits<float>::quiet_NaN();
    const ColourRange range{0.0, 1.0};
    const DecodedPng png = decode_png(encode_map_png(layer, W, H, range, "sigma/T (Gaussian)"));
    // 64 px → enlarged 4× to 256; a 90 px bar panel; at least 200 + 22 px high.
    EXPECT_EQ(png.width, 256u + 90u);
    EXPECT_EQ(png.height, 200u + 22u);
    EXPECT_EQ(png.depth, 8);
    EXPECT_EQ(png.color_type, PNG_COLOR_TYPE_RGB);
    // Pixel (x = 40, row 10) of the map: value 40/63 → VIRIDIS (OpenCV's table, independently
    // known endpoints: dark purple at 0, yellow at 1).
    EXPECT_EQ(png.at(40 * 4 + 1, 10 * 4 + 1), map_colour(layer[10 * W + 40], range));
    const auto low = map_colour(0.0f, range), high = map_colour(1.0f, range);
    EXPECT_GT(high[0], 200);  // yellow
    EXPECT_GT(high[1], 200);
    EXPECT_LT(high[2], 80);
    EXPECT_LT(low[1], 30);  // dark purple
    EXPECT_GT(low[2], 60);
    // The missing pixel: grey.
    EXPECT_EQ(png.at(1, 1),
              (std::array<std::uint8_t, 3>{kMissingGrey, kMissingGrey, kMissingGrey}));
    // The bar: its top is the colour of the upper end, its bottom the lower end.
    EXPECT_EQ(png.at(256 + 18, 12), high);
    EXPECT_EQ(png.at(256 + 18, 200 - 12), low);
    // The tick labels are drawn (dark pixels right of the bar).
    std::size_t dark = 0;
    for (std::uint32_t y = 0; y < 200; ++y)
        for (std::uint32_t x = 256 + 34; x < 256 + 90; ++x) {
            const auto c = png.at(x, y);
            if (c[0] < 100 && c[1] < 100 && c[2] < 100) ++dark;
        }
    EXPECT_GT(dark, 50u);
}

TEST(MapFiles, ClassPngHasTheClassColoursAndALegend) {
    const std::size_t W = 3, H = 2;
    const std::vector<std::uint8_t> classes{kClassSlightlyRough, kClassModeratelyRough,
                                            kClassVeryRough,     kClassNone,
                                            kClassVeryRough,     kClassSlightlyRough};
    const DecodedPng png = decode_png(encode_class_png(classes, W, H));
    // 3 px → enlarged 64× to 192 px (the cap), legend 150 px.
    EXPECT_EQ(png.width, 192u + 150u);
    EXPECT_EQ(png.height, 128u);
    for (std::size_t i = 0; i < classes.size(); ++i) {
        const auto got = png.at(static_cast<std::uint32_t>((i % W) * 64 + 32),
                                static_cast<std::uint32_t>((i / W) * 64 + 32));
        const std::array<std::uint8_t, 3> want =
            classes[i] < 3 ? kClassColours[classes[i]]
                           : std::array<std::uint8_t, 3>{kMissingGrey, kMissingGrey, kMissingGrey};
        EXPECT_EQ(got, want) << i;
    }
    // The legend's swatches.
    EXPECT_EQ(png.at(192 + 15, 10 + 7), kClassColours[0]);
    EXPECT_EQ(png.at(192 + 15, 32 + 7), kClassColours[1]);
    EXPECT_EQ(png.at(192 + 15, 54 + 7), kClassColours[2]);
}

TEST(MapFiles, BadInput) {
    const std::vector<float> layer(12, 1.0f);
    EXPECT_THROW(encode_map_tiff_float(layer, 5, 2), InvalidArgument);
    EXPECT_THROW(encode_npy(layer, 0, 12), InvalidArgument);
    EXPECT_THROW(encode_map_png(layer, 4, 3, {1.0, 1.0}, "x"), InvalidArgument);
    EXPECT_THROW(encode_map_png(layer, 4, 3, {0.0, std::nan("")}, "x"), InvalidArgument);
    EXPECT_THROW(encode_map_png(layer, 6, 3, {0.0, 1.0}, "x"), InvalidArgument);
    EXPECT_THROW(encode_class_png(std::vector<std::uint8_t>(5), 2, 3), InvalidArgument);
    // finite_range ignores NaN, widens a constant layer.
    const std::vector<float> v{std::nanf(""), 2.0f, 4.0f};
    EXPECT_EQ(finite_range(v).lower, 2.0);
    EXPECT_EQ(finite_range(v).upper, 4.0);
    const std::vector<float> c{3.0f, 3.0f};
    EXPECT_LT(finite_range(c).lower, finite_range(c).upper);
}

}  // namespace
}  // namespace roughscope::image
