#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/surface/formats.hpp"
#include "roughscope/surface/height_map.hpp"

namespace roughscope::surface {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

TEST(HeightMap, RowMajorLayoutAndMask) {
    HeightMap map = make_height_map(3, 2, 0.5, 0.25);
    map.at(2, 1) = 7.0;
    map.at(0, 1) = kNaN;
    EXPECT_EQ(map.heights_um[1 * 3 + 2], 7.0);
    EXPECT_EQ(map.count_valid(), 5U);
    EXPECT_TRUE(map.has_missing());
    EXPECT_EQ(map.mask(), (std::vector<std::uint8_t>{1, 1, 1, 0, 1, 1}));
    EXPECT_DOUBLE_EQ(map.length_x_um(), 1.5);
    EXPECT_NO_THROW(validate(map, "m"));
}

TEST(HeightMap, MakeRejectsEmptyHugeAndBadSpacing) {
    EXPECT_THROW(make_height_map(0, 1, 1, 1), InvalidArgument);
    EXPECT_THROW(make_height_map(std::size_t{1} << 20, std::size_t{1} << 20, 1, 1),
                 InvalidArgument);
    EXPECT_THROW(make_height_map(2, 2, 0.0, 1), InvalidArgument);
    EXPECT_THROW(make_height_map(2, 2, 1, kNaN), InvalidArgument);
}

TEST(HeightMap, ValidateRejectsInfinityAllMissingAndWrongSize) {
    HeightMap map = make_height_map(2, 2, 1, 1);
    map.heights_um[0] = std::numeric_limits<double>::infinity();
    EXPECT_THROW(validate(map, "m"), InvalidArgument);
    map.heights_um.assign(4, kNaN);
    EXPECT_THROW(validate(map, "m"), InvalidArgument);
    map.heights_um.assign(3, 0.0);
    EXPECT_THROW(validate(map, "m"), InvalidArgument);
}

TEST(HeightMap, BitwiseEqualTreatsNaNAlikeAndSignedZerosApart) {
    HeightMap a = make_height_map(2, 1, 1, 1);
    HeightMap b = a;
    a.heights_um[0] = kNaN;
    b.heights_um[0] = -kNaN;
    EXPECT_TRUE(bitwise_equal(a, b));
    b.heights_um[1] = -0.0;
    EXPECT_FALSE(bitwise_equal(a, b));
}

TEST(HeightFormats, ExtensionsAndNames) {
    EXPECT_EQ(height_format_from_extension("a/b.X3P"), HeightFormat::X3p);
    EXPECT_EQ(height_format_from_extension("b.tif"), HeightFormat::Tiff);
    EXPECT_EQ(height_format_from_extension("b.unknown"), std::nullopt);
    EXPECT_EQ(parse_height_format("CSV-matrix"), HeightFormat::CsvMatrix);
    EXPECT_EQ(to_string(HeightFormat::Gsf), "gsf");
    EXPECT_THROW(parse_height_format("jpeg"), InvalidArgument);
}

TEST(HeightFormats, ReadNamesTheProblem) {
    EXPECT_THROW(read_height_map("no/such/file.x3p"), DataError);
    EXPECT_THROW(read_height_map("file.unknown"), InvalidArgument);
    EXPECT_THROW(encode_height_map(make_height_map(2, 2, 1, 1), HeightFormat::Gwy),
                 InvalidArgument);
}

}  // namespace
}  // namespace roughscope::surface
