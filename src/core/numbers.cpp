// The strict number parser and the formatter family (numbers.hpp).
#include "roughscope/core/numbers.hpp"

#include <algorithm>
#include <bit>
#include <cassert>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <optional>
#include <system_error>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"

namespace roughscope {
namespace {

[[noreturn]] void refuse_non_finite(std::string_view name) {
    throw Error("internal error: " + std::string(name) +
                " is not a finite number; refusing to print it");
}

// printf's "%.*g" in the C locale (write_significant).
std::string printf_g(double value, int digits) {
    char buf[kSignificantBufferSize];
    return std::string(buf, write_significant(buf, value, digits));
}

// "%.*g" by std::to_chars with a precision, specified to give printf's characters without its
// format parsing (snprintf if it ever refused).
char* write_significant_exact(char* out, double value, int digits) {
    const auto [end, ec] =
        std::to_chars(out, out + kSignificantBufferSize, value, std::chars_format::general, digits);
    if (ec == std::errc()) return end;
    const int n = std::snprintf(out, kSignificantBufferSize, "%.*g", digits, value);
    return out + std::max(0, std::min(n, static_cast<int>(kSignificantBufferSize) - 1));
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

// printf's "%.*g" characters of the decimal ±0.d₁d₂…d_k·10^(exponent+1) rounded to `digits`
// significant digits (dig holds k ≤ digits of them; trailing zeros are dropped here).
char* write_g(char* out, bool negative, const char* dig, int k, int exponent, int digits) {
    while (k > 1 && dig[k - 1] == '0') --k;  // %g drops trailing zeros
    char* o = out;
    if (negative) *o++ = '-';
    if (exponent < -4 || exponent >= digits) {  // style e
        *o++ = dig[0];
        if (k > 1) {
            *o++ = '.';
            for (int i = 1; i < k; ++i) *o++ = dig[i];
        }
        *o++ = 'e';
        *o++ = exponent < 0 ? '-' : '+';
        const int e = std::abs(exponent);
        if (e < 10) *o++ = '0';
        o = std::to_chars(o, o + 4, e).ptr;
    } else if (exponent >= 0) {  // style f, integer part of exponent + 1 digits
        for (int i = 0; i <= exponent; ++i) *o++ = i < k ? dig[i] : '0';
        if (k > exponent + 1) {
            *o++ = '.';
            for (int i = exponent + 1; i < k; ++i) *o++ = dig[i];
        }
    } else {  // style f, 0.000ddd
        *o++ = '0';
        *o++ = '.';
        for (int i = 0; i < -exponent - 1; ++i) *o++ = '0';
        for (int i = 0; i < k; ++i) *o++ = dig[i];
    }
    return o;
}

// |value| rounded to `digits` (1..15) significant digits, m·10^(exponent − digits + 1) with
// 10^(digits−1) ≤ m < 10^digits, from one scaling t = |value|·10^s: with 10^s exact (|s| ≤ 22)
// the product or quotient is correctly rounded, within half an ulp of t of the exact one, so
// rounding t to an integer gives the correctly rounded m unless the exact value may lie within
// that distance of a half-integer (an exact tie among them) — then, and outside the range of
// exact powers, nullopt and the caller takes the exact path.
struct ScaledDigits {
    std::int64_t m = 0;
    int exponent = 0;  // decimal exponent of the leading digit
};

constexpr double kExactPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                  1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                  1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
constexpr int kMaxExactPow10 = 22;

double scale_by_pow10(double a, int s) { return s >= 0 ? a * kExactPow10[s] : a / kExactPow10[-s]; }

std::optional<ScaledDigits> round_by_scaling(double value, int digits) {
    const double a = std::abs(value);
    if (!(a >= std::numeric_limits<double>::min()) || !std::isfinite(a)) return std::nullopt;
    // a in [2^(b-1), 2^b) for the biased exponent field E: b = E − 1022; floor((b − 1)·log10 2),
    // the decimal exponent or one less, as (b − 1)·78913 / 2^18 rounded down (exact for
    // |b| < 1650).
    const int binary_exponent =
        static_cast<int>((std::bit_cast<std::uint64_t>(a) >> 52) & 0x7ff) - 1022;
    int exponent = ((binary_exponent - 1) * 78913) >> 18;
    const double top = kExactPow10[digits];
    int s = digits - 1 - exponent;
    if (s > kMaxExactPow10 || s < -kMaxExactPow10) return std::nullopt;
    double t = scale_by_pow10(a, s);
    if (t >= top) {
        ++exponent;
        --s;
        if (s < -kMaxExactPow10) return std::nullopt;
        t = scale_by_pow10(a, s);
    }
    const auto floor_t = static_cast<double>(static_cast<std::int64_t>(t));  // t < 10^15
    const double fraction = t - floor_t;
    if (std::abs(fraction - 0.5) <= t * 0x1p-52) return std::nullopt;  // a tie within the error
    auto m = static_cast<std::int64_t>(floor_t) + (fraction > 0.5 ? 1 : 0);
    if (m == static_cast<std::int64_t>(top)) {  // rounded up to 10^digits
        m /= 10;
        ++exponent;
    }
    if (m < static_cast<std::int64_t>(kExactPow10[digits - 1])) return std::nullopt;
    return ScaledDigits{m, exponent};
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

// Shortest round-trip digits S of a normal double v are within half an ulp (relative 2^-53) of
// v, far less than half a unit of the 15th significant digit (relative ≥ 5e-16): with
// k ≤ digits ≤ 15 digits, S is the correctly rounded value, and with more, S rounds to the same
// `digits` digits as v unless a rounding boundary lies between them, which the shortest (and,
// among the shortest, closest) digits exclude; S ending on an exact tie ("…5" right after the
// kept digits) goes to the exact path.
SignificantDigits::SignificantDigits(double value) : value_(value) {
    // The digits correctly rounded to kScaledDigits by one exact scaling (cheap), which serve
    // every precision up to that; the shortest round-trip digits when that is not exact.
    if (const auto r = round_by_scaling(value, kScaledDigits)) {
        const char* const end = std::to_chars(digits_, digits_ + sizeof digits_, r->m).ptr;
        count_ = static_cast<int>(end - digits_);
        while (count_ > 1 && digits_[count_ - 1] == '0') --count_;
        exponent_ = r->exponent;
        negative_ = std::signbit(value);
        decomposed_ = true;
        precise_up_to_ = kScaledDigits;
        return;
    }
    *this = SignificantDigits(value, Shortest{});
}

namespace {
// std::to_chars's shortest digits, from its scientific text "[-]d[.ddd]e(+|-)XX[X]".
ShortestDigits shortest_digits_by_to_chars(double value) {
    ShortestDigits out;
    char sci[kSignificantBufferSize];
    const auto printed = std::to_chars(sci, sci + sizeof sci, value, std::chars_format::scientific);
    if (printed.ec != std::errc()) return out;
    const char* p = sci;
    if (*p == '-') ++p;
    int k = 0;
    for (; p < printed.ptr && *p != 'e'; ++p)
        if (*p != '.') out.digits[k++] = *p;
    if (p == printed.ptr) return out;
    ++p;  // 'e'
    const bool negative_exponent = *p == '-';
    if (*p == '-' || *p == '+') ++p;
    int exponent = 0;
    for (; p < printed.ptr; ++p) exponent = exponent * 10 + (*p - '0');
    out.count = k;
    out.exponent = negative_exponent ? -exponent : exponent;
    return out;
}
}  // namespace

ShortestDigits shortest_digits(double value) {
    assert(std::isfinite(value) && value != 0.0);
    if (const auto r = round_by_scaling(value, 15)) {
        const int q = r->exponent - 14;
        if (q >= -kMaxExactPow10 && q <= kMaxExactPow10 &&
            scale_by_pow10(static_cast<double>(r->m), q) == std::abs(value)) {
            ShortestDigits out;
            const char* const end =
                std::to_chars(out.digits, out.digits + sizeof out.digits, r->m).ptr;
            out.count = static_cast<int>(end - out.digits);
            while (out.count > 1 && out.digits[out.count - 1] == '0') --out.count;
            out.exponent = r->exponent;
            return out;
        }
    }
    return shortest_digits_by_to_chars(value);
}

SignificantDigits::SignificantDigits(double value, Shortest) : value_(value) {
    const double magnitude = std::abs(value);
    if (!(magnitude >= std::numeric_limits<double>::min()) || !std::isfinite(value)) return;
    const ShortestDigits d = shortest_digits_by_to_chars(value);
    if (d.count == 0) return;
    std::copy(d.digits, d.digits + d.count, digits_);
    count_ = d.count;
    exponent_ = d.exponent;
    negative_ = std::signbit(value);
    decomposed_ = true;
}

double SignificantDigits::parsed(int digits) const {
    if (digits < 1 || digits > precise_up_to_ || !decomposed_)
        return parse_significant(value_, digits);
    if (count_ == digits + 1 && digits_[digits] == '5') return parse_significant(value_, digits);
    const int k = std::min(count_, digits);
    std::int64_t m = 0;
    for (int i = 0; i < k; ++i) m = m * 10 + (digits_[i] - '0');
    if (count_ > digits && digits_[digits] >= '5') ++m;  // may reach 10^digits: still exact
    const int q = exponent_ - (k - 1);
    if (q > kMaxExactPow10 || q < -kMaxExactPow10) return parse_significant(value_, digits);
    // m < 2^53 and 10^|q| exact: one correctly rounded operation, as strtod rounds.
    const double v = scale_by_pow10(static_cast<double>(m), q);
    return negative_ ? -v : v;
}

bool SignificantDigits::rounding_may_stay_close(int digits) const {
    if (!decomposed_ || digits < 1 || digits > 13 || digits >= count_) return true;
    return digits_[digits] == '0' || digits_[digits] == '9';
}

char* SignificantDigits::write(char* out, int digits) const {
    if (digits < 1 || digits > 15 || !decomposed_)
        return write_significant_exact(out, value_, digits);
    if (digits > precise_up_to_) return SignificantDigits(value_, Shortest{}).write(out, digits);
    char dig[24];
    int k = count_;
    int exponent = exponent_;
    std::copy(digits_, digits_ + k, dig);
    if (k > digits) {
        if (k == digits + 1 && dig[digits] == '5')
            return write_significant_exact(out, value_, digits);
        const bool up = dig[digits] >= '5';
        k = digits;
        if (up) {
            int i = k - 1;
            while (i >= 0 && dig[i] == '9') dig[i--] = '0';
            if (i < 0) {
                dig[0] = '1';
                ++exponent;
            } else {
                ++dig[i];
            }
        }
    }
    return write_g(out, negative_, dig, k, exponent, digits);
}

char* write_significant(char* out, double value, int digits) {
    if (digits < 1 || digits > 15) return write_significant_exact(out, value, digits);
    if (const auto r = round_by_scaling(value, digits)) {
        char dig[24];
        const int k = static_cast<int>(std::to_chars(dig, dig + sizeof dig, r->m).ptr - dig);
        return write_g(out, std::signbit(value), dig, k, r->exponent, digits);
    }
    return SignificantDigits(value, SignificantDigits::Shortest{}).write(out, digits);
}

double parse_significant(double value, int digits) {
    if (digits >= 1 && digits <= 15) {
        if (const auto r = round_by_scaling(value, digits)) {
            const int q = r->exponent - (digits - 1);
            if (q >= -kMaxExactPow10 && q <= kMaxExactPow10) {
                // m < 2^53 and 10^|q| exact: one correctly rounded operation, as strtod rounds.
                const double v = scale_by_pow10(static_cast<double>(r->m), q);
                return std::signbit(value) ? -v : v;
            }
        }
    }
    char buf[kSignificantBufferSize + 1];
    char* const end = write_significant(buf, value, digits);
    double v = 0.0;
    if (std::from_chars(buf, end, v).ec != std::errc()) {
        *end = '\0';
        v = std::strtod(buf, nullptr);  // from_chars refuses what strtod rounds to 0 or inf
    }
    return v;
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
