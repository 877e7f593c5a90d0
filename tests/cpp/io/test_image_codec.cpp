// io's PNG and TIFF codecs (src/io/png_codec.hpp, tiff_codec.hpp): encode → decode round trips of
// every sample type the callers use, files of an independent writer (libpng called directly,
// tests/cpp/photo/image_files.hpp) decoded, a float TIFF read back by libtiff directly, and
// broken files as DataErrors naming them.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <tiffio.h>

#include "../photo/image_files.hpp"
#include "io/png_codec.hpp"
#include "io/tiff_codec.hpp"
#include "roughscope/core/errors.hpp"

namespace {

namespace codec = roughscope::io::codec;
using roughscope::DataError;

// Samples x · 7 + y · 13 + c · 5 (mod the type's range), interleaved.
template <class T>
std::vector<T> pattern(std::size_t w, std::size_t h, std::size_t channels, double top) {
    std::vector<T> v(w * h * channels);
    for (std::size_t y = 0; y < h; ++y)
        for (std::size_t x = 0; x < w; ++x)
            for (std::size_t c = 0; c < channels; ++c)
                v[(y * w + x) * channels + c] =
                    static_cast<T>(std::fmod(x * 7.0 + y * 13.0 * 251.0 + c * 5.0, top));
    return v;
}

template <class T>
void expect_samples(const codec::ImageBuffer& image, const std::vector<T>& expected, std::size_t w,
                    std::size_t h, std::size_t channels) {
    ASSERT_EQ(image.width, w);
    ASSERT_EQ(image.height, h);
    ASSERT_EQ(image.channels, channels);
    ASSERT_EQ(image.type.bytes(), sizeof(T));
    for (std::size_t y = 0; y < h; ++y)
        for (std::size_t x = 0; x < w; ++x)
            for (std::size_t c = 0; c < channels; ++c)
                ASSERT_EQ(image.sample(x, y, c),
                          static_cast<double>(expected[(y * w + x) * channels + c]))
                    << x << ", " << y << ", " << c;
}

template <class T>
void png_round_trip(std::size_t channels, const codec::PngEncodeOptions& options = {}) {
    const std::size_t w = 13;
    const std::size_t h = 5;
    const auto samples = pattern<T>(w, h, channels, sizeof(T) == 1 ? 256.0 : 65536.0);
    const int bits = static_cast<int>(8 * sizeof(T));
    const std::string file =
        codec::encode_png({samples.data(), w, h, channels, {bits, false}, 0}, options);
    expect_samples(codec::decode_png(codec::as_bytes(file), "rt.png"), samples, w, h, channels);
}

template <class T>
void tiff_round_trip(std::size_t channels, bool is_float) {
    const std::size_t w = 11;
    const std::size_t h = 7;
    auto samples = pattern<T>(w, h, channels, is_float ? 1e9 : (sizeof(T) == 1 ? 256.0 : 65536.0));
    if (is_float) {
        samples[3] = static_cast<T>(-0.1);
        samples[5] = std::numeric_limits<T>::quiet_NaN();
    }
    const int bits = static_cast<int>(8 * sizeof(T));
    const std::string file =
        codec::encode_tiff({samples.data(), w, h, channels, {bits, is_float}, 0});
    const codec::ImageBuffer image = codec::decode_tiff(codec::as_bytes(file), "rt.tif");
    EXPECT_EQ(image.type.is_float, is_float);
    if (is_float) {
        EXPECT_TRUE(std::isnan(image.sample(5, 0)));
        samples[5] = 0;
        auto copy = image;
        const T zero = 0;
        std::memcpy(copy.data.data() + 5 * sizeof(T), &zero, sizeof(T));
        expect_samples(copy, samples, w, h, channels);
        return;
    }
    expect_samples(image, samples, w, h, channels);
}

TEST(PngCodec, RoundTripsEightAndSixteenBitGreyAndColour) {
    png_round_trip<std::uint8_t>(1);
    png_round_trip<std::uint8_t>(3);
    png_round_trip<std::uint16_t>(1);
    png_round_trip<std::uint16_t>(3);
    png_round_trip<std::uint8_t>(2);
    png_round_trip<std::uint16_t>(4);
    codec::PngEncodeOptions fast;  // the captures' settings
    fast.compression_level = 1;
    fast.filter = false;
    fast.significant_bits = 12;
    png_round_trip<std::uint16_t>(1, fast);
}

TEST(PngCodec, EncodesRowsWithAStrideAndWritesTheChunksItIsAskedFor) {
    // Rows of 3 RGB pixels, 16 bytes apart (as a cv::Mat with padding).
    std::vector<std::uint8_t> padded(16 * 2, 0xEE);
    for (std::size_t r = 0; r < 2; ++r)
        for (std::size_t i = 0; i < 9; ++i)
            padded[r * 16 + i] = static_cast<std::uint8_t>(r * 9 + i);
    codec::PngEncodeOptions options;
    options.significant_bits = 5;
    const std::string file = codec::encode_png({padded.data(), 3, 2, 3, {8, false}, 16}, options);
    codec::PngDecoder png(codec::as_bytes(file), "stride.png");
    const codec::PngHeader& h = png.read_header();
    EXPECT_EQ(h.width, 3U);
    EXPECT_EQ(h.height, 2U);
    EXPECT_EQ(h.colour_type, static_cast<int>(codec::PngColour::Rgb));
    EXPECT_EQ(h.significant_bits, 5);
    std::vector<std::uint8_t> rows(png.row_bytes() * 2);
    png.read_rows(rows.data(), 2);
    png.read_end();
    for (std::size_t i = 0; i < rows.size(); ++i) EXPECT_EQ(rows[i], i);
}

TEST(PngCodec, DecodesAnIndependentWritersFileWithItsChunks) {
    namespace t = roughscope::testing;
    t::PngSpec spec;
    spec.width = 3;
    spec.height = 2;
    spec.depth = 16;
    spec.samples = {0, 1, 258, 65535, 4660, 43981};  // big-endian in the file
    spec.gama = 1 / 2.2;
    spec.interlaced = true;
    const t::ByteVector bytes = t::png_bytes(spec);
    codec::PngDecoder png(bytes, "independent.png");
    const codec::PngHeader& h = png.read_header();
    EXPECT_TRUE(h.interlaced);
    ASSERT_TRUE(h.gamma_fixed.has_value());
    EXPECT_EQ(*h.gamma_fixed, 45455);
    EXPECT_FALSE(h.srgb);
    const codec::ImageBuffer image = codec::decode_png(bytes, "independent.png");
    for (std::size_t i = 0; i < 6; ++i) EXPECT_EQ(image.sample(i % 3, i / 3), spec.samples[i]);
}

TEST(PngCodec, BrokenFilesAreDataErrorsNamingThem) {
    const std::vector<std::uint16_t> samples(40 * 30, 7);
    const std::string file = codec::encode_png({samples.data(), 40, 30, 1, {16, false}, 0});
    const std::string cut = file.substr(0, file.size() / 2);
    try {
        codec::decode_png(codec::as_bytes(cut), "cut.png");
        ADD_FAILURE() << "no error";
    } catch (const codec::PngError& e) {
        EXPECT_NE(std::string(e.what()).find("cut.png: corrupt or truncated PNG (libpng: "),
                  std::string::npos)
            << e.what();
        EXPECT_NE(e.detail().find("truncated"), std::string::npos) << e.detail();
        EXPECT_LE(e.offset(), cut.size());
        EXPECT_GT(e.offset(), 8U);
    }
    EXPECT_THROW(codec::decode_png(codec::as_bytes("not a png at all"), "x.png"), DataError);
    // The header check refuses before any sample is allocated.
    EXPECT_THROW(codec::decode_png(codec::as_bytes(file), "big.png",
                                   [](const codec::PngHeader&) { throw DataError("refused"); }),
                 DataError);
    const std::vector<float> floats(4, 1.0F);
    EXPECT_THROW(codec::encode_png({floats.data(), 2, 2, 1, {32, true}, 0}),
                 roughscope::InvalidArgument);
}

TEST(TiffCodec, RoundTripsUnsignedAndFloatSamples) {
    tiff_round_trip<std::uint8_t>(1, false);
    tiff_round_trip<std::uint8_t>(3, false);
    tiff_round_trip<std::uint16_t>(1, false);
    tiff_round_trip<std::uint16_t>(3, false);
    tiff_round_trip<float>(1, true);
    tiff_round_trip<double>(1, true);
}

TEST(TiffCodec, FloatFileReadsBackWithLibtiffAndCarriesItsTags) {
    const std::vector<float> samples = {0.5F, -2.0F, 1e-3F, 7.25F, 3.0F, 4.0F};
    codec::TiffEncodeOptions options;
    options.mode = "wl";
    options.orientation = true;
    options.software = "codec test";
    const std::string file =
        codec::encode_tiff({samples.data(), 3, 2, 1, {32, true}, 0}, options, "test tiff");
    ASSERT_EQ(file.substr(0, 4), std::string("II*\0", 4));
    const auto path = roughscope::testing::fresh_dir("codec_tiff") / "f.tif";
    roughscope::io::write_file_atomic(path, file);
    TIFF* tif = TIFFOpen(path.c_str(), "r");
    ASSERT_NE(tif, nullptr);
    std::uint16_t format = 0;
    std::uint16_t bits = 0;
    char* software = nullptr;
    TIFFGetField(tif, TIFFTAG_SAMPLEFORMAT, &format);
    TIFFGetField(tif, TIFFTAG_BITSPERSAMPLE, &bits);
    TIFFGetField(tif, TIFFTAG_SOFTWARE, &software);
    EXPECT_EQ(format, SAMPLEFORMAT_IEEEFP);
    EXPECT_EQ(bits, 32);
    EXPECT_STREQ(software, "codec test");
    std::vector<float> row(3);
    for (std::uint32_t r = 0; r < 2; ++r) {
        ASSERT_EQ(TIFFReadScanline(tif, row.data(), r, 0), 1);
        for (std::size_t x = 0; x < 3; ++x) EXPECT_EQ(row[x], samples[r * 3 + x]);
    }
    TIFFClose(tif);

    codec::TiffDecoder decoder(codec::as_bytes(file), "f.tif");
    ASSERT_TRUE(decoder.ok());
    EXPECT_EQ(decoder.header().orientation, codec::tiff::kOrientationTopLeft);
    EXPECT_FALSE(decoder.header().tiled);
    EXPECT_FALSE(decoder.header().has_exif);
}

TEST(TiffCodec, BrokenFilesAreDataErrorsNamingThem) {
    const std::vector<std::uint16_t> samples(64 * 64, 9);
    const std::string file = codec::encode_tiff({samples.data(), 64, 64, 1, {16, false}, 0});
    // Cut in half: the file ends inside the strip (libtiff writes the directory last).
    const std::string cut = file.substr(0, file.size() / 2);
    try {
        codec::decode_tiff(codec::as_bytes(cut), "cut.tif");
        ADD_FAILURE() << "no error";
    } catch (const DataError& e) {
        EXPECT_NE(std::string(e.what()).find("cut.tif"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("truncated"), std::string::npos) << e.what();
    }
    codec::TiffDecoder header_only(codec::as_bytes(file.substr(0, 6)), "short.tif");
    EXPECT_FALSE(header_only.ok());
    EXPECT_FALSE(header_only.reason().empty());
    try {
        codec::decode_tiff(codec::as_bytes(file.substr(0, 6)), "short.tif");
        ADD_FAILURE() << "no error";
    } catch (const DataError& e) {
        EXPECT_NE(std::string(e.what()).find("short.tif: corrupt or truncated TIFF"),
                  std::string::npos)
            << e.what();
    }
}

}  // namespace
