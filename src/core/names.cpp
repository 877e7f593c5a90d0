// The enum-name scheme of names.hpp.
#include "roughscope/core/names.hpp"

#include <cctype>

namespace roughscope {

std::string normalize_name(std::string_view name) {
    constexpr std::string_view kSpace = " \t\r\n\v\f";
    const auto first = name.find_first_not_of(kSpace);
    if (first == std::string_view::npos) return {};
    name = name.substr(first, name.find_last_not_of(kSpace) - first + 1);
    std::string out;
    out.reserve(name.size());
    for (const char c : name)
        out += c == '-' ? '_' : static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return out;
}

bool name_matches(std::string_view canonical, std::string_view input) {
    return normalize_name(input) == canonical;
}

void throw_unknown_name(std::string_view what, std::string_view name, std::string_view valid) {
    throw InvalidArgument(std::string(what) + " '" + std::string(name) +
                          "' is not recognised; valid values: " + std::string(valid));
}

}  // namespace roughscope
