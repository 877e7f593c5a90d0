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

Json degrees(double radians, double given_degrees) {
    // The argument (docs in json.hpp) needs the few-ulp neighbourhoods of normal doubles on both
    // sides: radians away from the subnormals, degrees away from overflow.
    const double magnitude = std::abs(given_degrees);
    if (!(magnitude >= 1e-280 && magnitude <= 1e300) ||
        std::bit_cast<std::uint64_t>(deg_to_rad(given_degrees)) !=
            std::bit_cast<std::uint64_t>(radians))
        return degrees(radians);
    // At most 13 significant digits. Typed angles first, without the digits: a decimal
    // m·10⁻⁶ (|m| < 10¹³: m and 10⁶ exact, the quotient correctly rounded) that reads back as
    // given_degrees.
    if (magnitude < 1e7) {
        const double m = std::nearbyint(given_degrees * 1e6);
        if (m / 1e6 == given_degrees) return given_degrees;
    }
    if (shortest_digits(given_degrees).count <= 13) return given_degrees;
    return degrees(radians);
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
        case Json::value_t::array:
        case Json::value_t::object: {
            const bool object = value.is_object();
            if (value.empty()) {
                out += object ? "{}" : "[]";
                return;
            }
            out += object ? '{' : '[';
            bool first = true;
            for (const auto& item : value.items()) {
                if (!first) out += ',';
                first = false;
                if (pretty) newline_and_indent(depth + 1);
                if (object) {
                    append_string(out, item.key());
                    out += pretty ? ": " : ":";
                }
                append_value(out, item.value(), indent, depth + 1);
            }
            if (pretty) newline_and_indent(depth);
            out += object ? '}' : ']';
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

char* write_number(char* out, double value) {
    if (!std::isfinite(value)) return std::copy_n("null", 4, out);
    if (std::signbit(value)) {
        *out++ = '-';
        value = -value;
    }
    if (value == 0.0) return std::copy_n("0.0", 3, out);
    // Below 1e-4 and from 1e15 up, every decimal that reads back as `value` is on the same side
    // of 1e-4 and 1e15 as `value` (those two decimals read back as doubles of their own), so the
    // layout is the exponent form below, which is std::to_chars's own scientific form
    // ("d[.igits]e±XX[X]"): taken directly, without the scaling attempt and re-reading the text.
    if (value < 1e-4 || value >= 1e15)
        return std::to_chars(out, out + kNumberBufferSize - 1, value, std::chars_format::scientific)
            .ptr;
    const ShortestDigits d = shortest_digits(value);
    const int n = d.exponent + 1;  // digits before the decimal point
    if (n > -4 && n <= 0) {        // 0.[000]digits
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
