// Height images: a PNG and TIFFs written here from the specifications by minimal independent
// writers (PNG: stored deflate blocks, CRC-32 and Adler-32 computed here; TIFF: a baseline
// header and IFD byte by byte, both byte orders) read to the intended heights; malformed files
// give DataErrors; options are checked; the writers round-trip bit-exactly where the format can
// hold the values.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "expect_data_error.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/surface/formats.hpp"
#include "roughscope/surface/height_map.hpp"

namespace roughscope::surface {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

using roughscope::testing::expect_data_error;

// ---- a minimal PNG writer (PNG specification, RFC 1950/1951 stored blocks) ------------------

std::uint32_t crc32(const std::string& bytes) {
    std::uint32_t c = 0xffffffffU;
    for (const char ch : bytes) {
        c ^= static_cast<unsigned char>(ch);
        for (int k = 0; k < 8; ++k) c = (c & 1U) != 0 ? 0xedb88320U ^ (c >> 1) : c >> 1;
    }
    return c ^ 0xffffffffU;
}

std::string be32(std::uint32_t v) {
    return {static_cast<char>(v >> 24), static_cast<char>(v >> 16), static_cast<char>(v >> 8),
            static_cast<char>(v)};
}

std::string chunk(const std::string& type, const std::string& data) {
    return be32(static_cast<std::uint32_t>(data.size())) + type + data + be32(crc32(type + data));
}

// Grey PNG of `depth` bits (8 or 16) from row-major counts; `color` overrides the colour type.
std::string minimal_png(std::uint32_t width, std::uint32_t height,
                        const std::vector<std::uint16_t>& counts, int depth = 16, int color = 0) {
    std::string raw;
    for (std::uint32_t y = 0; y < height; ++y) {
        raw.push_back(0);  // filter: none
        for (std::uint32_t x = 0; x < width; ++x) {
            const std::uint16_t c = counts[y * width + x];
            if (depth == 16) raw.push_back(static_cast<char>(c >> 8));
            raw.push_back(static_cast<char>(c & 0xff));
        }
    }
    std::string z = "\x78\x01";  // zlib header: deflate, 32 KiB window, check bits
    z.push_back(1);              // BFINAL = 1, BTYPE = 00 (stored); raw.size() < 65536 here
    const auto len = static_cast<std::uint16_t>(raw.size());
    z.push_back(static_cast<char>(len & 0xff));
    z.push_back(static_cast<char>(len >> 8));
    z.push_back(static_cast<char>(~len & 0xff));
    z.push_back(static_cast<char>((~len >> 8) & 0xff));
    z += raw;
    std::uint32_t a = 1;
    std::uint32_t b = 0;
    for (const char ch : raw) {
        a = (a + static_cast<unsigned char>(ch)) % 65521U;
        b = (b + a) % 65521U;
    }
    z += be32((b << 16) | a);
    std::string ihdr = be32(width) + be32(height);
    ihdr.push_back(static_cast<char>(depth));
    ihdr.push_back(static_cast<char>(color));
    ihdr += std::string(3, '\0');  // compression, filter, interlace
    return std::string("\x89PNG\r\n\x1a\n", 8) + chunk("IHDR", ihdr) + chunk("IDAT", z) +
           chunk("IEND", "");
}

// Signature, IHDR and IEND only: a header that promises pixels it does not have.
std::string png_header_only(std::uint32_t width, std::uint32_t height) {
    std::string ihdr = be32(width) + be32(height);
    ihdr.push_back(16);
    ihdr += std::string(4, '\0');  // grey, compression, filter, interlace
    return std::string("\x89PNG\r\n\x1a\n", 8) + chunk("IHDR", ihdr) + chunk("IDAT", "") +
           chunk("IEND", "");
}

HeightReadOptions scaled(double z_scale_um) {
    HeightReadOptions o;
    o.z_scale_um = z_scale_um;
    return o;
}

TEST(FormatPng, MinimalIndependentPngReadsToTheIntendedHeights) {
    const std::string png = minimal_png(3, 2, {0, 1, 65535, 256, 4660, 7});
    HeightReadOptions options = scaled(0.5);
    options.dx_um = 0.25;
    const HeightMap map = formats::decode_png(png, "h.png", options);
    ASSERT_EQ(map.nx, 3U);
    ASSERT_EQ(map.ny, 2U);
    EXPECT_EQ(map.at(2, 0), 32767.5);
    EXPECT_EQ(map.at(0, 1), 128.0);
    EXPECT_EQ(map.at(1, 1), 2330.0);
    EXPECT_EQ(map.dx_um, 0.25);
    EXPECT_EQ(map.dy_um, 0.25);  // dy defaults to dx
    const HeightMap eight = formats::decode_png(minimal_png(2, 1, {9, 200}, 8), "h.png", scaled(2));
    EXPECT_EQ(eight.at(1, 0), 400.0);
    EXPECT_EQ(eight.dx_um, 1.0);
    EXPECT_NE(eight.title.find("assumed"), std::string::npos);
}

TEST(FormatPng, MalformedAndUnsupportedFilesGiveDataErrors) {
    const std::string good = minimal_png(3, 2, {1, 2, 3, 4, 5, 6});
    const HeightReadOptions o = scaled(1);
    expect_data_error([&] { formats::decode_png("GIF89a....", "h.png", o); },
                      {"h.png: byte offset 0", "signature"});
    expect_data_error([&] { formats::decode_png(good.substr(0, 50), "h.png", o); },
                      {"h.png: byte offset", "PNG:"});
    std::string bad_crc = good;
    bad_crc[29] = static_cast<char>(bad_crc[29] ^ 1);  // last byte of the IHDR CRC
    expect_data_error([&] { formats::decode_png(bad_crc, "h.png", o); }, {"h.png", "PNG:"});
    expect_data_error([&] { formats::decode_png(minimal_png(1, 1, {1}, 8, 2), "h.png", o); },
                      {"colour type 2"});
    // Sizes larger than the data: refused from the header, before any allocation.
    expect_data_error([&] { formats::decode_png(png_header_only(60000, 60000), "h.png", o); },
                      {"60000 x 60000", "outside"});
    expect_data_error([&] { formats::decode_png(png_header_only(10000, 10000), "h.png", o); },
                      {"1032:1"});
    // Options: the z scale is required for counts.
    EXPECT_THROW(formats::decode_png(good, "h.png", {}), InvalidArgument);
    EXPECT_THROW(formats::decode_png(good, "h.png", scaled(-1)), InvalidArgument);
}

TEST(FormatPng, WriterRoundTripsIntegerMultiplesAndRefusesTheRest) {
    HeightMap map = make_height_map(4, 3, 1, 1);
    for (std::size_t i = 0; i < map.size(); ++i) map.heights_um[i] = 0.125 * (i * 5000.0);
    HeightWriteOptions w;
    w.z_scale_um = 0.125;
    const std::string png = formats::encode_png(map, w);
    EXPECT_TRUE(bitwise_equal(map, formats::decode_png(png, "w.png", scaled(0.125))));

    EXPECT_THROW(formats::encode_png(map, {}), InvalidArgument);  // no z scale
    HeightMap nan_map = map;
    nan_map.heights_um[3] = kNaN;
    EXPECT_THROW(formats::encode_png(nan_map, w), InvalidArgument);
    HeightMap negative = map;
    negative.heights_um[0] = -1.0;
    EXPECT_THROW(formats::encode_png(negative, w), InvalidArgument);
    HeightMap too_high = map;
    too_high.heights_um[0] = 0.125 * 65536;
    EXPECT_THROW(formats::encode_png(too_high, w), InvalidArgument);
}

// ---- a minimal baseline TIFF writer (TIFF 6.0: header, one strip, one IFD) ------------------

struct TiffBytes {
    bool big = false;
    std::string out;
    void u16(std::uint16_t v) {
        if (big) {
            out.push_back(static_cast<char>(v >> 8));
            out.push_back(static_cast<char>(v & 0xff));
        } else {
            out.push_back(static_cast<char>(v & 0xff));
            out.push_back(static_cast<char>(v >> 8));
        }
    }
    void u32(std::uint32_t v) {
        if (big) {
            u16(static_cast<std::uint16_t>(v >> 16));
            u16(static_cast<std::uint16_t>(v & 0xffff));
        } else {
            u16(static_cast<std::uint16_t>(v & 0xffff));
            u16(static_cast<std::uint16_t>(v >> 16));
        }
    }
    void entry_short(std::uint16_t tag, std::uint16_t value) {
        u16(tag);
        u16(3);
        u32(1);
        u16(value);  // left-justified in the 4-byte field
        u16(0);
    }
    void entry_long(std::uint16_t tag, std::uint32_t value) {
        u16(tag);
        u16(4);
        u32(1);
        u32(value);
    }
};

// `pixels`: the strip, already in the file's byte order. `strip_bytes` may lie.
std::string minimal_tiff(bool big, std::uint32_t width, std::uint32_t height, int bits,
                         int sample_format, const std::string& pixels, int samples = 1,
                         std::uint32_t strip_bytes = 0) {
    TiffBytes t;
    t.big = big;
    t.out = big ? std::string("MM\0*", 4) : std::string("II*\0", 4);
    t.u32(static_cast<std::uint32_t>(8 + pixels.size()));  // IFD after the pixels
    t.out += pixels;
    t.u16(10);
    t.entry_long(256, width);
    t.entry_long(257, height);
    t.entry_short(258, static_cast<std::uint16_t>(bits));
    t.entry_short(259, 1);  // no compression
    t.entry_short(262, 1);  // BlackIsZero
    t.entry_long(273, 8);   // StripOffsets
    t.entry_short(277, static_cast<std::uint16_t>(samples));
    t.entry_long(278, height);  // RowsPerStrip
    t.entry_long(279, strip_bytes != 0 ? strip_bytes : static_cast<std::uint32_t>(pixels.size()));
    t.entry_short(339, static_cast<std::uint16_t>(sample_format));
    t.u32(0);
    return t.out;
}

template <class T>
std::string native_bytes(const std::vector<T>& values, bool big) {
    std::string out;
    for (const T v : values) {
        char b[sizeof(T)];
        std::memcpy(b, &v, sizeof(T));
        std::string s(b, sizeof(T));
        if (big) s.assign(s.rbegin(), s.rend());  // the test machine is little endian
        out += s;
    }
    return out;
}

TEST(FormatTiff, MinimalIndependentTiffsReadToTheIntendedHeights) {
    ASSERT_EQ(native_bytes<std::uint16_t>({1}, false)[0], 1) << "helpers assume little endian";
    const std::string u16 =
        minimal_tiff(false, 2, 2, 16, 1, native_bytes<std::uint16_t>({0, 1, 65535, 300}, false));
    const HeightMap a = formats::decode_tiff(u16, "h.tif", scaled(0.001));
    EXPECT_EQ(a.at(0, 1), 65.535);
    EXPECT_EQ(a.at(1, 1), 0.3);

    const std::string f32 =
        minimal_tiff(true, 3, 1, 32, 3, native_bytes<float>({1.5F, -2.25F, std::nanf("")}, true));
    const HeightMap b = formats::decode_tiff(f32, "h.tif", {});
    EXPECT_EQ(b.at(0, 0), 1.5);
    EXPECT_EQ(b.at(1, 0), -2.25);
    EXPECT_TRUE(std::isnan(b.at(2, 0)));

    const std::string f64 =
        minimal_tiff(false, 2, 1, 64, 3,
                     native_bytes<double>({0.1, std::numeric_limits<double>::infinity()}, false));
    const HeightMap c = formats::decode_tiff(f64, "h.tif", {});
    EXPECT_EQ(c.at(0, 0), 0.1);
    EXPECT_TRUE(std::isnan(c.at(1, 0)));  // infinity = missing

    const std::string u8 = minimal_tiff(true, 2, 1, 8, 1, std::string("\x02\xff", 2));
    EXPECT_EQ(formats::decode_tiff(u8, "h.tif", scaled(2)).at(1, 0), 510.0);
}

TEST(FormatTiff, MalformedAndUnsupportedFilesGiveDataErrors) {
    const std::string pixels = native_bytes<std::uint16_t>({1, 2, 3, 4}, false);
    const HeightReadOptions o = scaled(1);
    expect_data_error([&] { formats::decode_tiff("\x89PNG\r\n\x1a\n", "h.tif", o); },
                      {"h.tif: byte offset 0", "not a TIFF"});
    const std::string good = minimal_tiff(false, 2, 2, 16, 1, pixels);
    expect_data_error([&] { formats::decode_tiff(good.substr(0, 16), "h.tif", o); },
                      {"h.tif", "not a readable TIFF"});
    expect_data_error(
        [&] { formats::decode_tiff(minimal_tiff(false, 2, 2, 16, 1, pixels, 3), "h.tif", o); },
        {"3 samples per pixel"});
    expect_data_error(
        [&] { formats::decode_tiff(minimal_tiff(false, 1, 2, 32, 1, pixels), "h.tif", o); },
        {"32 bits in sample format 1"});
    // Dimensions larger than the data: the strip holds 8 bytes, the header asks for 200 x 200.
    expect_data_error(
        [&] {
            formats::decode_tiff(minimal_tiff(false, 200, 200, 16, 1, pixels, 1, 80000), "h.tif",
                                 o);
        },
        {"h.tif: TIFF row"});
    // ... or for more than 4096 times the file (a strip shared by every row could decode it):
    // refused before any row is decoded.
    expect_data_error(
        [&] {
            formats::decode_tiff(minimal_tiff(false, 1000, 1000, 16, 1, pixels, 1, 2000000),
                                 "h.tif", o);
        },
        {"h.tif: the TIFF header's 1000 x 1000 samples of 16 bits are more than 4096 times"});
    expect_data_error(
        [&] {
            formats::decode_tiff(minimal_tiff(false, 100000, 100000, 16, 1, pixels), "h.tif", o);
        },
        {"100000 x 100000", "outside"});
    EXPECT_THROW(formats::decode_tiff(good, "h.tif", {}), InvalidArgument);  // counts need a scale
}

TEST(FormatTiff, WritersRoundTripFloat32AndUint16) {
    HeightMap map = make_height_map(5, 4, 1, 1);
    for (std::size_t i = 0; i < map.size(); ++i) {
        map.heights_um[i] = static_cast<double>(static_cast<float>(std::sin(0.3 * i) * 7.0));
    }
    map.heights_um[6] = kNaN;
    const std::string f = formats::encode_tiff(map, {});
    EXPECT_TRUE(bitwise_equal(map, formats::decode_tiff(f, "w.tif", {})));

    HeightMap counts = make_height_map(3, 2, 1, 1);
    counts.heights_um = {0, 0.5, 1.0, 32767.5, 100, 3};
    HeightWriteOptions w;
    w.tiff_float = false;
    w.z_scale_um = 0.5;
    const std::string u = formats::encode_tiff(counts, w);
    EXPECT_TRUE(bitwise_equal(counts, formats::decode_tiff(u, "w.tif", scaled(0.5))));
    w.z_scale_um.reset();
    EXPECT_THROW(formats::encode_tiff(counts, w), InvalidArgument);
    HeightMap huge = counts;
    huge.heights_um[0] = 1e300;
    EXPECT_THROW(formats::encode_tiff(huge, {}), InvalidArgument);  // beyond float32
}

}  // namespace
}  // namespace roughscope::surface
