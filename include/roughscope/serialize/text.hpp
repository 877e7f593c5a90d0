// The text building blocks of the human-readable reports (the CLI's default output), beside the
// JSON, CSV and Markdown writers: every report of a result type is built in serialize (a
// to_text per result), the CLI only prints it.
//  * text_table: an aligned table (widths in characters, so "σ" or "±" count as one);
//  * key_value_lines: "key  value" lines with the keys padded to one width;
//  * format_fixed: `decimals` digits after the point ("%.*f"), as the paper prints its tables.
// Numbers for people: core/numbers.hpp (format_significant), a value with its standard error:
// core/uncertainty.hpp (format_uncertain).
#pragma once

#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace roughscope::serialize {

struct TextTableStyle {
    bool first_column_left = true;  // false: every column right-aligned
    bool rule = true;               // a dashed rule under the header
};

// Rows as an aligned text table: columns separated by two spaces, the first left-aligned and the
// others right-aligned (by default), a dashed rule under the header; no trailing spaces.
std::string text_table(const std::vector<std::string>& header,
                       const std::vector<std::vector<std::string>>& rows,
                       TextTableStyle style = {});

// "key  value" lines, the keys padded to the same width.
std::string key_value_lines(const std::vector<std::pair<std::string, std::string>>& items);

// `decimals` (0..17) digits after the decimal point ("%.*f"). Throws roughscope::Error naming
// `name` if the value is NaN or infinite (never printed).
std::string format_fixed(double value, int decimals, std::string_view name = "value");

}  // namespace roughscope::serialize
