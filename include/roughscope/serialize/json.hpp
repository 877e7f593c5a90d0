// The JSON building blocks of roughscope's output (topic `serialize`).
//
// Every result type has ONE JSON schema, built here as an nlohmann::ordered_json VALUE (keys keep
// the order in which they are inserted). The command line prints these values and the Python
// module converts them to dicts and lists; neither re-derives a key. Conventions:
//  * Unknown or undefined quantities (std::nullopt, NaN, ±inf) are null, never NaN.
//  * Numbers are not rounded: dump() writes each double with the shortest text that parses back
//    to the same double (round-trip precision).
//  * Angles are degrees (`_deg`), lengths micrometres (`_um`), as at every front end.
#pragma once

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
std::string dump(const Json& value, int indent = 2);

}  // namespace roughscope::serialize
