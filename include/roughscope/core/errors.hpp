// Typed errors of the public API (the "invalid input" tier of DEVELOPERS.md).
//
// Every exception message names the offending input, its value and the valid range, so that a
// front end can show it to the user verbatim. The message is made printable and bounded on the
// way in (core/text.hpp: control characters and invalid UTF-8 escaped, at most kMessageMaxBytes
// kept), so a value read from a file can never reach a terminal raw, cut a C string at a NUL
// byte, or make a Python exception without a message. The CLI turns any roughscope::Error into a
// one-line message and a non-zero exit status; the Python module raises ValueError subclasses.
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>

namespace roughscope {

// Base of every error the library throws on purpose.
class Error : public std::runtime_error {
  public:
    explicit Error(std::string_view message);
};

// An argument is outside its valid range, NaN, or inconsistent with another argument.
class InvalidArgument : public Error {
  public:
    using Error::Error;
};

// The inputs are valid one by one but the equation being inverted has no solution for them
// (e.g. a brightness ratio outside the range a model can produce). The message gives the range
// of inputs that would have a solution.
class NoSolution : public Error {
  public:
    using Error::Error;
};

// A file or table is malformed or missing (the message names the file and, when known, the line).
class DataError : public Error {
  public:
    using Error::Error;
};

namespace check {

// Throws InvalidArgument unless `value` is finite.
void finite(std::string_view name, double value);

// Throws InvalidArgument unless `value` is finite and > 0. `unit` is appended to the message.
void positive(std::string_view name, double value, std::string_view unit = "");

// Throws InvalidArgument unless `value` is finite and >= 0.
void non_negative(std::string_view name, double value, std::string_view unit = "");

// Throws InvalidArgument unless 0 <= theta_rad < pi/2. The message shows degrees.
void polar_angle(std::string_view name, double theta_rad);

// Throws InvalidArgument unless `value` is finite (azimuths may be any real number; they are
// wrapped by the functions that use them).
void azimuth(std::string_view name, double phi_rad);

// Formats a double for messages: format_message of numbers.hpp (shortest round-trip form, so that
// a value is never shown equal to the limit it breaks; "nan"/"inf" spelled out).
std::string format_number(double value);

}  // namespace check
}  // namespace roughscope
