// Reading an options object (serialize/*.cpp only): typed look-ups that name the key on error.
#pragma once

#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>

#include "roughscope/core/errors.hpp"
#include "roughscope/serialize/json.hpp"

namespace roughscope::serialize::detail {

// Throws InvalidArgument if `options` is not an object (or null) or has a key not in `known`.
void check_keys(const Json& options, std::string_view what,
                std::initializer_list<std::string_view> known);

// The value at `key`, or nullopt when absent or null; InvalidArgument for a wrong type.
std::optional<double> get_number(const Json& options, const char* key);
std::optional<int> get_int(const Json& options, const char* key);
std::optional<bool> get_bool(const Json& options, const char* key);
std::optional<std::string> get_string(const Json& options, const char* key);
// A pair [a, b] of numbers.
std::optional<std::pair<double, double>> get_number_pair(const Json& options, const char* key);
std::optional<std::pair<int, int>> get_int_pair(const Json& options, const char* key);

}  // namespace roughscope::serialize::detail
