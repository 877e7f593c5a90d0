// JSON building blocks (serialize/json.hpp).
#include "roughscope/serialize/json.hpp"

#include <cmath>

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

std::string dump(const Json& value, int indent) {
    // error_handler::replace: invalid UTF-8 in a name read from a file cannot abort the output.
    return value.dump(indent, ' ', false, Json::error_handler_t::replace) + "\n";
}

}  // namespace roughscope::serialize
