// Numbers at the text boundary: the library's one strict parser and one formatter family.
//
// Parsing (files, command-line values, CSV cells): std::from_chars on the WHOLE text; surrounding
// spaces/tabs (and CR/LF) are allowed, a leading '+' is allowed; anything else after the number
// ("1.5x"), hexadecimal, "nan", "inf" and values outside the double range are rejected, with a
// reason that can be shown to the user.
//
// Formatting (three members, one per use):
//  * format_roundtrip   — shortest text that reads back to the same double (files, JSON-like
//                         output); refuses NaN/infinity (results are never printed as NaN);
//  * format_significant — fixed number of significant digits ("%.*g") for human-readable text;
//                         refuses NaN/infinity too;
//  * format_message     — error messages: shortest round-trip form, or fixed significant
//                         digits when asked, but never rounded to a shorter, rounder number
//                         that is not the value ("kappa = 1.00000001 must exceed 1", not
//                         "kappa = 1 must exceed 1"); "nan", "inf" and "-inf" spelled out (the
//                         value being reported may be the bad one).
//
// Integers (counts, sample and measurement numbers given as text): try_parse_integer, the same
// rules as numbers (decimal digits only, optional sign, surrounding spaces allowed; no "0x19",
// no "25.0", no exponent).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace roughscope {

// `text` without leading and trailing spaces, tabs, CR, LF, VT, FF (what the parser ignores; the
// one trim of the library's text readers).
std::string_view trim_space(std::string_view text);

// Parses the whole of `text` as a finite double. Returns std::nullopt and sets `reason` ("empty
// (a number is required)", "not a number", "not a finite number (NaN is not accepted)", "out of
// the range of double-precision numbers", ...) otherwise.
std::optional<double> try_parse_number(std::string_view text, std::string& reason);

// As try_parse_number but throws InvalidArgument "<what>: '<text>' is <reason>" (text trimmed,
// quoted by quote_input of core/text.hpp).
double parse_number(std::string_view text, std::string_view what);

// Parses the whole of `text` as a decimal integer in [lo, hi] (surrounding spaces/tabs allowed, a
// leading '+' or '-' allowed; no hexadecimal, no fraction, no exponent). Returns std::nullopt and
// sets `reason` ("not an integer", "out of the range [lo, hi]", ...) otherwise.
std::optional<long long> try_parse_integer(std::string_view text, long long lo, long long hi,
                                           std::string& reason);

// As try_parse_integer but throws InvalidArgument "<what>: '<text>' is <reason>".
long long parse_integer(std::string_view text, long long lo, long long hi, std::string_view what);

// Parses "a,b,c" into exactly `count` finite numbers; throws InvalidArgument naming `what` (and
// the item, 1-based, for a bad number).
std::vector<double> parse_number_list(std::string_view text, std::size_t count,
                                      std::string_view what);

// Shortest round-trip text of a finite value ("0.1", "1e-07", "-0" kept as "-0"). Throws
// roughscope::Error naming `name` for NaN or infinity.
std::string format_roundtrip(double value, std::string_view name = "value");

// `digits` significant digits ("%.*g", 1 <= digits <= 17), "-0" printed as "0". Throws
// roughscope::Error naming `name` for NaN or infinity.
std::string format_significant(double value, int digits, std::string_view name = "value");

// Writes the "%.*g" text of a finite `value` (1 <= digits <= 17, C locale, "-0" kept: the bytes
// std::snprintf writes) at `out`, which must have room for kSignificantBufferSize characters;
// returns the end. Digits <= 15 of a normal number come from one scaling by an exact power of
// ten rounded to an integer when that is provably the correct rounding (not near a tie, the
// power within 10^±22), else from the shortest round-trip digits (which are the correctly rounded
// ones at that precision, rounded once more unless they end on an exact tie); everything else
// from std::to_chars with a precision.
inline constexpr std::size_t kSignificantBufferSize = 32;
char* write_significant(char* out, double value, int digits);

// The double that write_significant's text reads as (strtod of "%.*g"), for a finite `value`
// and 1 <= digits <= 17; found without the text when it can be exactly (the rounded digits
// m·10^q of exact operands, |q| <= 22, in one correctly rounded operation).
double parse_significant(double value, int digits);

// write_significant at several precisions of one value: its digits are found once — rounded to
// 12 digits by one exact scaling where write_significant's fast path applies, else the shortest
// round-trip digits — and each write() rounds them (same bytes as write_significant).
// The shortest round-trip decimal digits of a finite |value| > 0 (normal or subnormal): the
// fewest significant digits that parse back to the same double, the closest of them when several
// qualify — std::to_chars's digits. digits[0 .. count) with digits[0] != '0' and no trailing
// zero; value = ±d1.d2d3… × 10^exponent. A cheap exact path serves values that some decimal of at
// most 15 digits reads back as (it is then the only one: two such decimals are at least 10^-15 of
// the value apart, more than the 2^-52 interval of reals that read as one normal double).
struct ShortestDigits {
    char digits[24] = {};
    int count = 0;
    int exponent = 0;
};
ShortestDigits shortest_digits(double value);

class SignificantDigits {
  public:
    explicit SignificantDigits(double value);
    char* write(char* out, int digits) const;
    // parse_significant(value, digits), from the digits found once.
    double parsed(int digits) const;
    // False when rounding to `digits` (<= 13) moves the value by at least a tenth of a unit in
    // the last kept place (the dropped digits start with 1..8): relative 1e-14 or more.
    bool rounding_may_stay_close(int digits) const;

  private:
    friend char* write_significant(char* out, double value, int digits);
    struct Shortest {};
    static constexpr int kScaledDigits = 12;
    SignificantDigits(double value, Shortest);  // the shortest round-trip digits

    double value_;
    int precise_up_to_ = 15;   // the precisions the digits give (more: found again)
    bool decomposed_ = false;  // false: every precision through the exact path
    bool negative_ = false;
    int count_ = 0;  // digits in digits_
    int exponent_ = 0;
    char digits_[24] = {};
};

// For error messages only: the shortest round-trip form, or `digits` significant digits when
// digits > 0 — unless the rounded text has fewer significant digits than `digits` and differs
// from the value by more than floating-point noise (relative 1e-14): 1.00000001 at 7 digits is
// "1.00000001", not "1", while 29.999999999999996 is "30". "nan", "inf", "-inf" spelled out.
std::string format_message(double value, int digits = 0);

// `value` rounded to `digits` significant digits (the value format_significant prints). NaN,
// infinity and zero are returned unchanged.
double round_significant(double value, int digits);

}  // namespace roughscope
