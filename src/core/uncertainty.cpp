// "value ± error" (uncertainty.hpp). Every rounding is printf's, correctly rounded from the
// binary value at a decimal place, so the error's two digits and the value's last one are the
// digits of the same place.
#include "roughscope/core/uncertainty.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/numbers.hpp"

namespace roughscope {
namespace {

// Values up to this magnitude, and errors from 10^kMinFixedExponent to it, in fixed notation.
constexpr double kMaxFixed = 1e15;
constexpr int kMinFixedExponent = -5;
// A double has 17 significant digits at most: no more decimals in a mantissa.
constexpr int kMaxDecimals = 16;

std::string printf_text(const char* format, int precision, double value) {
    char buf[400];  // "%.17f" of 1e15 or "%.17e" of any double fits easily
    const int n = std::snprintf(buf, sizeof buf, format, precision, value);
    return std::string(buf, n > 0 ? static_cast<std::size_t>(n) : 0);
}

// The decimal exponent of a "%e" text ("d.ddde-05" → -5).
int exponent_of(const std::string& scientific) {
    return std::atoi(scientific.c_str() + scientific.find('e') + 1);
}

// "-0.000" (a small negative value rounded to zero) without its sign.
std::string without_negative_zero(std::string text) {
    if (!text.empty() && text.front() == '-' &&
        text.find_first_not_of("0.", 1) == std::string::npos)
        text.erase(0, 1);
    return text;
}

}  // namespace

std::string format_uncertain(double value, std::optional<double> std_error, int digits,
                             std::string_view name) {
    if (digits < 1 || digits > 17)
        throw InvalidArgument("digits = " + std::to_string(digits) +
                              " is outside the valid range [1, 17]");
    const bool usable = std_error && std::isfinite(*std_error) && *std_error > 0.0;
    if (!usable || !std::isfinite(value)) return format_significant(value, digits, name);
    const double error = *std_error;
    // The error to kErrorDigits digits; `place`: the decimal exponent of its last digit.
    const std::string error_sci = printf_text("%.*e", kErrorDigits - 1, error);
    const int error_exponent = exponent_of(error_sci);
    const int place = error_exponent - (kErrorDigits - 1);
    // The value's decimal exponent (from 17 significant digits: not carried by rounding).
    const int value_exponent = exponent_of(printf_text("%.*e", 16, value));
    if (error_exponent >= kMinFixedExponent && std::abs(value) < kMaxFixed &&
        std::strtod(error_sci.c_str(), nullptr) < kMaxFixed) {
        const int decimals = place < 0 ? -place : 0;
        if (place <= 0)
            return without_negative_zero(printf_text("%.*f", decimals, value)) + " ± " +
                   printf_text("%.*f", decimals, error);
        // The error's last digit left of the decimal point: both rounded to 10^place first.
        const double rounded_error = std::strtod(error_sci.c_str(), nullptr);
        double rounded_value = 0.0;
        if (value_exponent >= place)
            rounded_value =
                std::strtod(printf_text("%.*e", value_exponent - place, value).c_str(), nullptr);
        else
            rounded_value = std::round(value / std::pow(10.0, place)) * std::pow(10.0, place);
        return without_negative_zero(printf_text("%.*f", 0, rounded_value)) + " ± " +
               printf_text("%.*f", 0, rounded_error);
    }
    // Scientific: the value's mantissa to the error's place (one decimal more when rounding
    // carried into the next power of ten: 9.99996e-07 ± 2.3e-10 → 1.0000e-06).
    if (value_exponent < place) return "0 ± " + error_sci;
    const int decimals = std::min(value_exponent - place, kMaxDecimals);
    std::string value_sci = printf_text("%.*e", decimals, value);
    if (exponent_of(value_sci) > value_exponent && decimals < kMaxDecimals)
        value_sci = printf_text("%.*e", decimals + 1, std::strtod(value_sci.c_str(), nullptr));
    return without_negative_zero(value_sci) + " ± " + error_sci;
}

}  // namespace roughscope
