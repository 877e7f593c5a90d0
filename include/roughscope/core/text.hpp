// Small text helpers shared by the library and the front ends.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace roughscope {

// The items separated by `sep` ("a, b, c" for sep = ", "); empty for no items.
inline std::string join(const std::vector<std::string>& items, std::string_view sep) {
    std::string out;
    for (std::size_t i = 0; i < items.size(); ++i) {
        if (i) out += sep;
        out += items[i];
    }
    return out;
}

}  // namespace roughscope
