// Text height files with a UTF-8 byte-order mark (docs/input-files.md: a mark at the start of a
// text file is skipped): CSV matrix, XYZ and ASCII SDF files written here byte by byte, read from
// disk to the same map as without the mark; a mark anywhere else is data (refused), and a binary
// SDF never starts with one.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "../io/test_files.hpp"
#include "expect_data_error.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/surface/formats.hpp"
#include "roughscope/surface/height_map.hpp"

namespace roughscope::surface {
namespace {

using roughscope::testing::expect_data_error;

const std::string kBom = "\xEF\xBB\xBF";

void write_bytes(const std::filesystem::path& path, const std::string& bytes) {
    std::ofstream out(path, std::ios::binary);
    out << bytes;
}

const std::string kCsv = "# dx_um = 0.5\n1.25,-2,3\n4,NaN,6\n";
const std::string kXyz = "0 0 1.5\n2 0 -2\n0 2 3\n2 2 4\n";
const std::string kSdf =
    "aISO-1.0\n"
    "ManufacID   = HandMade\n"
    "CreateDate  = 010120250000\n"
    "ModDate     = 010120250000\n"
    "NumPoints   = 2\n"
    "NumProfiles = 2\n"
    "Xscale      = 1.0E-06\n"
    "Yscale      = 2.0E-06\n"
    "Zscale      = 1.0E-09\n"
    "Zresolution = -1\n"
    "Compression = 0\n"
    "DataType    = 5\n"
    "CheckType   = 0\n"
    "*\n"
    "10 20\n"
    "-30 40\n"
    "*\n";

// The map read from `leaf` with and without a BOM (and with CRLF line ends and a BOM).
void expect_bom_skipped(const std::string& leaf, const std::string& text) {
    const auto dir = testing::fresh_dir("surface_bom_" + leaf);
    write_bytes(dir / ("plain_" + leaf), text);
    write_bytes(dir / ("bom_" + leaf), kBom + text);
    std::string crlf;
    for (const char c : text) {
        if (c == '\n') crlf.push_back('\r');
        crlf.push_back(c);
    }
    write_bytes(dir / ("bom_crlf_" + leaf), kBom + crlf);
    const HeightMap plain = read_height_map(dir / ("plain_" + leaf));
    for (const char* prefix : {"bom_", "bom_crlf_"}) {
        SCOPED_TRACE(prefix + leaf);
        const HeightMap map = read_height_map(dir / (prefix + leaf));
        EXPECT_TRUE(bitwise_equal(map, plain));
    }
    std::filesystem::remove_all(dir);
}

TEST(FormatBom, CsvMatrixWithAByteOrderMarkReadsAsWithout) {
    expect_bom_skipped("m.csv", kCsv);
    const auto dir = testing::fresh_dir("surface_bom_csv_values");
    // The mark directly before the first number (no header line): the number is read.
    write_bytes(dir / "m.csv", kBom + "1.25,-2,3\n4,NaN,6\n");
    const HeightMap map = read_height_map(dir / "m.csv");
    ASSERT_EQ(map.nx, 3U);
    ASSERT_EQ(map.ny, 2U);
    EXPECT_EQ(map.at(0, 0), 1.25);
    EXPECT_EQ(map.at(2, 1), 6.0);
    EXPECT_TRUE(std::isnan(map.at(1, 1)));
    std::filesystem::remove_all(dir);
}

TEST(FormatBom, XyzWithAByteOrderMarkReadsAsWithout) {
    expect_bom_skipped("p.xyz", kXyz);
    const HeightMap map = formats::decode_xyz(kBom + kXyz, "p.xyz", {});
    EXPECT_EQ(map.nx, 2U);
    EXPECT_EQ(map.dx_um, 2.0);
    EXPECT_EQ(map.at(0, 0), 1.5);
}

TEST(FormatBom, AsciiSdfWithAByteOrderMarkReadsAsWithout) {
    expect_bom_skipped("s.sdf", kSdf);
    const HeightMap map = formats::decode_sdf(kBom + kSdf, "s.sdf", {});
    ASSERT_EQ(map.nx, 2U);
    EXPECT_DOUBLE_EQ(map.dy_um, 2.0);
    EXPECT_DOUBLE_EQ(map.at(0, 1), -0.03);
}

TEST(FormatBom, AMarkElsewhereIsDataAndBinarySdfHasNone) {
    // Only the first three bytes of the file may be the mark: on a later line it is a bad number.
    expect_data_error([] { formats::decode_csv_matrix("1,2\n" + kBom + "3,4\n", "m.csv", {}); },
                      {"m.csv:2", "is not a number"});
    // Two marks: the second is data.
    expect_data_error([] { formats::decode_csv_matrix(kBom + kBom + "1,2\n", "m.csv", {}); },
                      {"m.csv:1", "is not a number"});
    // A binary SDF is not text: a mark before its "bISO-1.0" is not an SDF file.
    expect_data_error([] { formats::decode_sdf(kBom + "bISO-1.0", "s.sdf", {}); },
                      {"s.sdf", "not an SDF file"});
}

}  // namespace
}  // namespace roughscope::surface
