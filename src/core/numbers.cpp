// The strict number parser and the formatter family (numbers.hpp).
#include "roughscope/core/numbers.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <system_error>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"

namespace roughscope {
namespace {

[[noreturn]] void refuse_non_finite(std::string_view name) {
    throw Error("internal error: " + std::string(name) +
                " is not a finite number; refusing to print it");
}

// printf's "%.*g" in the C locale: std::to_chars with a precision is specified to give the
// same characters, without printf's format parsing and multi-precision arithmetic.
std::string printf_g(double value, int digits) {
    char buf[64];
    const auto [end, ec] =
        std::to_chars(buf, buf + sizeof buf, value, std::chars_format::general, digits);
    if (ec != std::errc()) {
        std::snprintf(buf, sizeof buf, "%.*g", digits, value);
        return buf;
    }
    return std::string(buf, end);
}

// Relative differences this small are floating-point noise, not information, in a message.
constexpr double kConversionNoise = 1e-14;

// Significant digits of a "%g" text (trailing zeros are already dropped by %g).
int significant_digits(std::string_view text) {
    int count = 0;
    bool leading = true;
    for (const char c : text) {
        if (c == 'e' || c == 'E') break;
        if (c < '0' || c > '9') continue;
        if (leading && c == '0') continue;
        leading = false;
        ++count;
    }
    return count;
}

}  // namespace

std::string_view trim_space(std::string_view s) {
    constexpr std::string_view kSpace = " \t\r\n\v\f";
    const auto first = s.find_first_not_of(kSpace);
    if (first == std::string_view::npos) return {};
    const auto last = s.find_last_not_of(kSpace);
    return s.substr(first, last - first + 1);
}

std::optional<double> try_parse_number(std::string_view text, std::string& reason) {
    std::string_view s = trim_space(text);
    if (s.empty()) {
        reason = "empty (a number is required)";
        return std::nullopt;
    }
    if (s.front() == '+' && s.size() > 1 && s[1] != '-') s.remove_prefix(1);
    double value = 0.0;
    const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
    if (ec == std::errc::result_out_of_range) {
        reason = "out of the range of double-precision numbers";
        return std::nullopt;
    }
    if (s.empty() || ec != std::errc() || ptr != s.data() + s.size()) {
        reason = "not a number";
        return std::nullopt;
    }
    if (std::isnan(value)) {
        reason = "not a finite number (NaN is not accepted)";
        return std::nullopt;
    }
    if (std::isinf(value)) {
        reason = "not a finite number (infinity is not accepted)";
        return std::nullopt;
    }
    return value;
}

double parse_number(std::string_view text, std::string_view what) {
    std::string reason;
    const auto value = try_parse_number(text, reason);
    if (!value)
        throw InvalidArgument(std::string(what) + ": " + quote_input(trim_space(text)) + " is " +
                              reason);
    return *value;
}

std::optional<long long> try_parse_integer(std::string_view text, long long lo, long long hi,
                                           std::string& reason) {
    std::string_view s = trim_space(text);
    if (s.empty()) {
        reason = "empty (an integer is required)";
        return std::nullopt;
    }
    if (s.front() == '+' && s.size() > 1 && s[1] != '-') s.remove_prefix(1);
    long long value = 0;
    const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), value, 10);
    if (ec == std::errc::invalid_argument || ptr != s.data() + s.size()) {
        reason = "not an integer (decimal digits only)";
        return std::nullopt;
    }
    if (ec == std::errc::result_out_of_range || value < lo || value > hi) {
        reason = "out of the range [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
        return std::nullopt;
    }
    return value;
}

long long parse_integer(std::string_view text, long long lo, long long hi, std::string_view what) {
    std::string reason;
    const auto value = try_parse_integer(text, lo, hi, reason);
    if (!value)
        throw InvalidArgument(std::string(what) + ": " + quote_input(trim_space(text)) + " is " +
                              reason);
    return *value;
}

std::vector<double> parse_number_list(std::string_view text, std::size_t count,
                                      std::string_view what) {
    std::vector<std::string_view> parts;
    for (std::size_t start = 0;;) {
        const auto comma = text.find(',', start);
        parts.push_back(
            text.substr(start, comma == std::string_view::npos ? comma : comma - start));
        if (comma == std::string_view::npos) break;
        start = comma + 1;
    }
    if (parts.size() != count)
        throw InvalidArgument(std::string(what) + ": expected " + std::to_string(count) +
                              " comma-separated numbers, got " + quote_input(trim_space(text)));
    std::vector<double> out;
    out.reserve(count);
    for (std::size_t i = 0; i < parts.size(); ++i)
        out.push_back(
            parse_number(parts[i], std::string(what) + " (item " + std::to_string(i + 1) + ")"));
    return out;
}

std::string format_roundtrip(double value, std::string_view name) {
    if (!std::isfinite(value)) refuse_non_finite(name);
    char buf[64];
    const auto res = std::to_chars(buf, buf + sizeof buf, value);
    return std::string(buf, res.ptr);
}

std::string format_significant(double value, int digits, std::string_view name) {
    if (!std::isfinite(value)) refuse_non_finite(name);
    if (digits < 1 || digits > 17)
        throw InvalidArgument("digits = " + std::to_string(digits) +
                              " is outside the valid range [1, 17]");
    return printf_g(value == 0.0 ? 0.0 : value, digits);  // no "-0"
}

std::string format_message(double value, int digits) {
    if (std::isnan(value)) return "nan";
    if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
    if (digits > 0) {
        // Rounding that ends in a shorter, rounder number than asked for ("1" for 1.00000001 at
        // 7 digits) would show the value equal to a limit it breaks: then every digit is shown,
        // unless the difference is rounding noise of a unit conversion (29.999999999999996 deg
        // from 30 deg in radians stays "30").
        std::string rounded = printf_g(value, digits < 17 ? digits : 17);
        const double shown = std::strtod(rounded.c_str(), nullptr);
        if (significant_digits(rounded) >= digits ||
            std::abs(shown - value) <= kConversionNoise * std::abs(value))
            return rounded;
    }
    char buf[64];
    const auto res = std::to_chars(buf, buf + sizeof buf, value);
    return std::string(buf, res.ptr);
}

double round_significant(double value, int digits) {
    if (!std::isfinite(value) || value == 0.0) return value;
    const std::string text = printf_g(value, digits);
    double rounded = value;
    if (std::from_chars(text.data(), text.data() + text.size(), rounded).ec != std::errc())
        return std::strtod(text.c_str(), nullptr);
    return rounded;
}

}  // namespace roughscope
