// Text helpers shared by the x3p reader and writer (format_x3p.cpp, format_x3p_write.cpp).
// Internal to the surface topic.
#pragma once

#include <string>
#include <string_view>

namespace roughscope::surface::formats::x3p {

// The MD5 of `data` as 32 lowercase hexadecimal digits (OpenSSL's EVP MD5).
std::string md5_hex(std::string_view data);

// `um` (µm) as decimal metres that the reader reads back exactly: the shortest round-trip digits
// of the µm value with the exponent lowered by 6 ("1.5e-6" for 1.5 µm).
std::string um_to_metres_text(double um);

}  // namespace roughscope::surface::formats::x3p
