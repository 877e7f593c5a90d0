// Camera tone responses: how a stored code value relates to the light that reached the pixel.
// Shared by the synthetic captures (simulation/capture.hpp, which applies a response) and the
// image reader (image/read.hpp, which inverts it).
//   Linear: code ∝ light (RAW, linear 16-bit files, float TIFF).
//   Srgb:   IEC 61966-2-1 sRGB encoding (most JPEGs and 8-bit PNGs).
//   Gamma:  code = white · light^(1/γ) (γ given).
#pragma once

#include <string_view>

namespace roughscope {

enum class Response { Linear, Srgb, Gamma };
std::string_view to_string(Response response);  // "linear", "srgb", "gamma"
Response parse_response(std::string_view name);

// IEC 61966-2-1 sRGB transfer: encode u ∈ [0, 1] (linear) → v, decode v → u.
double srgb_encode(double linear);
double srgb_decode(double encoded);

}  // namespace roughscope
