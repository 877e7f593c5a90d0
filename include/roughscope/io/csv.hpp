// Reading delimited text files: the library's one CSV reader and the line/field splitter under it.
//
// Conventions shared by every text format the library reads (CSV tables, CUReT's table.txt and
// *.dat files; the JSON reference file too) — the one reading policy of docs/input-files.md:
//  * a UTF-8 byte-order mark at the start of the file is skipped; CRLF and LF line ends are both
//    accepted (one trailing CR is removed from every line); spaces and tabs around fields too;
//  * numbers are parsed strictly (roughscope/core/numbers.hpp): decimal only, "0x19", "nan",
//    "inf", "1.5x" are errors; integers are decimal digits only;
//  * a NUL byte makes it a binary file: DataError "<file>:<line>: not a text file: NUL byte ...";
//  * every error is a DataError "<file>:<line>: <reason>" naming the column or field, with the
//    input quoted by quote_input (core/text.hpp: escaped, at most 64 bytes shown).
//
// CSV (CsvReader): comma-separated, one header line naming the columns, then data rows.
//  * Blank lines and lines whose first non-space character is '#' are skipped (before or after
//    the header); fields are trimmed of spaces/tabs. No quoting.
//  * The header must contain every `required` column; `optional` columns are parsed as numbers
//    when present; other columns are kept as text only. Column names are case-sensitive.
//  * An empty cell of an optional column means "not given"; an empty required cell is an error.
// Rows are read one at a time (memory bounded by the longest line), or all at once with read_csv.
#pragma once

#include <cstddef>
#include <filesystem>
#include <iosfwd>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "roughscope/core/numbers.hpp"

namespace roughscope::io {

// ---------------------------------------------------------------------------------------------
// Lower level: lines and fields

// `s` without leading and trailing spaces, tabs, CR and LF (core/numbers.hpp's trim_space).
inline std::string_view trim(std::string_view s) { return trim_space(s); }

// The fields of `line` between `separator`s, untrimmed ("a,,b" -> "a", "", "b"; "" -> one field).
std::vector<std::string_view> split_fields(std::string_view line, char separator);

// The whitespace-separated words of `line` (empty for a blank line).
std::vector<std::string_view> split_whitespace(std::string_view line);

// The same into `out` (cleared first; its capacity is reused, for readers of many lines).
void split_fields(std::string_view line, char separator, std::vector<std::string_view>& out);
void split_whitespace(std::string_view line, std::vector<std::string_view>& out);

// The lines of a text held in memory (a file's bytes), by LineReader's rules: a UTF-8
// byte-order mark at the start is skipped, one trailing CR removed from each line, a NUL byte is
// a DataError "<source>:<line>: not a text file: NUL byte at column C". The lines are views into
// `text`, which must outlive the reader.
class TextLines {
  public:
    TextLines(std::string_view text, std::string source);

    // The next line (without its end); false at the end of the text.
    bool next(std::string_view& line);

    std::size_t line_number() const { return line_; }  // of the last line returned
    const std::string& source() const { return source_; }

  private:
    std::string_view rest_;
    bool done_ = false;
    std::string source_;
    std::size_t line_ = 0;
};

// Reads a text stream line by line: skips a UTF-8 byte-order mark at the start and removes one
// trailing CR from each line. Counts lines from 1 for error messages.
class LineReader {
  public:
    // Reads `in` (which must outlive the reader); `source` names it in messages.
    LineReader(std::istream& in, std::string source);
    // Opens `path`; throws DataError "<path>: cannot open: <reason>" (or "is a directory").
    explicit LineReader(const std::filesystem::path& path);
    ~LineReader();
    LineReader(LineReader&&) noexcept;
    LineReader& operator=(LineReader&&) noexcept;

    // The next line (without its end), valid until the next call; false at the end of input.
    // Throws DataError "<source>: read error" on an I/O failure.
    bool next(std::string_view& line);

    std::size_t line_number() const { return line_; }  // of the last line returned
    const std::string& source() const { return source_; }
    // "<source>:<line>: " for the last line returned.
    std::string where() const;

  private:
    std::unique_ptr<std::istream> owned_;
    std::istream* in_ = nullptr;
    std::string source_;
    std::string buffer_;
    std::size_t line_ = 0;
};

// ---------------------------------------------------------------------------------------------
// CSV with a header

// One data row, stored by column in header order (no per-row lookup structures: a row object is
// reused by CsvReader::next without reallocating).
struct CsvRow {
    std::size_t line = 0;                                     // 1-based line number in the file
    std::shared_ptr<const std::vector<std::string>> columns;  // the header (shared, not copied)
    std::vector<std::string> cells;                           // every column, trimmed, as written
    std::vector<double> numbers;                              // parsed value of each numeric column
    std::vector<unsigned char> present;                       // 1 where numbers[c] holds a value

    // Position of a column in the header, or std::nullopt.
    std::optional<std::size_t> column(std::string_view name) const;
    // A value: required column, or optional column given on this row; DataError "line N: ..."
    // if absent.
    double at(std::string_view column) const;
    // An optional column's value, std::nullopt when absent or empty on this row.
    std::optional<double> find(std::string_view column) const;
    // The same by position (CsvReader::column_index), for loops over many rows.
    std::optional<double> value(std::size_t column) const {
        return present[column] ? std::optional<double>(numbers[column]) : std::nullopt;
    }
    // The trimmed text of a column; DataError "line N: no column <name>" if there is none.
    const std::string& text(std::string_view column) const;
};

// Streams the rows of a CSV file (see the conventions above). The header is read by the
// constructor.
class CsvReader {
  public:
    // Opens `path`. Throws DataError for a missing/unreadable file, a missing header ("no header
    // line"), a header with an empty or duplicate column name, or missing required columns
    // ("missing column(s) a, b (found: ...; required: ...; optional: ...)").
    CsvReader(const std::filesystem::path& path, std::vector<std::string> required,
              std::vector<std::string> optional = {});
    // The same from a stream (which must outlive the reader); `source` names it in messages.
    CsvReader(std::istream& in, std::string source, std::vector<std::string> required,
              std::vector<std::string> optional = {});

    const std::vector<std::string>& header() const { return header_; }
    bool has_column(std::string_view name) const;
    // Position of a column in the header (for CsvRow::value), or std::nullopt.
    std::optional<std::size_t> column_index(std::string_view name) const;
    const std::string& source() const { return lines_.source(); }

    // Reads the next data row into `row`; false at the end of the file. Throws DataError
    // "<file>:<line>: ..." for a wrong number of fields ("expected N fields (...), found M") or
    // a bad number ("column <name>: '<cell>' is not a number").
    bool next(CsvRow& row);

    std::size_t rows_read() const { return rows_; }

  private:
    void read_header();

    LineReader lines_;
    std::vector<std::string> required_, optional_, header_;
    std::shared_ptr<const std::vector<std::string>> shared_header_;
    std::vector<std::string_view> fields_;  // the fields of the current line (reused)
    std::vector<int> kind_;                 // per column: 0 = text only, 1 = required, 2 = optional
    std::size_t rows_ = 0;
};

// Every row of a CSV file (CsvReader); throws DataError "<file>: no data rows after the header"
// when there are none.
std::vector<CsvRow> read_csv(const std::filesystem::path& path,
                             const std::vector<std::string>& required,
                             const std::vector<std::string>& optional = {});

// Quotes a CSV field for writing only if it contains a comma, quote or line break.
std::string csv_field(std::string_view text);

}  // namespace roughscope::io
