// Input files are regular files (docs/input-files.md, "Regular files only"): every reader checks
// its path with check_input_file before opening it, so that a device (/dev/zero, /dev/urandom),
// a FIFO or a socket named as an image, a mask, a height file, a CSV table or a capture file is
// refused by name instead of being read without end (or, for a FIFO with no writer, waited on
// for ever: the check looks at the file's type without opening it).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string_view>

namespace roughscope::io {

// Throws DataError "<name>: is a <kind>, not a regular file: ..." when `path` exists (symlinks
// followed) and is a character or block device, a FIFO, a socket or of another special kind.
// A missing path and a directory are left to the caller's own message (each reader says what it
// expected). `name` is how the caller names the file in its messages.
// With `allow_fifo`, a FIFO passes (a reader that takes a pipe reads it up to a stated cap,
// e.g. height files up to the memory budget); devices and sockets are still refused.
void check_input_file(const std::filesystem::path& path, std::string_view name,
                      bool allow_fifo = false);

// Throws DataError "<name>: <size> bytes, larger than the limit of <limit> for <what>" when the
// regular file `path` is larger than `max_bytes`, checked before it is read.
void check_input_size(const std::filesystem::path& path, std::string_view name,
                      std::uintmax_t max_bytes, std::string_view what);

}  // namespace roughscope::io
