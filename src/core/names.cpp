// The enum-name scheme of names.hpp.
#include "roughscope/core/names.hpp"

#include <cctype>

#include "roughscope/core/numbers.hpp"
#include "roughscope/core/text.hpp"

namespace roughscope {

std::string normalize_name(std::string_view name) {
    name = trim_space(name);
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
    throw InvalidArgument(std::string(what) + " " + quote_input(name) +
                          " is not recognised; valid values: " + std::string(valid));
}

}  // namespace roughscope
