// The CSV reader and the line/field splitter (csv.hpp).
#include "roughscope/io/csv.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <istream>
#include <set>
#include <system_error>
#include <utility>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/io/input_file.hpp"

namespace roughscope::io {
namespace {

bool is_space(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f';
}

// One line as every text reader takes it (csv.hpp): DataError for a NUL byte, the UTF-8
// byte-order mark skipped on line 1, one trailing CR removed.
std::string_view text_line(std::string_view line, std::size_t number, const std::string& source) {
    if (const auto nul = line.find('\0'); nul != std::string_view::npos)
        throw DataError(source + ":" + std::to_string(number) +
                        ": not a text file: NUL byte at column " + std::to_string(nul + 1));
    if (number == 1 && line.starts_with("\xEF\xBB\xBF")) line.remove_prefix(3);  // UTF-8 BOM
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    return line;
}

}  // namespace

void split_fields(std::string_view line, char separator, std::vector<std::string_view>& out) {
    out.clear();
    std::size_t start = 0;
    while (true) {
        const auto pos = line.find(separator, start);
        if (pos == std::string_view::npos) {
            out.push_back(line.substr(start));
            return;
        }
        out.push_back(line.substr(start, pos - start));
        start = pos + 1;
    }
}

void split_whitespace(std::string_view line, std::vector<std::string_view>& out) {
    out.clear();
    std::size_t k = 0;
    while (k < line.size()) {
        while (k < line.size() && is_space(line[k])) ++k;
        const std::size_t start = k;
        while (k < line.size() && !is_space(line[k])) ++k;
        if (k > start) out.push_back(line.substr(start, k - start));
    }
}

std::vector<std::string_view> split_fields(std::string_view line, char separator) {
    std::vector<std::string_view> out;
    split_fields(line, separator, out);
    return out;
}

std::vector<std::string_view> split_whitespace(std::string_view line) {
    std::vector<std::string_view> out;
    split_whitespace(line, out);
    return out;
}

// ---------------------------------------------------------------------------------------------
// TextLines

TextLines::TextLines(std::string_view text, std::string source)
    : rest_(text), source_(std::move(source)) {}

bool TextLines::next(std::string_view& line) {
    if (done_) return false;
    const std::size_t end = rest_.find('\n');
    std::string_view raw = rest_.substr(0, end);
    if (end == std::string_view::npos) {
        done_ = true;
        if (raw.empty()) return false;  // the text ended with a line end (or is empty)
    } else {
        rest_.remove_prefix(end + 1);
    }
    ++line_;
    line = text_line(raw, line_, source_);
    return true;
}

// ---------------------------------------------------------------------------------------------
// LineReader

LineReader::LineReader(std::istream& in, std::string source)
    : in_(&in), source_(std::move(source)) {}

LineReader::LineReader(const std::filesystem::path& path) : source_(path.string()) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec))
        throw DataError(source_ + ": is a directory, not a file");
    check_input_file(path, source_);
    auto file = std::make_unique<std::ifstream>(path, std::ios::binary);
    if (!*file) throw DataError(source_ + ": cannot open: " + std::strerror(errno));
    owned_ = std::move(file);
    in_ = owned_.get();
}

LineReader::~LineReader() = default;
LineReader::LineReader(LineReader&&) noexcept = default;
LineReader& LineReader::operator=(LineReader&&) noexcept = default;

bool LineReader::next(std::string_view& line) {
    if (!std::getline(*in_, buffer_)) {
        if (in_->bad()) throw DataError(source_ + ": read error");
        return false;
    }
    ++line_;
    line = text_line(buffer_, line_, source_);
    return true;
}

std::string LineReader::where() const { return source_ + ":" + std::to_string(line_) + ": "; }

// ---------------------------------------------------------------------------------------------
// CsvRow, CsvReader

std::optional<std::size_t> CsvRow::column(std::string_view name) const {
    if (!columns) return std::nullopt;
    const auto it = std::find(columns->begin(), columns->end(), name);
    if (it == columns->end()) return std::nullopt;
    return static_cast<std::size_t>(it - columns->begin());
}

double CsvRow::at(std::string_view column_name) const {
    const auto c = column(column_name);
    if (!c || !present[*c])
        throw DataError("line " + std::to_string(line) + ": column " + std::string(column_name) +
                        " has no value");
    return numbers[*c];
}

std::optional<double> CsvRow::find(std::string_view column_name) const {
    const auto c = column(column_name);
    if (!c) return std::nullopt;
    return value(*c);
}

