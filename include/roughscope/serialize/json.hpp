// The JSON building blocks of roughscope's output (topic `serialize`).
//
// Every result type has ONE JSON schema, built here as an nlohmann::ordered_json VALUE (keys keep
// the order in which they are inserted). The command line prints these values and the Python
// module converts them to dicts and lists; neither re-derives a key. Conventions:
//  * Unknown or undefined quantities (std::nullopt, NaN, ±inf) are null, never NaN.
//  * Numbers are not rounded: dump() writes each double with the shortest text that parses back
//    to the same double (round-trip precision), laid out by write_number().
//  * Angles are degrees (`_deg`), lengths micrometres (`_um`), as at every front end.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace roughscope::serialize {

using Json = nlohmann::ordered_json;

// A finite double as a JSON number, anything else (NaN, ±inf) as null.
Json number(double value);
// std::nullopt as null, else number(*value).
Json number(const std::optional<double>& value);
// An angle given in radians, as degrees: the shortest decimal (up to 17 digits) whose conversion
// back to radians (deg_to_rad) gives exactly `radians`, so an angle entered as 30° is echoed as
// 30, not 29.999999999999996, and nothing is lost. null if not finite.
Json degrees(double radians);
// degrees(radians) of an angle converted from `given_degrees` (deg_to_rad(given_degrees) is
// `radians` bit for bit; otherwise this is degrees(radians)): the same value, found without the
// search when given_degrees has at most 13 significant digits. The decimals that convert to the
// same radians are then within a few ulps (relative ~1e-15) of it: its own digits are the
// shortest among them (two decimals of at most 13 digits are at least 1e-13 of the value apart)
// and rounding degrees(radians)'s candidate to as many digits gives them back.
Json degrees(double radians, double given_degrees);
// A list of doubles (each through number()).
Json numbers(const std::vector<double>& values);
// An empty string as null (an absent reason or name), else the string.
Json text_or_null(const std::string& text);

// The key that names the roughscope version which produced a document ("0.2.0", the project's
// one version number, CMakeLists.txt).
inline constexpr const char* kVersionKey = "roughscope_version";

// A document as the command line writes it: an object gets kVersionKey as its first key (an array
// gets it in each object element); any other value is returned unchanged.
Json versioned(Json document);

// The document as text: 2-space indentation and a trailing newline (indent < 0: one line).
// Laid out as nlohmann's dump(indent) lays it out (": " and ",\n" inside an indented document,
// ":" and "," on one line, empty arrays and objects as [] and {}), strings escaped by nlohmann
// (invalid UTF-8 replaced by U+FFFD), every double through write_number().
std::string dump(const Json& value, int indent = 2);

// The one JSON number formatter, of dump() and of every writer that must give dump()'s bytes
// (the streamed `model --csv --json`). A finite double gets its shortest round-trip digits
// (std::to_chars: the fewest significant digits that parse back to the same double, the closest
// of them when several qualify) in nlohmann's layout: with the decimal point n digits after the
// first digit, 1234.5, 1200.0 (an integral value keeps ".0") and 0.00012 for -4 < n <= 15, else
// 1.2345e+16, 1e-05 (at least two exponent digits); 0.0 and -0.0 for zeros. NaN and ±inf are
// written as null. `out` needs room for kNumberBufferSize characters; returns the end.
inline constexpr std::size_t kNumberBufferSize = 32;
char* write_number(char* out, double value);

}  // namespace roughscope::serialize
