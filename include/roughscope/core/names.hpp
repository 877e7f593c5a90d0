// Internal: enum <-> name tables for the front ends ("vh", "gaussian", ...).
#pragma once

#include <cctype>
#include <string>
#include <string_view>

#include "roughscope/core/errors.hpp"

namespace roughscope {

template <class E>
struct NameEntry {
    std::string_view name;
    E value;
};

template <class Table, class E>
std::string_view name_of(const Table& table, E value) {
    for (const auto& entry : table)
        if (entry.value == value) return entry.name;
    return "unknown";
}

// Accepts the table's names; '-' and '_' are interchangeable and case is ignored.
template <class Table>
auto parse_name(const Table& table, std::string_view what, std::string_view name) {
    std::string norm;
    for (char c : name) norm += c == '-' ? '_' : static_cast<char>(std::tolower(c));
    std::string valid;
    for (const auto& entry : table) {
        if (entry.name == norm) return entry.value;
        if (!valid.empty()) valid += ", ";
        valid += entry.name;
    }
    throw InvalidArgument(std::string(what) + " '" + std::string(name) +
                          "' is not recognised; valid values: " + valid);
}

}  // namespace roughscope
