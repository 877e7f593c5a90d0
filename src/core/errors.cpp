#include "roughscope/core/errors.hpp"

#include <cmath>
#include <numbers>

#include "roughscope/core/numbers.hpp"
#include "roughscope/core/text.hpp"

namespace roughscope {

Error::Error(std::string_view message) : std::runtime_error(printable_message(message)) {}

}  // namespace roughscope

namespace roughscope::check {

std::string format_number(double value) { return format_message(value); }

namespace {
std::string with_unit(double value, std::string_view unit) {
    std::string s = format_number(value);
    if (!unit.empty()) {
        s += ' ';
        s += unit;
    }
    return s;
}
}  // namespace

void finite(std::string_view name, double value) {
    if (!std::isfinite(value))
        throw InvalidArgument(std::string(name) + " = " + format_number(value) +
                              " is not a finite number");
}

void positive(std::string_view name, double value, std::string_view unit) {
    if (!(std::isfinite(value) && value > 0.0))
        throw InvalidArgument(std::string(name) + " = " + with_unit(value, unit) +
                              " is invalid: it must be a finite number > 0");
}

void non_negative(std::string_view name, double value, std::string_view unit) {
    if (!(std::isfinite(value) && value >= 0.0))
        throw InvalidArgument(std::string(name) + " = " + with_unit(value, unit) +
                              " is invalid: it must be a finite number >= 0");
}

void polar_angle(std::string_view name, double theta_rad) {
    if (!(std::isfinite(theta_rad) && theta_rad >= 0.0 && theta_rad < std::numbers::pi / 2)) {
        const double deg = theta_rad * 180.0 / std::numbers::pi;
        throw InvalidArgument(std::string(name) + " = " + format_number(deg) +
                              " deg is outside the valid range [0, 90) deg");
    }
}

void azimuth(std::string_view name, double phi_rad) {
    if (!std::isfinite(phi_rad))
        throw InvalidArgument(std::string(name) + " = " + format_number(phi_rad) +
                              " is not a finite angle");
}

}  // namespace roughscope::check
