// Enum <-> name tables: the one naming scheme of every enum the front ends read or print
// ("vh", "gaussian", "very_rough", ...).
//
// A table is a constexpr array of NameEntry; the FIRST entry of a value is its canonical name
// (what to_string returns), later entries of the same value are aliases. Canonical names are
// lower case with '_' between words. Parsing is case-insensitive, ignores surrounding spaces and
// treats '-' and '_' alike everywhere ("Very-Rough" == "very_rough"); an unknown name throws
// InvalidArgument "<what> '<name>' is not recognised; valid values: <every name of the table>".
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "roughscope/core/errors.hpp"

namespace roughscope {

template <class E>
struct NameEntry {
    std::string_view name;
    E value;
};

// `name` trimmed of spaces, lower-cased, '-' replaced by '_'.
std::string normalize_name(std::string_view name);

// True if `input` names `canonical` under the scheme above (canonical is already normalised).
bool name_matches(std::string_view canonical, std::string_view input);

// Throws InvalidArgument "<what> '<name>' is not recognised; valid values: <valid>".
[[noreturn]] void throw_unknown_name(std::string_view what, std::string_view name,
                                     std::string_view valid);

// Canonical name of `value`; "unknown" if the table lacks it (a bug: asserted in debug builds).
template <class E, std::size_t N>
std::string_view name_of(const std::array<NameEntry<E>, N>& table, E value) {
    for (const auto& entry : table)
        if (entry.value == value) return entry.name;
    return "unknown";
}

// The value named `name` (canonical name or alias); throws as described above.
template <class E, std::size_t N>
E parse_name(const std::array<NameEntry<E>, N>& table, std::string_view what,
             std::string_view name) {
    const std::string norm = normalize_name(name);
    std::string valid;
    for (const auto& entry : table) {
        if (entry.name == norm) return entry.value;
        if (!valid.empty()) valid += ", ";
        valid += entry.name;
    }
    throw_unknown_name(what, name, valid);
}

// Canonical names in table order, aliases left out.
template <class E, std::size_t N>
std::vector<std::string> canonical_names(const std::array<NameEntry<E>, N>& table) {
    std::vector<std::string> out;
    for (std::size_t k = 0; k < N; ++k) {
        bool alias = false;
        for (std::size_t j = 0; j < k; ++j) alias = alias || table[j].value == table[k].value;
        if (!alias) out.emplace_back(table[k].name);
    }
    return out;
}

}  // namespace roughscope
