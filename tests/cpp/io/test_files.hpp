// Scratch files for the io tests: a fresh directory per test and whole-file reads.
#pragma once

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <unistd.h>

namespace roughscope::testing {

// An empty directory under the system's temporary folder, unique to this process and `name`.
inline std::filesystem::path fresh_dir(const std::string& name) {
    std::string leaf("roughscope_io_");
    leaf.append(std::to_string(::getpid())).append("_").append(name);
    const std::filesystem::path d = std::filesystem::temp_directory_path() / leaf;
    std::filesystem::remove_all(d);
    std::filesystem::create_directories(d);
    return d;
}

// The whole content of a file (empty if it cannot be read).
inline std::string slurp(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

}  // namespace roughscope::testing
