// ISO 25178-71 SDF: binary and ASCII files built here byte by byte from the format's layout (not
// by the project's writer) read to the intended heights; missing-point markers; every error
// path (truncation, wrong magic, unsupported fields, sizes larger than the data, bad numbers);
// bit-exact round trips through the writer.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "../io/test_files.hpp"
#include "expect_data_error.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/surface/formats.hpp"
#include "roughscope/surface/height_map.hpp"

namespace roughscope::surface {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

using roughscope::testing::expect_data_error;

// Little-endian bytes of a value (the test machine's order is checked below).
template <class T>
std::string le(T value) {
    std::string out(sizeof(T), '\0');
    std::memcpy(out.data(), &value, sizeof(T));
    return out;
}

// The 81-byte binary header of ISO 25178-71, field by field.
std::string binary_header(std::uint16_t nx, std::uint16_t ny, double xscale, double yscale,
                          double zscale, std::uint8_t data_type, std::uint8_t compression = 0,
                          std::uint8_t check = 0) {
    std::string h = "bISO-1.0";
    h += std::string("HandMade  ", 10);
    h += "010120250000";
    h += "010120250000";
    h += le(nx) + le(ny) + le(xscale) + le(yscale) + le(zscale) + le(0.0);
    h.push_back(static_cast<char>(compression));
    h.push_back(static_cast<char>(data_type));
    h.push_back(static_cast<char>(check));
    return h;
}

HeightMap sdf(const std::string& bytes) { return formats::decode_sdf(bytes, "s.sdf", {}); }

TEST(FormatSdf, HandBuiltBinaryInt16WithScalesAndMissingMarker) {
    ASSERT_EQ(le<std::uint16_t>(1)[0], 1) << "the helpers assume a little-endian machine";
    // 3 points x 2 profiles, 2 µm x 4 µm spacing, counts of 1 nm; -32768 marks a missing point.
    std::string bytes = binary_header(3, 2, 2e-6, 4e-6, 1e-9, 5);
    ASSERT_EQ(bytes.size(), 81U);
    for (const std::int16_t c : {1, -2, 300, -32768, 0, 32767}) bytes += le(c);
    const HeightMap map = sdf(bytes);
    ASSERT_EQ(map.nx, 3U);
    ASSERT_EQ(map.ny, 2U);
    EXPECT_DOUBLE_EQ(map.dx_um, 2.0);
    EXPECT_DOUBLE_EQ(map.dy_um, 4.0);
    EXPECT_DOUBLE_EQ(map.at(1, 0), -0.002);
    EXPECT_DOUBLE_EQ(map.at(2, 0), 0.3);
    EXPECT_TRUE(std::isnan(map.at(0, 1)));
    EXPECT_DOUBLE_EQ(map.at(2, 1), 32.767);
}

TEST(FormatSdf, HandBuiltBinaryDoubleFloatAndUint16) {
    std::string d = binary_header(2, 1, 1e-6, 1e-6, 1e-6, 7);
    d += le(1.25) + le(kNaN);
    const HeightMap a = sdf(d);
    EXPECT_EQ(a.at(0, 0), 1.25);  // Zscale 1e-6 m: the stored µm exactly
    EXPECT_TRUE(std::isnan(a.at(1, 0)));
    EXPECT_TRUE(a.is_profile());

    std::string f = binary_header(2, 1, 1e-6, 1e-6, 1e-3, 3);
    f += le(0.5F) + le(std::numeric_limits<float>::infinity());
    const HeightMap b = sdf(f);
    EXPECT_EQ(b.at(0, 0), 500.0);  // 0.5 mm
    EXPECT_TRUE(std::isnan(b.at(1, 0)));

    std::string u = binary_header(2, 1, 1e-6, 1e-6, 1e-6, 1);
    u += le<std::uint16_t>(65534) + le<std::uint16_t>(65535);
    const HeightMap c = sdf(u + "trailing text the reader ignores\n");
    EXPECT_EQ(c.at(0, 0), 65534.0);
    EXPECT_TRUE(std::isnan(c.at(1, 0)));
}

TEST(FormatSdf, HandWrittenAscii) {
    const std::string text =
        "aISO-1.0\n"
        "ManufacID   = HandMade\n"
        "; a comment line\n"
        "CreateDate  = 010120250000\n"
        "ModDate     = 010120250000\n"
        "NumPoints   = 3\n"
        "NumProfiles = 2\n"
        "Xscale      = 5.0E-07\n"
        "Yscale      = 5.0E-07\n"
        "Zscale      = 1.0E-09\n"
        "Zresolution = -1\n"
        "Compression = 0\n"
        "DataType    = 5\n"
        "CheckType   = 0\n"
        "*\n"
        "10 20 30\n"
        "-40 -32768 60\n"
        "*\n"
        "OPERATOR = nobody\n"
        "*\n";
    const HeightMap map = sdf(text);
    ASSERT_EQ(map.nx, 3U);
    EXPECT_DOUBLE_EQ(map.dx_um, 0.5);
    EXPECT_DOUBLE_EQ(map.at(2, 0), 0.03);
    EXPECT_DOUBLE_EQ(map.at(0, 1), -0.04);
    EXPECT_TRUE(std::isnan(map.at(1, 1)));
}

TEST(FormatSdf, TrailerOffsetsAndExactSpacingsHeaderWinsOnDisagreement) {
    const std::string head = binary_header(1, 1, 2e-6, 2e-6, 1e-6, 7) + le(1.0);
    const HeightMap a =
        sdf(head + "*\ndx_um = 2.0000000000000004\nx_offset_um = -7.5\ny_offset_um = 1e-3\n*\n");
    EXPECT_EQ(a.dx_um, 2.0000000000000004);  // agrees with Xscale: the exact value
    EXPECT_EQ(a.x_offset_um, -7.5);
    EXPECT_EQ(a.y_offset_um, 1e-3);
    const HeightMap b = sdf(head + "dx_um = 5\n");
    EXPECT_DOUBLE_EQ(b.dx_um, 2.0);  // disagrees (file rescaled elsewhere): the header wins
    EXPECT_EQ(b.x_offset_um, 0.0);
}

const std::string kAsciiHead =
    "aISO-1.0\nNumPoints = 2\nNumProfiles = 1\nXscale = 1e-6\nYscale = 1e-6\nZscale = 1e-6\n"
    "DataType = 7\n*\n";

TEST(FormatSdf, MalformedFilesGiveDataErrorsWithPlace) {
    expect_data_error([] { sdf(""); }, {"s.sdf", "empty"});
    expect_data_error([] { sdf("PK\x03\x04 not sdf"); }, {"s.sdf: byte offset 0", "not an SDF"});
    expect_data_error([] { sdf("bISO-1.0 short"); }, {"byte offset 14", "81 bytes"});
    // Dimensions larger than the data: 100 x 100 doubles announced, 2 given.
    expect_data_error([] { sdf(binary_header(100, 100, 1e-6, 1e-6, 1e-6, 7) + le(1.0) + le(2.0)); },
                      {"byte offset 81", "16 bytes", "80000 bytes"});
    // The largest header a binary SDF can state, with no data: no allocation, a clear error.
    expect_data_error([] { sdf(binary_header(65535, 65535, 1e-6, 1e-6, 1e-6, 7)); },
                      {"65535 x 65535", "outside"});
    expect_data_error([] { sdf(binary_header(10000, 10000, 1e-6, 1e-6, 1e-6, 7)); },
                      {"byte offset 81", "holds 0 bytes"});
    expect_data_error([] { sdf(binary_header(0, 2, 1e-6, 1e-6, 1e-6, 7)); }, {"0 x 2"});
    expect_data_error([] { sdf(binary_header(1, 1, 1e-6, 1e-6, 1e-6, 9) + le(1.0)); },
                      {"DataType = 9"});
    expect_data_error([] { sdf(binary_header(1, 1, 1e-6, 1e-6, 1e-6, 7, 1) + le(1.0)); },
                      {"Compression = 1"});
    expect_data_error([] { sdf(binary_header(1, 1, 1e-6, 1e-6, 1e-6, 7, 0, 2) + le(1.0)); },
                      {"CheckType = 2"});
    expect_data_error([] { sdf(binary_header(1, 1, -1e-6, 1e-6, 1e-6, 7) + le(1.0)); },
                      {"Xscale", "> 0"});
    expect_data_error([] { sdf(binary_header(1, 1, 1e-6, 1e-6, 1e-6, 7) + le(kNaN)); },
                      {"every point is missing"});
    expect_data_error(
        [] { sdf(binary_header(1, 1, 1e-6, 1e-6, 1e-6, 7) + le(1.0) + "dx_um = x\n"); },
        {"byte offset 89", "dx_um"});

    expect_data_error([] { sdf(kAsciiHead + "1 2x\n"); }, {"s.sdf:9:3", "'2x'"});
    expect_data_error([] { sdf(kAsciiHead + "1\n"); }, {"holds 1 values", "2 are needed"});
    expect_data_error([] { sdf(kAsciiHead + "1 2 3\n*\n"); }, {"s.sdf:9:5", "more than"});
    expect_data_error([] { sdf("aISO-1.0\nNumPoints = 2\nNumProfiles = 1\n1 2\n"); },
                      {"s.sdf:4", "Key = value"});
    expect_data_error([] { sdf("aISO-1.0\nNumPoints = 2\n"); }, {"no '*' line"});
    expect_data_error([] { sdf("aISO-1.0\nNumPoints = 2\n*\n1 2\n"); },
                      {"s.sdf:3", "no NumProfiles"});
    expect_data_error([] { sdf("aISO-1.0\nNumPoints = two\n*\n"); },
                      {"s.sdf:2:13", "NumPoints", "'two'"});
    expect_data_error(
        [] {
            sdf("aISO-1.0\nNumPoints = 10000\nNumProfiles = 10000\nXscale = 1\nYscale = 1\n"
                "Zscale = 1\nDataType = 7\n*\n1 2 3\n");
        },
        {"s.sdf:8", "cannot fit"});
    expect_data_error(
        [] {
            sdf("aISO-1.0\nNumPoints = 100000\nNumProfiles = 100000\nXscale = 1\nYscale = 1\n"
                "Zscale = 1\nDataType = 7\n*\n1\n");
        },
        {"100000 x 100000"});
}

HeightMap sample_map() {
    HeightMap map = make_height_map(5, 3, 0.1, 0.7000000000000001);
    map.x_offset_um = 12.5;
    map.y_offset_um = -3e-3;
    for (std::size_t i = 0; i < map.size(); ++i) {
        map.heights_um[i] = std::cos(1.3 * static_cast<double>(i)) * 1e-3;
    }
    map.heights_um[4] = kNaN;
    return map;
}

TEST(FormatSdf, WriterBinaryFollowsTheLayoutAndRoundTripsBitExactly) {
    const HeightMap map = sample_map();
    const std::string bytes = formats::encode_sdf(map, {});
    ASSERT_GE(bytes.size(), 81U + 15U * 8U);
    EXPECT_EQ(bytes.substr(0, 8), "bISO-1.0");
    EXPECT_EQ(bytes[79], 7);  // DataType double
    double zscale = 0;
    std::memcpy(&zscale, bytes.data() + 62, 8);
    EXPECT_EQ(zscale, 1e-6);
    double first = 0;
    std::memcpy(&first, bytes.data() + 81, 8);
    EXPECT_EQ(first, map.heights_um[0]);
    EXPECT_TRUE(bitwise_equal(map, sdf(bytes)));
}

TEST(FormatSdf, WriterAsciiRoundTripsBitExactly) {
    const HeightMap map = sample_map();
    HeightWriteOptions options;
    options.sdf_binary = false;
    const std::string text = formats::encode_sdf(map, options);
    EXPECT_EQ(text.substr(0, 9), "aISO-1.0\n");
    EXPECT_TRUE(bitwise_equal(map, sdf(text))) << text;
}

TEST(FormatSdf, WriterRefusesWhatBinaryCannotHold) {
    HeightMap wide = make_height_map(70000, 1, 1, 1);
    EXPECT_THROW(formats::encode_sdf(wide, {}), InvalidArgument);
    HeightWriteOptions ascii;
    ascii.sdf_binary = false;
    EXPECT_NO_THROW(formats::encode_sdf(wide, ascii));
}

TEST(FormatSdf, FilesOnDiskByExtension) {
    const auto dir = testing::fresh_dir("surface_sdf_files");
    const HeightMap map = sample_map();
    for (const char* leaf : {"m.sdf", "m.csv", "m.xyz"}) {
        write_height_map(map, dir / leaf);
        EXPECT_TRUE(bitwise_equal(map, read_height_map(dir / leaf))) << leaf;
    }
    EXPECT_EQ(testing::slurp(dir / "m.sdf").substr(0, 8), "bISO-1.0");
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace roughscope::surface
