// The CSV reader and the line splitter (roughscope/io/csv.hpp).
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/io/csv.hpp"

using namespace roughscope;
namespace fs = std::filesystem;

namespace {

fs::path temp_file(const std::string& name, const std::string& content) {
    const fs::path p =
        fs::temp_directory_path() /
        ("roughscope_io_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
         "_" + name);
    std::ofstream(p, std::ios::binary) << content;
    return p;
}

std::string error_of(const std::string& content, std::vector<std::string> required,
                     std::vector<std::string> optional = {}) {
    std::istringstream in(content);
    try {
        io::CsvReader reader(in, "t.csv", std::move(required), std::move(optional));
        io::CsvRow row;
        std::size_t n = 0;
        while (reader.next(row)) ++n;
        if (n == 0) return "no rows";
    } catch (const DataError& e) {
        return e.what();
    }
    return "no error";
}

}  // namespace

TEST(Csv, SplitsFieldsAndWords) {
    EXPECT_EQ(io::split_fields("a,,b", ',').size(), 3u);
    EXPECT_EQ(io::split_fields("", ',').size(), 1u);
    const auto w = io::split_whitespace("  1\t2   3 \r");
    ASSERT_EQ(w.size(), 3u);
    EXPECT_EQ(w[2], "3");
    EXPECT_TRUE(io::split_whitespace(" \t ").empty());
    EXPECT_EQ(io::trim(" \tx y\r\n"), "x y");
}

TEST(Csv, AcceptsBomCrlfCommentsAndBlankLines) {
    const std::string text =
        "\xEF\xBB\xBF# comment\r\n"
        "\r\n"
        "x, y ,label\r\n"
        "1, 2.5, a\r\n"
        "  # another\r\n"
        "-3,+4e1,b\r\n";
    std::istringstream in(text);
    io::CsvReader reader(in, "t.csv", {"x"}, {"y"});
    EXPECT_EQ(reader.header(), (std::vector<std::string>{"x", "y", "label"}));
    io::CsvRow row;
    ASSERT_TRUE(reader.next(row));
    EXPECT_EQ(row.line, 4u);
    EXPECT_EQ(row.at("x"), 1.0);
    EXPECT_EQ(row.find("y"), 2.5);
    EXPECT_EQ(row.text("label"), "a");
    ASSERT_TRUE(reader.next(row));
    EXPECT_EQ(row.line, 6u);
    EXPECT_EQ(row.at("y"), 40.0);
    EXPECT_FALSE(reader.next(row));
    EXPECT_EQ(reader.rows_read(), 2u);
}

TEST(Csv, BomOnTheHeaderLineIsNotPartOfTheFirstName) {
    std::istringstream in("\xEF\xBB\xBFtheta_i,value\n10,1\n");
    io::CsvReader reader(in, "t.csv", {"theta_i", "value"});
    EXPECT_TRUE(reader.has_column("theta_i"));
}

TEST(Csv, EmptyOptionalCellIsNotGiven) {
    std::istringstream in("x,w\n1,\n");
    io::CsvReader reader(in, "t.csv", {"x"}, {"w"});
    io::CsvRow row;
    ASSERT_TRUE(reader.next(row));
    EXPECT_FALSE(row.find("w").has_value());
    EXPECT_THROW((void)row.at("w"), DataError);
}

TEST(Csv, BadNumberNamesFileLineAndColumn) {
    EXPECT_EQ(error_of("x,y\n1,2\n# c\n3,1.5x\n", {"x", "y"}),
              "t.csv:4: column y: '1.5x' is not a number");
    EXPECT_EQ(error_of("x\nnan\n", {"x"}),
              "t.csv:2: column x: 'nan' is not a finite number (NaN is not accepted)");
    EXPECT_EQ(error_of("x,y\n1,\n", {"x", "y"}),
              "t.csv:2: column y: '' is empty (a number is required)");
}

