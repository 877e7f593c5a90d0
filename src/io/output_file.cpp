// Atomic output files (output_file.hpp).
#include "roughscope/io/output_file.hpp"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <iostream>
#include <random>
#include <system_error>

#include <unistd.h>

#include "roughscope/core/errors.hpp"

namespace roughscope::io {

void write_file_atomic(const std::filesystem::path& path, const std::string& content) {
    namespace fs = std::filesystem;
    const auto fail = [&](const std::string& reason) -> void {
        throw DataError("cannot write " + path.string() + ": " + reason);
    };
    if (path.empty()) fail("empty file name");
    if (path.filename().empty()) fail("not a file name");
    std::error_code ec;
    if (fs::is_directory(path, ec)) fail("is a directory");
    const fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
    if (!fs::is_directory(dir, ec)) fail("directory " + dir.string() + " does not exist");

    std::random_device rd;
    // Built with append (GCC 12 warns falsely on "." + std::string&&, -Wrestrict).
    std::string tmp_name(1, '.');
    tmp_name.append(path.filename().string())
        .append(".tmp-")
        .append(std::to_string(::getpid()))
        .append("-")
        .append(std::to_string(rd()));
    const fs::path tmp = dir / tmp_name;
    {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        if (!out) fail(std::strerror(errno));
        out.write(content.data(), static_cast<std::streamsize>(content.size()));
        out.flush();
        if (!out) {
            const std::string reason = std::strerror(errno);
            out.close();
            fs::remove(tmp, ec);
            fail(reason);
        }
        out.close();
        if (out.fail()) {
            fs::remove(tmp, ec);
            fail("error while closing the file");
        }
    }
    fs::rename(tmp, path, ec);
    if (ec) {
        std::error_code ignored;
        fs::remove(tmp, ignored);
        fail(ec.message());
    }
}

void write_output(const std::optional<std::filesystem::path>& path, const std::string& content) {
    if (path) {
        write_file_atomic(*path, content);
    } else {
        std::cout << content;
        std::cout.flush();
        if (!std::cout) throw DataError("cannot write to standard output");
    }
}

}  // namespace roughscope::io
