// CSV/ASCII matrix and XYZ height files: hand-written files (the format's specification, not the
// project's writer) read to the intended values, header conventions (roughscope's and Gwyddion's
// export header), units, missing points, the regular-grid check, every error path, and bit-exact
// round trips through the writers.
#include <cmath>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "expect_data_error.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/surface/formats.hpp"
#include "roughscope/surface/height_map.hpp"

namespace roughscope::surface {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Runs `body`, expects a DataError whose message contains every one of `parts`.
using roughscope::testing::expect_data_error;

HeightMap csv(const std::string& text, const HeightReadOptions& options = {}) {
    return formats::decode_csv_matrix(text, "m.csv", options);
}
HeightMap xyz(const std::string& text, const HeightReadOptions& options = {}) {
    return formats::decode_xyz(text, "p.xyz", options);
}

HeightMap sample_map() {
    HeightMap map = make_height_map(4, 3, 0.1, 0.30000000000000004);
    map.x_offset_um = -2.5;
    map.y_offset_um = 1e-7;
    for (std::size_t i = 0; i < map.size(); ++i) {
        map.heights_um[i] = std::sin(0.7 * static_cast<double>(i)) / 3.0;
    }
    map.heights_um[5] = kNaN;
    map.heights_um[2] = -0.0;
    map.heights_um[7] = 5e-324;  // the smallest subnormal
    return map;
}

TEST(FormatCsv, HandWrittenMatrixWithSeparatorsCommentsAndMissingPoints) {
    const HeightMap a = csv("# a comment\n1,2,3\n4,,NaN\r\n\n");
    ASSERT_EQ(a.nx, 3U);
    ASSERT_EQ(a.ny, 2U);
    EXPECT_EQ(a.at(2, 0), 3.0);
    EXPECT_EQ(a.at(0, 1), 4.0);
    EXPECT_TRUE(std::isnan(a.at(1, 1)));
    EXPECT_TRUE(std::isnan(a.at(2, 1)));
    EXPECT_EQ(a.dx_um, 1.0);
    EXPECT_NE(a.title.find("assumed"), std::string::npos);  // spacing defaulted: said so

    const HeightMap b = csv("1.5;-2;3e-1\n4;5;6\n");
    EXPECT_EQ(b.at(2, 0), 0.3);
    const HeightMap c = csv("1\t2  3\n  4 5\t6\n");
    EXPECT_EQ(c.nx, 3U);
    EXPECT_EQ(c.at(2, 1), 6.0);
}

TEST(FormatCsv, HeaderSpacingsUnitAndOffsetsWinOverOptions) {
    HeightReadOptions options;
    options.dx_um = 7.0;
    options.length_unit = "mm";
    const HeightMap a =
        csv("# dx_um = 0.5\n# dy_um: 0.25\n# unit = nm\n# x_offset_um = 3\n# title = T\n1,2\n3,4\n",
            options);
    EXPECT_EQ(a.dx_um, 0.5);
    EXPECT_EQ(a.dy_um, 0.25);
    EXPECT_EQ(a.x_offset_um, 3.0);
    EXPECT_EQ(a.at(1, 1), 0.004);  // 4 nm
    EXPECT_EQ(a.title, "T");
    // Without a header the options apply (dy defaults to dx).
    const HeightMap b = csv("1,2\n3,4\n", options);
    EXPECT_EQ(b.dx_um, 7.0);
    EXPECT_EQ(b.dy_um, 7.0);
    EXPECT_EQ(b.at(0, 0), 1000.0);  // 1 mm
    EXPECT_EQ(b.title.find("assumed"), std::string::npos);
}

TEST(FormatCsv, GwyddionExportHeader) {
    // Gwyddion's "ASCII data matrix" export with the informational header: field size and units.
    const std::string text =
        "# Channel: Height\n# Width: 4.000 \xC2\xB5m\n# Height: 2.000 \xC2\xB5m\n"
        "# Value units: m\n1e-9\t2e-9\n3e-9\t4e-9\n";
    const HeightMap a = csv(text);
    EXPECT_EQ(a.title, "Height");
    EXPECT_EQ(a.dx_um, 2.0);
    EXPECT_EQ(a.dy_um, 1.0);
    EXPECT_DOUBLE_EQ(a.at(1, 1), 0.004);
}

TEST(FormatCsv, ErrorsNameFileLineAndColumn) {
    expect_data_error([] { csv("1,2\n3,x4\n"); }, {"m.csv:2:3", "'x4'", "not a number"});
    expect_data_error([] { csv("1,2\n3,4,5\n"); }, {"m.csv:2", "3 values", "line 1", "has 2"});
    expect_data_error([] { csv("# only a comment\n"); }, {"m.csv", "no data rows"});
    expect_data_error([] { csv(""); }, {"no data rows"});
    expect_data_error([] { csv("# dx_um = -1\n1\n"); }, {"m.csv:1:", "dx_um", "> 0"});
    expect_data_error([] { csv("# unit = furlong\n1\n"); }, {"m.csv:1:", "furlong"});
    expect_data_error([] { csv("# Width: 4.0\n1\n"); }, {"m.csv:1:", "<length> <unit>"});
    expect_data_error([] { csv("nan,NaN\n"); }, {"every point is missing"});
    expect_data_error([] { csv("1,inf\n"); }, {"m.csv:1:3", "'inf'"});
    // A NUL byte: a binary file, as for every text reader (docs/input-files.md).
    expect_data_error(
        [] {
            csv(
                std::string("1,2\n3,\0"
                            "4\n",
                            9));
        },
        {"m.csv:2: not a text file: NUL byte at column 3"});
    expect_data_error([] { xyz(std::string("0 0 1\n\0", 7)); }, {"p.xyz:2: not a text file"});
    HeightReadOptions bad;
    bad.length_unit = "inch";
    EXPECT_THROW(csv("1\n", bad), InvalidArgument);
    bad = {};
    bad.dx_um = 0.0;
    EXPECT_THROW(csv("1\n", bad), InvalidArgument);
}

TEST(FormatCsv, WriterRoundTripsBitExactly) {
    const HeightMap map = sample_map();
    const std::string text = formats::encode_csv_matrix(map, {});
    const HeightMap back = csv(text);
    EXPECT_TRUE(bitwise_equal(map, back)) << text;
    EXPECT_NE(text.find("# dx_um = 0.1\n"), std::string::npos);
}

TEST(FormatXyz, HandWrittenTriplesInAnyOrderWithAHole) {
    // A 3 x 2 grid in mm, shuffled, node (1 mm, 0.5 mm) missing, one z NaN.
    const std::string text =
        "# unit = mm\n"
        "2 0.5 6\n0 0 1\n1 0 2\n2 0 3\n0 0.5 NaN\n";
    const HeightMap a = xyz(text);
    ASSERT_EQ(a.nx, 3U);
    ASSERT_EQ(a.ny, 2U);
    EXPECT_EQ(a.dx_um, 1000.0);
    EXPECT_EQ(a.dy_um, 500.0);
    EXPECT_EQ(a.at(1, 0), 2000.0);
    EXPECT_EQ(a.at(2, 1), 6000.0);
    EXPECT_TRUE(std::isnan(a.at(0, 1)));
    EXPECT_TRUE(std::isnan(a.at(1, 1)));  // no point there
    // Comma separated, with offsets and jitter well below 1 % of the spacing.
    const HeightMap b = xyz("10,20,1\n10.5000001,20,2\n10,20.25,3\n10.5,20.25,4\n");
    EXPECT_EQ(b.nx, 2U);
    EXPECT_EQ(b.x_offset_um, 10.0);
    EXPECT_EQ(b.y_offset_um, 20.0);
    EXPECT_NEAR(b.dx_um, 0.5, 1e-6);
    EXPECT_EQ(b.at(1, 1), 4.0);
}

TEST(FormatXyz, OffGridDuplicateSparseAndMalformedPointsAreNamed) {
    expect_data_error([] { xyz("0 0 1\n1 0 2\n2.5 0 3\n"); },
                      {"p.xyz:2", "off the regular grid along x"});
    expect_data_error([] { xyz("0 0 1\n1 0 2\n0 0 3\n"); },
                      {"p.xyz:3", "duplicate point", "line 1"});
    expect_data_error([] { xyz("0 0 1\n1 0 2\n1000 0 3\n"); }, {"do not fill a regular grid"});
    expect_data_error([] { xyz("0 0 1\n0 1e-300 2\n1 1e300 3\n"); }, {"p.xyz"});
    expect_data_error([] { xyz("0 0\n"); }, {"p.xyz:1", "2 values", "3 (x, y, z)"});
    expect_data_error([] { xyz("0 NaN 1\n"); }, {"p.xyz:1:3", "y:"});
    expect_data_error([] { xyz("0 0 1e999\n"); }, {"p.xyz:1:5", "out of the range"});
    expect_data_error([] { xyz("#\n"); }, {"no data lines"});
}

TEST(FormatXyz, WriterRoundTripsBitExactly) {
    const HeightMap map = sample_map();
    const std::string text = formats::encode_xyz(map, {});
    EXPECT_TRUE(bitwise_equal(map, xyz(text))) << text;
    HeightMap profile = make_height_map(5, 1, 0.7, 0.7);
    profile.heights_um = {1, 2, 3, 4, 5};
    EXPECT_TRUE(bitwise_equal(profile, xyz(formats::encode_xyz(profile, {}))));
}

}  // namespace
}  // namespace roughscope::surface
