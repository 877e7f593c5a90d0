// The text building blocks of the reports (text.hpp).
#include "roughscope/serialize/text.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "roughscope/core/errors.hpp"

namespace roughscope::serialize {
namespace {

// Characters of UTF-8 text (bytes that do not continue a character).
std::size_t width_of(std::string_view text) {
    return static_cast<std::size_t>(std::count_if(text.begin(), text.end(), [](char c) {
        return (static_cast<unsigned char>(c) & 0xC0) != 0x80;
    }));
}

}  // namespace

std::string text_table(const std::vector<std::string>& header,
                       const std::vector<std::vector<std::string>>& rows, TextTableStyle style) {
    std::size_t ncol = header.size();
    for (const auto& r : rows) ncol = std::max(ncol, r.size());
    std::vector<std::size_t> width(ncol, 0);
    const auto measure = [&](const std::vector<std::string>& r) {
        for (std::size_t c = 0; c < r.size(); ++c) width[c] = std::max(width[c], width_of(r[c]));
    };
    measure(header);
    for (const auto& r : rows) measure(r);
    std::string out;
    const auto emit = [&](const std::vector<std::string>& r) {
        std::string line;
        for (std::size_t c = 0; c < ncol; ++c) {
            const std::string cell = c < r.size() ? r[c] : "";
            const std::string pad(width[c] - width_of(cell), ' ');
            if (c) line += "  ";
            line += c == 0 && style.first_column_left ? cell + pad : pad + cell;
        }
        while (!line.empty() && line.back() == ' ') line.pop_back();
        out += line;
        out += '\n';
    };
    if (!header.empty()) {
        emit(header);
        if (style.rule) {
            std::size_t total = 0;
            for (std::size_t c = 0; c < ncol; ++c) total += width[c] + (c ? 2 : 0);
            out += std::string(total, '-');
            out += '\n';
        }
    }
    for (const auto& r : rows) emit(r);
    return out;
}

std::string key_value_lines(const std::vector<std::pair<std::string, std::string>>& items) {
    std::size_t width = 0;
    for (const auto& [k, v] : items) width = std::max(width, width_of(k));
    std::string out;
    for (const auto& [k, v] : items) {
        out += k;
        out += std::string(width - width_of(k) + 2, ' ');
        out += v;
        out += '\n';
    }
    return out;
}

std::string format_fixed(double value, int decimals, std::string_view name) {
    if (!std::isfinite(value))
        throw Error("internal error: " + std::string(name) +
                    " is not a finite number; refusing to print it");
    if (decimals < 0 || decimals > 17)
        throw InvalidArgument("decimals = " + std::to_string(decimals) +
                              " is outside the valid range [0, 17]");
    char buf[400];  // %.17f of the largest double needs 309 + 1 + 17 characters
    std::snprintf(buf, sizeof buf, "%.*f", decimals, value);
    return buf;
}

}  // namespace roughscope::serialize
