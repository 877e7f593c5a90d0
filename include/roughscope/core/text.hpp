// Small text helpers shared by the library and the front ends, and the one rule for putting text
// that came from an input (a file, a flag, a Python string) into a message.
//
// Messages are shown on a terminal, written to logs and turned into Python strings, so the text
// they quote is made printable and short:
//  * printable_text: control characters (C0, DEL, C1) become escapes ("\x1b", "\x00", "\t",
//    "\n", "\r", "\u009b") and bytes that are not valid UTF-8 become "\xNN"; valid UTF-8 (µm, θ)
//    is kept. A backslash is kept as it is, so escaping twice changes nothing.
//  * quote_input: printable_text in single quotes, cut after kQuoteMaxBytes bytes of the input
//    with "…' (N bytes in all)" after the quote.
//  * printable_message: printable_text of a whole message, cut after kMessageMaxBytes bytes with
//    "… (N bytes in all)". Every roughscope::Error passes its message through it (errors.hpp), so
//    no library message can hold a raw control character or invalid UTF-8, or be longer.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace roughscope {

// The items separated by `sep` ("a, b, c" for sep = ", "); empty for no items.
inline std::string join(const std::vector<std::string>& items, std::string_view sep) {
    std::string out;
    for (std::size_t i = 0; i < items.size(); ++i) {
        if (i) out += sep;
        out += items[i];
    }
    return out;
}

// The parts (strings, string views, literals, chars) joined into one string by appending: the
// one way to build a message from pieces (GCC 12 warns falsely with -Wrestrict on
// "literal" + std::string).
template <class... Parts>
std::string concat(const Parts&... parts) {
    std::string out;
    ((out += parts), ...);
    return out;
}

// Longest input quoted by quote_input (bytes of the original text, before escaping).
inline constexpr std::size_t kQuoteMaxBytes = 64;
// Longest message kept by printable_message (bytes of the original message).
inline constexpr std::size_t kMessageMaxBytes = 4096;

// `text` with control characters and invalid UTF-8 escaped (see above).
std::string printable_text(std::string_view text);

// "'<printable text>'", or "'<first max_bytes bytes>…' (N bytes in all)" for a longer text (the
// cut never splits a UTF-8 sequence).
std::string quote_input(std::string_view text, std::size_t max_bytes = kQuoteMaxBytes);

// printable_text of the first max_bytes bytes of `message`, then "… (N bytes in all)" when cut.
std::string printable_message(std::string_view message, std::size_t max_bytes = kMessageMaxBytes);

}  // namespace roughscope