TEST(Csv, MissingColumnListsFoundRequiredAndOptional) {
    EXPECT_EQ(error_of("x,z\n1,2\n", {"x", "y"}, {"w"}),
              "t.csv:1: missing column(s) y (found: x, z; required: x, y; optional: w)");
    EXPECT_NE(error_of("x,x\n", {"x"}).find("t.csv:1: duplicate column 'x'"), std::string::npos);
    EXPECT_NE(error_of("x,,y\n", {"x"}).find("empty column name"), std::string::npos);
}

TEST(Csv, WrongFieldCount) {
    EXPECT_EQ(error_of("x,y\n1\n", {"x"}), "t.csv:2: expected 2 fields (x,y), found 1");
}

TEST(Csv, EmptyFileHasNoHeader) {
    EXPECT_EQ(error_of("", {"x"}), "t.csv: no header line (expected columns x)");
    EXPECT_EQ(error_of("# only a comment\n\n", {"x"}),
              "t.csv: no header line (expected columns x)");
    EXPECT_EQ(error_of("x\n", {"x"}), "no rows");
}

TEST(Csv, ReadAllFromAFile) {
    const fs::path p = temp_file("all.csv", "a,b\n1,2\n3,4\n");
    const auto rows = io::read_csv(p, {"a", "b"});
    ASSERT_EQ(rows.size(), 2u);
    EXPECT_EQ(rows[1].at("b"), 4.0);
    const fs::path empty = temp_file("empty.csv", "a,b\n");
    try {
        io::read_csv(empty, {"a"});
        FAIL() << "no exception";
    } catch (const DataError& e) {
        EXPECT_NE(std::string(e.what()).find("no data rows"), std::string::npos);
    }
    fs::remove(p);
    fs::remove(empty);
    EXPECT_THROW(io::read_csv(p, {"a"}), DataError);                          // missing file
    EXPECT_THROW(io::read_csv(fs::temp_directory_path(), {"a"}), DataError);  // a directory
}

// Streaming: a large generated file is read row by row; the count and a checksum match.
TEST(Csv, StreamsALargeFileRowByRow) {
    constexpr std::size_t kRows = 200000;
    const fs::path p = temp_file("large.csv", "");
    {
        std::ofstream out(p, std::ios::binary);
        out << "i,x,label\r\n";
        for (std::size_t i = 0; i < kRows; ++i) out << i << "," << 0.5 * i << ",r\r\n";
    }
    io::CsvReader reader(p, {"i", "x"});
    io::CsvRow row;
    std::size_t n = 0;
    double sum = 0.0;
    while (reader.next(row)) {
        ASSERT_EQ(row.at("i"), static_cast<double>(n));
        sum += row.at("x");
        ++n;
    }
    EXPECT_EQ(n, kRows);
    EXPECT_EQ(reader.rows_read(), kRows);
    EXPECT_EQ(row.line, kRows + 1);
    EXPECT_DOUBLE_EQ(sum, 0.5 * (kRows - 1) * kRows / 2.0);
    fs::remove(p);
}

TEST(Csv, LineReaderStripsBomOnlyAtTheStart) {
    std::istringstream in(
        "\xEF\xBB\xBF"
        "a\r\n\xEF\xBB\xBF"
        "b\n");
    io::LineReader lines(in, "mem");
    std::string_view l;
    ASSERT_TRUE(lines.next(l));
    EXPECT_EQ(l, "a");
    ASSERT_TRUE(lines.next(l));
    EXPECT_EQ(l,
              "\xEF\xBB\xBF"
              "b");
    EXPECT_EQ(lines.where(), "mem:2: ");
    EXPECT_FALSE(lines.next(l));
    EXPECT_THROW(io::LineReader(fs::path("/nonexistent/roughscope/file.txt")), DataError);
}

TEST(Csv, FieldQuotingForWriting) {
    EXPECT_EQ(io::csv_field("plain"), "plain");
    EXPECT_EQ(io::csv_field("a,\"b\""), "\"a,\"\"b\"\"\"");
}
