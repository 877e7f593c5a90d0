// JSON building blocks (serialize/json.hpp).
#include "roughscope/serialize/json.hpp"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string_view>

#include "roughscope/core/numbers.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/version.hpp"

namespace roughscope::serialize {

Json number(double value) { return std::isfinite(value) ? Json(value) : Json(nullptr); }

Json number(const std::optional<double>& value) { return value ? number(*value) : Json(nullptr); }

Json degrees(double radians) {
    const double deg = rad_to_deg(radians);
    if (!std::isfinite(deg)) return nullptr;
    // A rounding that moves deg by relative 1e-14 or more cannot map to the same radians (they
    // are within an ulp or two of each other): those precisions are not tried.
    const SignificantDigits significant(deg);
    for (int digits = 1; digits <= 17; ++digits) {
        if (!significant.rounding_may_stay_close(digits)) continue;
        const double candidate = significant.parsed(digits);  // strtod("%.*g")
        if (deg_to_rad(candidate) == radians) return candidate;
    }
    return deg;
}

Json numbers(const std::vector<double>& values) {
    Json out = Json::array();
    for (double v : values) out.push_back(number(v));
    return out;
}

Json text_or_null(const std::string& text) { return text.empty() ? Json(nullptr) : Json(text); }

Json versioned(Json document) {
    if (document.is_array()) {
        for (Json& element : document) element = versioned(std::move(element));
        return document;
    }
    if (!document.is_object()) return document;
    Json out = Json::object();
    out[kVersionKey] = ROUGHSCOPE_VERSION_STRING;
    for (auto& [key, value] : document.items())
        if (key != kVersionKey) out[key] = std::move(value);
    return out;
}

namespace {

// A string nlohmann's dump writes as its bytes (ensure_ascii off): ASCII without control
// characters, quote or backslash. Anything else (escapes, UTF-8, invalid UTF-8) is left to it.
bool written_as_is(std::string_view text) {
    return std::all_of(text.begin(), text.end(), [](char c) {
        const auto u = static_cast<unsigned char>(c);
        return u >= 0x20 && u < 0x80 && c != '"' && c != '\\';
    });
}

// nlohmann's escaping; error_handler::replace: invalid UTF-8 in a name read from a file cannot
// abort the output.
void append_string(std::string& out, const std::string& text) {
    if (written_as_is(text)) {
        out += '"';
        out += text;
        out += '"';
    } else {
        out += Json(text).dump(-1, ' ', false, Json::error_handler_t::replace);
    }
}

// `value` as nlohmann's dump(indent) writes it at nesting depth `depth` (indent < 0: one line).
void append_value(std::string& out, const Json& value, int indent, int depth) {
    const bool pretty = indent >= 0;
    const auto newline_and_indent = [&](int level) {
        out += '\n';
        out.append(static_cast<std::size_t>(indent) * static_cast<std::size_t>(level), ' ');
    };
    switch (value.type()) {
        case Json::value_t::null:
            out += "null";
            return;
        case Json::value_t::boolean:
            out += value.get<bool>() ? "true" : "false";
            return;
        case Json::value_t::number_integer:
        case Json::value_t::number_unsigned: {
            char buffer[24];
            const char* const end =
                value.is_number_unsigned()
                    ? std::to_chars(buffer, buffer + sizeof buffer, value.get<std::uint64_t>()).ptr
                    : std::to_chars(buffer, buffer + sizeof buffer, value.get<std::int64_t>()).ptr;
            out.append(buffer, static_cast<std::size_t>(end - buffer));
            return;
        }
        case Json::value_t::number_float: {
            char buffer[kNumberBufferSize];
            const char* const end = write_number(buffer, value.get<double>());
            out.append(buffer, static_cast<std::size_t>(end - buffer));
            return;
        }
        case Json::value_t::string:
            append_string(out, value.get_ref<const std::string&>());
            return;
        case Json::value_t::array: {
            if (value.empty()) {
                out += "[]";
                return;
            }
            out += '[';
            bool first = true;
            for (const Json& element : value) {
                if (!first) out += ',';
                first = false;
                if (pretty) newline_and_indent(depth + 1);
                append_value(out, element, indent, depth + 1);
            }
            if (pretty) newline_and_indent(depth);
            out += ']';
            return;
        }
        case Json::value_t::object: {
            if (value.empty()) {
                out += "{}";
                return;
            }
            out += '{';
            bool first = true;
            for (const auto& [key, element] : value.items()) {
                if (!first) out += ',';
                first = false;
                if (pretty) newline_and_indent(depth + 1);
                append_string(out, key);
                out += pretty ? ": " : ":";
                append_value(out, element, indent, depth + 1);
            }
            if (pretty) newline_and_indent(depth);
            out += '}';
            return;
        }
        case Json::value_t::binary:
        case Json::value_t::discarded:
            break;
    }
    // Left to nlohmann (no roughscope document holds one): its text at depth 0, whose line breaks
    // get this depth's indentation (a binary value holds no string).
    const std::string text = value.dump(indent, ' ', false, Json::error_handler_t::replace);
    for (char c : text) {
        if (c == '\n')
            newline_and_indent(depth);
        else
            out += c;
    }
}

}  // namespace

namespace {

constexpr double kExactPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                  1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                  1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
constexpr int kMaxExactPow10 = 22;

// Significant digits d1 d2 ... d_count of a positive number, d1 != 0: value = 0.d1d2... * 10^point.
struct Digits {
    char digits[kNumberBufferSize];
    int count = 0;
    int point = 0;
};

// The shortest round-trip digits when some decimal of at most 15 significant digits reads back as
// `value` (> 0): then it is the only one — two such decimals are at least 10^-15 of the value
// apart, more than the width 2^-52 of the interval of reals that read as one normal double — so
// it is the text std::to_chars gives. One scaling by an exact power of ten (|s| <= 22) finds the
// candidate m * 10^-s, m < 10^15 + 1; the exact quotient (or product) tells whether it reads
// back. False when it does not (16 or 17 digits needed) or the scaling is not exact.
bool few_digits(double value, Digits& out) {
    if (!(value >= std::numeric_limits<double>::min())) return false;
    // value in [2^b, 2^(b+1)): floor(b log10 2) is its decimal exponent or one less
    // (b * 78913 / 2^18 rounded down, exact for |b| < 1650).
    const int b = static_cast<int>((std::bit_cast<std::uint64_t>(value) >> 52) & 0x7ff) - 1023;
    int s = 14 - ((b * 78913) >> 18);
    if (s > kMaxExactPow10 || s <= -kMaxExactPow10) return false;
    const auto scale = [](double a, int by) {
        return by >= 0 ? a * kExactPow10[by] : a / kExactPow10[-by];
    };
    double t = scale(value, s);  // in [10^14, 10^16)
    if (t >= 1e15) t = scale(value, --s);
    // t rounded to an integer (t < 2^51: its fraction is exact).
    const auto whole = static_cast<std::uint64_t>(t);
    const std::uint64_t m = whole + (t - static_cast<double>(whole) >= 0.5 ? 1 : 0);
    const double back =
        s >= 0 ? static_cast<double>(m) / kExactPow10[s] : static_cast<double>(m) * kExactPow10[-s];
    if (back != value) return false;
    const char* const end = std::to_chars(out.digits, out.digits + sizeof out.digits, m).ptr;
    int count = static_cast<int>(end - out.digits);
    out.point = count - s;
    while (out.digits[count - 1] == '0') --count;  // m > 0
    out.count = count;
    return true;
}

// The shortest round-trip digits of a positive finite `value` from std::to_chars's scientific
// text "d[.ddd]e(+|-)XX[X]".
void shortest_digits(double value, Digits& out) {
    char text[kNumberBufferSize];
    const char* const begin = text;
    const char* const end =
        std::to_chars(text, text + sizeof text, value, std::chars_format::scientific).ptr;
    const char* const e = std::find(begin, end, 'e');
    int exponent = 0;
    for (const char* p = e + 2; p < end; ++p) exponent = exponent * 10 + (*p - '0');
    out.point = (e[1] == '-' ? -exponent : exponent) + 1;
    out.digits[0] = text[0];
    int count = 1;
    if (e - begin > 1) {  // "d.ddd"
        count = static_cast<int>(e - begin) - 1;
        std::copy(begin + 2, e, out.digits + 1);
    }
    out.count = count;
}

}  // namespace

char* write_number(char* out, double value) {
    if (!std::isfinite(value)) return std::copy_n("null", 4, out);
    if (std::signbit(value)) {
        *out++ = '-';
        value = -value;
    }
    if (value == 0.0) return std::copy_n("0.0", 3, out);
    Digits d;
    if (!few_digits(value, d)) shortest_digits(value, d);
    const int n = d.point;   // digits before the decimal point
    if (n > -4 && n <= 0) {  // 0.[000]digits
        *out++ = '0';
        *out++ = '.';
        out = std::fill_n(out, -n, '0');
        return std::copy_n(d.digits, d.count, out);
    }
    if (n > 0 && n <= 15) {
        if (d.count <= n) {  // digits[000].0
            out = std::copy_n(d.digits, d.count, out);
            out = std::fill_n(out, n - d.count, '0');
            *out++ = '.';
            *out++ = '0';
            return out;
        }
        out = std::copy_n(d.digits, n, out);  // dig.its
        *out++ = '.';
        return std::copy_n(d.digits + n, d.count - n, out);
    }
    // d[.igits]e(+|-)XX[X], at least two exponent digits.
    *out++ = d.digits[0];
    if (d.count > 1) {
        *out++ = '.';
        out = std::copy_n(d.digits + 1, d.count - 1, out);
    }
    *out++ = 'e';
    int exponent = n - 1;
    *out++ = exponent < 0 ? '-' : '+';
    exponent = std::abs(exponent);
    if (exponent >= 100) {
        *out++ = static_cast<char>('0' + exponent / 100);
        exponent %= 100;
    }
    *out++ = static_cast<char>('0' + exponent / 10);
    *out++ = static_cast<char>('0' + exponent % 10);
    return out;
}

std::string dump(const Json& value, int indent) {
    std::string out;
    append_value(out, value, indent, 0);
    out += '\n';
    return out;
}

}  // namespace roughscope::serialize
