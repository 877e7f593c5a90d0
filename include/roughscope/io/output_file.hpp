// Writing outputs without leaving half-written files behind (DEVELOPERS.md: "nothing written
// half-way").
#pragma once

#include <filesystem>
#include <optional>
#include <string>

namespace roughscope::io {

// Writes `content` to `path` atomically: a temporary file in the same directory is written,
// flushed and renamed over `path`. On any failure the temporary file is removed, `path` is left
// untouched, and DataError("cannot write <path>: <reason>") is thrown.
void write_file_atomic(const std::filesystem::path& path, const std::string& content);

// Writes `content` to `path` atomically when given, else to standard output (DataError "cannot
// write to standard output" if that fails).
void write_output(const std::optional<std::filesystem::path>& path, const std::string& content);

}  // namespace roughscope::io
