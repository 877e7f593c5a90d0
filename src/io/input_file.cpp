// Input files are regular files (io/input_file.hpp; docs/input-files.md).
#include "roughscope/io/input_file.hpp"

#include <string>
#include <system_error>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"

namespace roughscope::io {

namespace {

// What a special file is, in words; empty for a regular file, a directory or no file.
std::string_view special_kind(const std::filesystem::file_status& status) {
    namespace fs = std::filesystem;
    switch (status.type()) {
        case fs::file_type::character:
            return "character device";
        case fs::file_type::block:
            return "block device";
        case fs::file_type::fifo:
            return "FIFO (named pipe)";
        case fs::file_type::socket:
            return "socket";
        case fs::file_type::unknown:
            return "special file";
        default:
            return {};
    }
}

}  // namespace

void check_input_file(const std::filesystem::path& path, std::string_view name, bool allow_fifo) {
    std::error_code ec;
    const std::filesystem::file_status status = std::filesystem::status(path, ec);
    if (ec) return;  // no such file, or not reachable: the caller's open reports it
    if (allow_fifo && status.type() == std::filesystem::file_type::fifo) return;
    const std::string_view kind = special_kind(status);
    if (kind.empty()) return;
    throw DataError(concat(name, ": is a ", kind,
                           ", not a regular file: inputs are read from regular files only (a "
                           "device or pipe could be read without end); save the data to a file "
                           "first"));
}

void check_input_size(const std::filesystem::path& path, std::string_view name,
                      std::uintmax_t max_bytes, std::string_view what) {
    std::error_code ec;
    const std::uintmax_t size = std::filesystem::file_size(path, ec);
    if (ec || size <= max_bytes) return;
    throw DataError(concat(name, ": ", std::to_string(size), " bytes, larger than the limit of ",
                           std::to_string(max_bytes), " bytes for ", what));
}

}  // namespace roughscope::io
