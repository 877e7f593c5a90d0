// Headerless float32/float64 height files: bytes laid out here by hand (both byte orders) read
// to the intended heights; the options are required and checked; a byte count that does not
// match nx·ny·size is a DataError stating both numbers; float64 round trips bit-exactly.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/surface/formats.hpp"
#include "roughscope/surface/height_map.hpp"

namespace roughscope::surface {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

template <class T>
std::string bytes_of(const std::vector<T>& values, bool big) {
    std::string out;
    for (const T v : values) {
        std::string s(sizeof(T), '\0');
        std::memcpy(s.data(), &v, sizeof(T));
        if (big) s.assign(s.rbegin(), s.rend());  // the test machine is little endian
        out += s;
    }
    return out;
}

HeightReadOptions grid(std::size_t nx, std::size_t ny, double dx_um) {
    HeightReadOptions o;
    o.nx = nx;
    o.ny = ny;
    o.dx_um = dx_um;
    return o;
}

TEST(FormatRaw, HandLaidBytesInBothOrdersAndSizes) {
    ASSERT_EQ(bytes_of<std::uint16_t>({1}, false)[0], 1) << "helpers assume little endian";
    HeightReadOptions o = grid(3, 2, 0.5);
    const HeightMap a =
        formats::decode_raw(bytes_of<double>({1, 2, 3, 4, kNaN, 6}, false), "r.raw", o);
    EXPECT_EQ(a.at(2, 0), 3.0);
    EXPECT_TRUE(std::isnan(a.at(1, 1)));
    EXPECT_EQ(a.dx_um, 0.5);
    EXPECT_EQ(a.dy_um, 0.5);  // dy defaults to dx
    o.raw_type = RawSampleType::Float32;
    o.raw_big_endian = true;
    o.dy_um = 2.0;
    const HeightMap b = formats::decode_raw(
        bytes_of<float>({0.5F, -1.0F, std::numeric_limits<float>::infinity(), 8, 9, 10}, true),
        "r.f32", o);
    EXPECT_EQ(b.at(0, 0), 0.5);
    EXPECT_EQ(b.at(1, 0), -1.0);
    EXPECT_TRUE(std::isnan(b.at(2, 0)));  // infinity = missing
    EXPECT_EQ(b.dy_um, 2.0);
    o.raw_type = RawSampleType::Float64;
    const HeightMap c = formats::decode_raw(bytes_of<double>({0.1, 0, 0, 0, 0, 7}, true), "r", o);
    EXPECT_EQ(c.at(0, 0), 0.1);
    EXPECT_EQ(c.at(2, 1), 7.0);
}

TEST(FormatRaw, ByteCountMismatchStatesBothNumbers) {
    const std::string six = bytes_of<double>({1, 2, 3, 4, 5, 6}, false);
    try {
        formats::decode_raw(six.substr(0, 47), "r.raw", grid(3, 2, 1));
        ADD_FAILURE() << "no DataError";
    } catch (const DataError& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("r.raw"), std::string::npos) << m;
        EXPECT_NE(m.find("47 bytes"), std::string::npos) << m;
        EXPECT_NE(m.find("= 48 bytes"), std::string::npos) << m;
    }
    EXPECT_THROW(formats::decode_raw(six + "x", "r.raw", grid(3, 2, 1)), DataError);
    // Absurd dimensions against a small file: a DataError, not an allocation.
    EXPECT_THROW(formats::decode_raw(six, "r.raw", grid(16384, 16384, 1)), DataError);
    EXPECT_THROW(formats::decode_raw(bytes_of<double>({kNaN}, false), "r.raw", grid(1, 1, 1)),
                 DataError);  // every point missing
}

TEST(FormatRaw, OptionsAreRequiredAndChecked) {
    const std::string six = bytes_of<double>({1, 2, 3, 4, 5, 6}, false);
    HeightReadOptions o = grid(3, 2, 1);
    o.nx.reset();
    EXPECT_THROW(formats::decode_raw(six, "r.raw", o), InvalidArgument);
    o = grid(3, 2, 1);
    o.dx_um.reset();
    EXPECT_THROW(formats::decode_raw(six, "r.raw", o), InvalidArgument);
    EXPECT_THROW(formats::decode_raw(six, "r.raw", grid(0, 2, 1)), InvalidArgument);
    EXPECT_THROW(formats::decode_raw(six, "r.raw", grid(3, 2, -1)), InvalidArgument);
    EXPECT_NO_THROW(formats::decode_raw(six, "r.raw", grid(3, 2, 1)));
}

TEST(FormatRaw, Float64RoundTripsBitExactlyFloat32WhenRepresentable) {
    HeightMap map = make_height_map(4, 2, 0.3, 0.3);
    for (std::size_t i = 0; i < map.size(); ++i) map.heights_um[i] = std::exp(0.37 * i) / 7.0;
    map.heights_um[1] = kNaN;
    HeightReadOptions o = grid(4, 2, 0.3);
    EXPECT_TRUE(bitwise_equal(map, formats::decode_raw(formats::encode_raw(map, {}), "r", o)));
    HeightMap f = map;
    for (double& z : f.heights_um) z = static_cast<double>(static_cast<float>(z));
    HeightWriteOptions w;
    w.raw_type = RawSampleType::Float32;
    o.raw_type = RawSampleType::Float32;
    EXPECT_TRUE(bitwise_equal(f, formats::decode_raw(formats::encode_raw(f, w), "r", o)));
    f.heights_um[0] = 1e300;
    EXPECT_THROW(formats::encode_raw(f, w), InvalidArgument);
}

}  // namespace
}  // namespace roughscope::surface
