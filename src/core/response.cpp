#include "roughscope/core/response.hpp"

#include <array>
#include <cmath>

#include "roughscope/core/names.hpp"

namespace roughscope {
namespace {

constexpr std::array<NameEntry<Response>, 3> kResponseNames{{
    {"linear", Response::Linear},
    {"srgb", Response::Srgb},
    {"gamma", Response::Gamma},
}};

}  // namespace

std::string_view to_string(Response response) { return name_of(kResponseNames, response); }

Response parse_response(std::string_view name) {
    return parse_name(kResponseNames, "response", name);
}

// IEC 61966-2-1: v = 12.92 u for u ≤ 0.0031308, else 1.055 u^(1/2.4) − 0.055.
double srgb_encode(double linear) {
    if (linear <= 0.0031308) return 12.92 * linear;
    return 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
}

// IEC 61966-2-1 inverse: u = v / 12.92 for v ≤ 0.04045, else ((v + 0.055)/1.055)^2.4.
double srgb_decode(double encoded) {
    if (encoded <= 0.04045) return encoded / 12.92;
    return std::pow((encoded + 0.055) / 1.055, 2.4);
}

}  // namespace roughscope
