// The tests' rule for reference data beside the project (io/data_locator.hpp): a test that needs
// a file of ../shared skips visibly when it is absent, or FAILS when
// ROUGHSCOPE_REQUIRE_SHARED_DATA=1.
#pragma once

#include <filesystem>
#include <optional>
#include <vector>

#include <gtest/gtest.h>

#include "roughscope/io/data_locator.hpp"

namespace roughscope::testing {

// Where the tests look besides the current directory: the source tree (compile-time path, for
// tests only).
inline std::vector<std::filesystem::path> shared_search_starts() {
    return {std::filesystem::path(ROUGHSCOPE_SOURCE_DIR)};
}

inline std::optional<std::filesystem::path> paper_tables() {
    return io::paper_tables_path(shared_search_starts());
}

inline std::optional<std::filesystem::path> curet_dir() {
    return io::curet_data_dir(shared_search_starts());
}

}  // namespace roughscope::testing

// Skips (or fails, under ROUGHSCOPE_REQUIRE_SHARED_DATA=1) the current test when `found` (a
// std::optional<path>) is empty; `relative` names what was looked for.
#define ROUGHSCOPE_NEED_SHARED(found, relative)                                            \
    if (!(found)) {                                                                        \
        if (::roughscope::io::shared_data_required())                                      \
            GTEST_FAIL() << "shared data required (ROUGHSCOPE_REQUIRE_SHARED_DATA=1) but " \
                         << ::roughscope::io::shared_search_description(relative)          \
                         << " was not found";                                              \
        else                                                                               \
            GTEST_SKIP() << "shared data not found: "                                      \
                         << ::roughscope::io::shared_search_description(relative)          \
                         << " (not part of the repository)";                               \
    }
