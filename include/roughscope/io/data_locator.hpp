// Where the reference data beside the project are: the paper's printed tables
// (reference/paper-tables.json) and the CUReT database (data/curet). They are never part of the
// repository; they live in a folder `shared` next to it.
//
// The one rule, used by the CLI, the Python module, the tests and the benchmarks:
//  1. if the environment variable ROUGHSCOPE_SHARED_DIR is set (non-empty), it is the shared
//     folder, and nothing else is searched;
//  2. otherwise `../shared` is searched upward: for the current directory and each of its
//     parents D, D/../shared; then the same from each directory in `extra_starts` (the tests pass
//     their source tree here; the library itself knows no build-time path).
// The first candidate that holds the requested item wins.
//
// The rule for tests: a test needing these data SKIPS visibly when they are absent, unless the
// environment variable ROUGHSCOPE_REQUIRE_SHARED_DATA=1, in which case it FAILS
// (shared_data_required()).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace roughscope::io {

inline constexpr const char* kSharedDirEnv = "ROUGHSCOPE_SHARED_DIR";
inline constexpr const char* kRequireSharedDataEnv = "ROUGHSCOPE_REQUIRE_SHARED_DATA";
inline constexpr const char* kPaperTablesRelative = "reference/paper-tables.json";
inline constexpr const char* kCuretRelative = "data/curet";

// The shared folders to look in, in order (see the rule above); they need not exist.
std::vector<std::filesystem::path> shared_dir_candidates(
    const std::vector<std::filesystem::path>& extra_starts = {});

// `relative` (a file or a directory, e.g. "reference/paper-tables.json") in the first candidate
// shared folder that holds it, or std::nullopt.
std::optional<std::filesystem::path> find_shared(
    std::string_view relative, const std::vector<std::filesystem::path>& extra_starts = {});

// The paper's printed tables (a regular file), or std::nullopt.
std::optional<std::filesystem::path> paper_tables_path(
    const std::vector<std::filesystem::path>& extra_starts = {});

// The CUReT directory: the first data/curet holding table.txt and abrdf.dat, or std::nullopt.
std::optional<std::filesystem::path> curet_data_dir(
    const std::vector<std::filesystem::path>& extra_starts = {});

// One line saying where `relative` was looked for (for "not found" messages and test skips).
std::string shared_search_description(std::string_view relative);

// True when ROUGHSCOPE_REQUIRE_SHARED_DATA=1: missing shared data is then a test failure.
bool shared_data_required();

}  // namespace roughscope::io