const std::string& CsvRow::text(std::string_view column_name) const {
    const auto c = column(column_name);
    if (!c)
        throw DataError("line " + std::to_string(line) + ": no column " + std::string(column_name));
    return cells[*c];
}

CsvReader::CsvReader(const std::filesystem::path& path, std::vector<std::string> required,
                     std::vector<std::string> optional)
    : lines_(path), required_(std::move(required)), optional_(std::move(optional)) {
    read_header();
}

CsvReader::CsvReader(std::istream& in, std::string source, std::vector<std::string> required,
                     std::vector<std::string> optional)
    : lines_(in, std::move(source)),
      required_(std::move(required)),
      optional_(std::move(optional)) {
    read_header();
}

bool CsvReader::has_column(std::string_view name) const { return column_index(name).has_value(); }

std::optional<std::size_t> CsvReader::column_index(std::string_view name) const {
    const auto it = std::find(header_.begin(), header_.end(), name);
    if (it == header_.end()) return std::nullopt;
    return static_cast<std::size_t>(it - header_.begin());
}

void CsvReader::read_header() {
    std::string_view raw;
    while (lines_.next(raw)) {
        const std::string_view line = trim(raw);
        if (line.empty() || line.front() == '#') continue;
        std::set<std::string, std::less<>> seen;
        for (const auto f : split_fields(line, ',')) {
            std::string name(trim(f));
            if (name.empty())
                throw DataError(lines_.where() + "empty column name in the header " +
                                quote_input(line));
            if (!seen.insert(name).second)
                throw DataError(lines_.where() + "duplicate column " + quote_input(name) +
                                " in the header");
            header_.push_back(std::move(name));
        }
        std::vector<std::string> missing;
        for (const auto& r : required_)
            if (!seen.count(r)) missing.push_back(r);
        if (!missing.empty())
            throw DataError(
                lines_.where() + "missing column(s) " + join(missing, ", ") +
                " (found: " + join(header_, ", ") + "; required: " + join(required_, ", ") +
                (optional_.empty() ? "" : "; optional: " + join(optional_, ", ")) + ")");
        for (const auto& name : header_) {
            if (std::find(required_.begin(), required_.end(), name) != required_.end())
                kind_.push_back(1);
            else if (std::find(optional_.begin(), optional_.end(), name) != optional_.end())
                kind_.push_back(2);
            else
                kind_.push_back(0);
        }
        shared_header_ = std::make_shared<const std::vector<std::string>>(header_);
        return;
    }
    throw DataError(lines_.source() + ": no header line (expected columns " +
                    join(required_, ", ") + ")");
}

bool CsvReader::next(CsvRow& row) {
    std::string_view raw;
    while (lines_.next(raw)) {
        const std::string_view line = trim(raw);
        if (line.empty() || line.front() == '#') continue;
        split_fields(line, ',', fields_);
        if (fields_.size() != header_.size())
            throw DataError(lines_.where() + "expected " + std::to_string(header_.size()) +
                            " fields (" + join(header_, ",") + "), found " +
                            std::to_string(fields_.size()));
        row.line = lines_.line_number();
        if (row.columns != shared_header_) row.columns = shared_header_;
        row.cells.resize(header_.size());
        row.numbers.assign(header_.size(), 0.0);
        row.present.assign(header_.size(), 0);
        for (std::size_t c = 0; c < fields_.size(); ++c) {
            const std::string_view cell = trim(fields_[c]);
            row.cells[c].assign(cell);
            if (kind_[c] == 0) continue;
            if (cell.empty() && kind_[c] == 2) continue;  // optional, not given on this row
            std::string reason;
            const auto value = try_parse_number(cell, reason);
            if (!value)
                throw DataError(lines_.where() + "column " + header_[c] + ": " + quote_input(cell) +
                                " is " + reason);
            row.numbers[c] = *value;
            row.present[c] = 1;
        }
        ++rows_;
        return true;
    }
    return false;
}

std::vector<CsvRow> read_csv(const std::filesystem::path& path,
                             const std::vector<std::string>& required,
                             const std::vector<std::string>& optional) {
    CsvReader reader(path, required, optional);
    std::vector<CsvRow> rows;
    CsvRow row;
    while (reader.next(row)) rows.push_back(row);
    if (rows.empty()) throw DataError(reader.source() + ": no data rows after the header");
    return rows;
}

std::string csv_field(std::string_view text) {
    if (text.find_first_of(",\"\n\r") == std::string_view::npos) return std::string(text);
    std::string out = "\"";
    for (char c : text) {
        if (c == '"') out += '"';
        out += c;
    }
    out += '"';
    return out;
}

}  // namespace roughscope::io
