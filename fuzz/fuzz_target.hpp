// What every fuzz target (fuzz/*.cpp) shares.
//
// Each target feeds its input bytes to one of the library's readers. A roughscope::Error (or a
// subclass: InvalidArgument, NoSolution, DataError) is the reader's documented answer to bad
// input and is ignored; any other exception escapes LLVMFuzzerTestOneInput and terminates the
// process, and a crash, an assertion or a sanitizer report is a bug as well.
//
// The same sources are linked either with libFuzzer (-fsanitize=fuzzer, clang,
// -DROUGHSCOPE_BUILD_FUZZERS=ON) or with replay_main.cpp, which runs every file of the given
// directories once (the ctest entries fuzz_replay_<target>).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "roughscope/core/errors.hpp"

// The libFuzzer entry point each target defines.
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace roughscope::fuzz {

// The input as text (any bytes, NUL included).
inline std::string_view as_text(const std::uint8_t* data, std::size_t size) {
    return {reinterpret_cast<const char*>(data), size};
}

// Runs `body`; a roughscope::Error is the expected answer to malformed input and is swallowed.
template <class Body>
void expect_only_roughscope_errors(Body&& body) {
    try {
        body();
    } catch (const roughscope::Error&) {
        // Documented rejection of bad input: fine.
    }
}

}  // namespace roughscope::fuzz
