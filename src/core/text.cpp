// Printable, bounded text for messages (text.hpp).
#include "roughscope/core/text.hpp"

#include <algorithm>
#include <cstdio>
#include <string>

namespace roughscope {
namespace {

void append_hex(std::string& out, unsigned char byte) {
    char buf[8];
    std::snprintf(buf, sizeof buf, "\\x%02x", static_cast<unsigned>(byte));
    out += buf;
}

// Length of the valid UTF-8 sequence starting at text[k] (1..4), or 0 if it is not one.
std::size_t utf8_length(std::string_view text, std::size_t k) {
    const auto byte = [&](std::size_t i) { return static_cast<unsigned char>(text[i]); };
    const unsigned char b0 = byte(k);
    std::size_t len = 0;
    unsigned lo = 0x80, hi = 0xBF;  // allowed range of the second byte
    if (b0 >= 0xC2 && b0 <= 0xDF) {
        len = 2;
    } else if (b0 >= 0xE0 && b0 <= 0xEF) {
        len = 3;
        if (b0 == 0xE0) lo = 0xA0;  // no overlong forms
        if (b0 == 0xED) hi = 0x9F;  // no surrogates
    } else if (b0 >= 0xF0 && b0 <= 0xF4) {
        len = 4;
        if (b0 == 0xF0) lo = 0x90;
        if (b0 == 0xF4) hi = 0x8F;  // <= U+10FFFF
    } else {
        return 0;
    }
    if (k + len > text.size()) return 0;
    if (byte(k + 1) < lo || byte(k + 1) > hi) return 0;
    for (std::size_t i = 2; i < len; ++i)
        if (byte(k + i) < 0x80 || byte(k + i) > 0xBF) return 0;
    return len;
}

// Where to cut `text` at most max_bytes in without splitting a UTF-8 sequence.
std::size_t cut_point(std::string_view text, std::size_t max_bytes) {
    std::size_t k = 0;
    while (k < text.size()) {
        const std::size_t len = std::max<std::size_t>(1, utf8_length(text, k));
        if (k + len > max_bytes) break;
        k += len;
    }
    return k;
}

std::string bytes_in_all(std::size_t size) {
    return " (" + std::to_string(size) + " bytes in all)";
}

}  // namespace

std::string printable_text(std::string_view text) {
    std::string out;
    out.reserve(text.size());
    for (std::size_t k = 0; k < text.size();) {
        const auto c = static_cast<unsigned char>(text[k]);
        if (c < 0x80) {
            if (c == '\t')
                out += "\\t";
            else if (c == '\n')
                out += "\\n";
            else if (c == '\r')
                out += "\\r";
            else if (c < 0x20 || c == 0x7F)
                append_hex(out, c);
            else
                out += static_cast<char>(c);
            ++k;
            continue;
        }
        const std::size_t len = utf8_length(text, k);
        if (len == 0) {  // not UTF-8: the byte itself
            append_hex(out, c);
            ++k;
        } else if (len == 2 && c == 0xC2 && static_cast<unsigned char>(text[k + 1]) < 0xA0) {
            char buf[8];  // C1 control character U+0080..U+009F
            std::snprintf(buf, sizeof buf, "\\u%04x",
                          static_cast<unsigned>(static_cast<unsigned char>(text[k + 1])));
            out += buf;
            k += 2;
        } else {
            out.append(text.substr(k, len));
            k += len;
        }
    }
    return out;
}

std::string quote_input(std::string_view text, std::size_t max_bytes) {
    std::string out = "'";
    if (text.size() <= max_bytes) {
        out += printable_text(text);
        out += '\'';
        return out;
    }
    out += printable_text(text.substr(0, cut_point(text, max_bytes)));
    out += "\xE2\x80\xA6'";  // …
    out += bytes_in_all(text.size());
    return out;
}

std::string printable_message(std::string_view message, std::size_t max_bytes) {
    if (message.size() <= max_bytes) return printable_text(message);
    std::string out = printable_text(message.substr(0, cut_point(message, max_bytes)));
    out += "\xE2\x80\xA6";  // …
    out += bytes_in_all(message.size());
    return out;
}

}  // namespace roughscope
