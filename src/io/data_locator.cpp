// The reference-data locator (data_locator.hpp).
#include "roughscope/io/data_locator.hpp"

#include <algorithm>
#include <cstdlib>
#include <system_error>

namespace roughscope::io {
namespace fs = std::filesystem;
namespace {

std::optional<fs::path> env_path(const char* name) {
    const char* value = std::getenv(name);
    if (value == nullptr || *value == '\0') return std::nullopt;
    return fs::path(value);
}

void add_upward(const fs::path& start, std::vector<fs::path>& out) {
    std::error_code ec;
    fs::path dir = fs::absolute(start, ec);
    if (ec) return;
    dir = dir.lexically_normal();
    if (!dir.has_filename() && dir.has_parent_path() && dir != dir.root_path())
        dir = dir.parent_path();  // "a/b/" -> "a/b"
    while (true) {
        const fs::path candidate = (dir.parent_path() / "shared").lexically_normal();
        if (std::find(out.begin(), out.end(), candidate) == out.end()) out.push_back(candidate);
        if (dir == dir.root_path() || !dir.has_relative_path()) break;
        dir = dir.parent_path();
    }
}

bool holds_curet(const fs::path& dir) {
    std::error_code ec;
    return fs::is_regular_file(dir / "table.txt", ec) && fs::is_regular_file(dir / "abrdf.dat", ec);
}

}  // namespace

std::vector<fs::path> shared_dir_candidates(const std::vector<fs::path>& extra_starts) {
    if (auto env = env_path(kSharedDirEnv)) return {*env};
    std::vector<fs::path> out;
    std::error_code ec;
    const fs::path cwd = fs::current_path(ec);
    if (!ec) add_upward(cwd, out);
    for (const fs::path& start : extra_starts) add_upward(start, out);
    return out;
}

std::optional<fs::path> find_shared(std::string_view relative,
                                    const std::vector<fs::path>& extra_starts) {
    for (const fs::path& dir : shared_dir_candidates(extra_starts)) {
        std::error_code ec;
        const fs::path p = dir / fs::path(relative);
        if (fs::exists(p, ec)) return p;
    }
    return std::nullopt;
}

std::optional<fs::path> paper_tables_path(const std::vector<fs::path>& extra_starts) {
    for (const fs::path& dir : shared_dir_candidates(extra_starts)) {
        std::error_code ec;
        const fs::path p = dir / kPaperTablesRelative;
        if (fs::is_regular_file(p, ec)) return p;
    }
    return std::nullopt;
}

std::optional<fs::path> curet_data_dir(const std::vector<fs::path>& extra_starts) {
    for (const fs::path& dir : shared_dir_candidates(extra_starts)) {
        const fs::path p = dir / kCuretRelative;
        if (holds_curet(p)) return p;
    }
    return std::nullopt;
}

std::string shared_search_description(std::string_view relative) {
    if (auto env = env_path(kSharedDirEnv))
        return std::string(kSharedDirEnv) + "/" + std::string(relative) + " (" +
               (*env / fs::path(relative)).string() + ")";
    return "../shared/" + std::string(relative) + " from the current directory upward (or set " +
           kSharedDirEnv + ")";
}

bool shared_data_required() {
    const char* value = std::getenv(kRequireSharedDataEnv);
    return value != nullptr && std::string_view(value) == "1";
}

}  // namespace roughscope::io
