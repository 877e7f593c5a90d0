// ISO 25178-71 Surface Data File (SDF), binary (bISO-1.0) and ASCII (aISO-1.0)
// (docs/height-files.md, "SDF").
//
// Binary layout (little endian, 81-byte header): version char[8], ManufacID char[10],
// CreateDate char[12], ModDate char[12], NumPoints uint16, NumProfiles uint16, Xscale, Yscale,
// Zscale, Zresolution double, Compression, DataType, CheckType uint8; then NumPoints ×
// NumProfiles samples row by row; then an optional text trailer. ASCII: the same fields as
// `Key = value` lines after the version line, a `*` line, the samples as whitespace-separated
// numbers, a `*`, the trailer (`Key = value` lines). DataType: 0 uint8, 1 uint16, 2 uint32,
// 3 float, 4 int8, 5 int16, 6 int32, 7 double. Scales are metres (per point, per profile, per
// count); heights = Zscale × sample.
//
// Missing points: NaN (or ±inf) in float/double data; in integer data the type's marker value as
// Gwyddion reads it (uint16 65535, uint32 4294967295, int16 −32768, int32 −2147483648; none for
// 8-bit data). The writer stores doubles (µm, Zscale = 1e-6 m so that heights read back bit for
// bit) and NaN for missing points, and writes roughscope's own trailer keys dx_um, dy_um,
// x_offset_um, y_offset_um with the exact values (SDF has no offsets, and a spacing in metres may
// not convert back to the same µm double).
#include <bit>
#include <cctype>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/surface/formats.hpp"
#include "tab_common.hpp"

namespace roughscope::surface::formats {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr std::size_t kBinaryHeaderBytes = 8 + 10 + 12 + 12 + 2 + 2 + 4 * 8 + 3;
constexpr int kDataTypeCount = 8;
constexpr std::size_t kTypeBytes[kDataTypeCount] = {1, 2, 4, 4, 1, 2, 4, 8};
constexpr const char* kTypeNames[kDataTypeCount] = {"uint8", "uint16", "uint32", "float",
                                                    "int8",  "int16",  "int32",  "double"};
constexpr int kDouble = 7;

struct SdfHeader {
    std::size_t nx = 0, ny = 0;
    double xscale_m = 0, yscale_m = 0, zscale_m = 0;
    int compression = 0, data_type = 0, check_type = 0;
};

// Roughscope's exact values from the trailer.
struct Trailer {
    std::optional<double> dx_um, dy_um, x_offset_um, y_offset_um;
};

// The missing-point marker of an integer data type (as a double), if any.
std::optional<double> missing_marker(int data_type) {
    switch (data_type) {
        case 1:
            return 65535.0;
        case 2:
            return 4294967295.0;
        case 5:
            return -32768.0;
        case 6:
            return -2147483648.0;
        default:
            return std::nullopt;
    }
}

void check_header(const std::string& name, const SdfHeader& h, std::string_view where) {
    auto fail = [&](const std::string& what) {
        throw DataError(name + ": " + std::string(where) + ": " + what);
    };
    if (h.compression != 0) {
        fail("Compression = " + std::to_string(h.compression) + " is not supported (only 0)");
    }
    if (h.check_type != 0) {
        fail("CheckType = " + std::to_string(h.check_type) + " is not supported (only 0)");
    }
    if (h.data_type < 0 || h.data_type >= kDataTypeCount) {
        fail("DataType = " + std::to_string(h.data_type) +
             " is not one of 0 (uint8) to 7 (double)");
    }
    const std::pair<const char*, double> scales[] = {
        {"Xscale", h.xscale_m}, {"Yscale", h.yscale_m}, {"Zscale", h.zscale_m}};
    for (const auto& scale : scales) {
        if (!(std::isfinite(scale.second) && scale.second > 0.0)) {
            std::string what(scale.first);
            what.append(" = ")
                .append(format_message(scale.second))
                .append(" m must be finite and > 0");
            fail(what);
        }
    }
    tab::check_grid_size(name, h.nx, h.ny, where);
}

double metres_for(double um);

// The µm spacing a scale in metres means; the trailer's exact value when it agrees (to 1e-9, or
// the scale is exactly what the writer stores for it: subnormal scales lose digits).
double spacing_um(double scale_m, const std::optional<double>& exact_um) {
    const double um = scale_m * 1e6;
    if (exact_um && (std::abs(*exact_um - um) <= 1e-9 * um || metres_for(*exact_um) == scale_m)) {
        return *exact_um;
    }
    return um;
}

HeightMap assemble(const SdfHeader& h, const Trailer& t, std::vector<double> heights) {
    HeightMap map;
    map.nx = h.nx;
    map.ny = h.ny;
    map.dx_um = spacing_um(h.xscale_m, t.dx_um);
    map.dy_um = spacing_um(h.yscale_m, t.dy_um);
    map.x_offset_um = t.x_offset_um.value_or(0.0);
    map.y_offset_um = t.y_offset_um.value_or(0.0);
    map.heights_um = std::move(heights);
    return map;
}

struct TextLine {
    std::string_view text;
    std::size_t number;
};

// `Key = value` / `Key value`: the key (a letter, then letters, digits, '_') and the value.
bool split_key_value(std::string_view line, std::string_view& key, std::string_view& value) {
    const std::string_view t = trim_space(line);
    if (t.empty() || std::isalpha(static_cast<unsigned char>(t.front())) == 0) return false;
    std::size_t i = 0;
    while (i < t.size() && (std::isalnum(static_cast<unsigned char>(t[i])) != 0 || t[i] == '_')) {
        ++i;
    }
    if (i == 0) return false;
    key = t.substr(0, i);
    std::string_view rest = trim_space(t.substr(i));
    if (!rest.empty() && rest.front() == '=') rest = trim_space(rest.substr(1));
    value = rest;
    return true;
}

// Reads roughscope's keys from trailer lines; other lines are ignored.
// Errors name the line (ASCII files) or, when `binary_base` is set, the byte offset of the line.
void read_trailer(const std::string& name, std::string_view text, std::size_t first_line,
                  std::optional<std::size_t> binary_base, Trailer& trailer) {
    std::size_t number = first_line;
    std::size_t start = 0;
    while (start < text.size()) {
        std::size_t end = text.find('\n', start);
        if (end == std::string_view::npos) end = text.size();
        const std::string_view line = text.substr(start, end - start);
        std::string_view key, value;
        if (split_key_value(line, key, value)) {
            std::optional<double>* slot = nullptr;
            if (key == "dx_um") slot = &trailer.dx_um;
            if (key == "dy_um") slot = &trailer.dy_um;
            if (key == "x_offset_um") slot = &trailer.x_offset_um;
            if (key == "y_offset_um") slot = &trailer.y_offset_um;
            if (slot != nullptr) {
                std::string reason;
                const auto v = try_parse_number(value, reason);
                if (!v) {
                    std::string what = "trailer ";
                    what.append(key)
                        .append(": ")
                        .append(quote_input(value))
                        .append(" is ")
                        .append(reason);
                    if (binary_base) throw tab::error_at_offset(name, *binary_base + start, what);
                    throw tab::error_at(name, number, 0, what);
                }
                *slot = *v;
            }
        }
        ++number;
        start = end + 1;
    }
}

HeightMap decode_binary(std::string_view bytes, const std::string& name) {
    if (bytes.size() < kBinaryHeaderBytes) {
        throw tab::error_at_offset(name, bytes.size(),
                                   "the binary SDF header needs " +
                                       std::to_string(kBinaryHeaderBytes) +
                                       " bytes, the file has " + std::to_string(bytes.size()));
    }
    const char* p = bytes.data();
    SdfHeader h;
    h.nx = tab::load<std::uint16_t>(p + 42, false);
    h.ny = tab::load<std::uint16_t>(p + 44, false);
    h.xscale_m = tab::load<double>(p + 46, false);
    h.yscale_m = tab::load<double>(p + 54, false);
    h.zscale_m = tab::load<double>(p + 62, false);
    h.compression = static_cast<unsigned char>(p[78]);
    h.data_type = static_cast<unsigned char>(p[79]);
    h.check_type = static_cast<unsigned char>(p[80]);
    check_header(name, h, "header");
    const std::size_t n = h.nx * h.ny;
    const std::size_t size = kTypeBytes[h.data_type];
    const std::size_t available = bytes.size() - kBinaryHeaderBytes;
    if (available / size < n) {
        std::string what = "the data holds ";
        what.append(std::to_string(available))
            .append(" bytes; NumPoints x NumProfiles x ")
            .append(std::to_string(size))
            .append(" (")
            .append(kTypeNames[h.data_type])
            .append(") = ")
            .append(std::to_string(n))
            .append(" x ")
            .append(std::to_string(size))
            .append(" = ")
            .append(std::to_string(n * size))
            .append(" bytes are needed (truncated file?)");
        throw tab::error_at_offset(name, kBinaryHeaderBytes, what);
    }
    Trailer trailer;
    const std::size_t trailer_at = kBinaryHeaderBytes + n * size;
    read_trailer(name, bytes.substr(trailer_at), 1, trailer_at, trailer);

    const double factor = h.zscale_m * 1e6;  // µm per count (exactly 1 for Zscale = 1e-6)
    std::vector<double> heights(n);
    const char* data = p + kBinaryHeaderBytes;
    const auto marker = missing_marker(h.data_type);
    auto convert = [&](auto tag) {
        using T = decltype(tag);
        for (std::size_t i = 0; i < n; ++i) {
            const double v = static_cast<double>(tab::load<T>(data + i * sizeof(T), false));
            heights[i] = (marker && v == *marker) || std::isinf(v) ? kNaN : v * factor;
        }
    };
    switch (h.data_type) {
        case 0:
            convert(std::uint8_t{});
            break;
        case 1:
            convert(std::uint16_t{});
            break;
        case 2:
            convert(std::uint32_t{});
            break;
        case 3:
            convert(float{});
            break;
        case 4:
            convert(std::int8_t{});
            break;
        case 5:
            convert(std::int16_t{});
            break;
        case 6:
            convert(std::int32_t{});
            break;
        default:
            if (factor == 1.0 && std::endian::native == std::endian::little) {
                // Bit for bit; tab::finish turns infinities into NaN.
                std::memcpy(heights.data(), data, n * sizeof(double));
            } else {
                convert(double{});
            }
            break;
    }
    return assemble(h, trailer, std::move(heights));
}

// The lines of a text file with their numbers (from 1), split at '\n'.
std::vector<TextLine> split_lines(std::string_view bytes) {
    std::vector<TextLine> lines;
    std::size_t start = 0;
    std::size_t number = 1;
    while (start < bytes.size()) {
        std::size_t end = bytes.find('\n', start);
        if (end == std::string_view::npos) end = bytes.size();
        lines.push_back({bytes.substr(start, end - start), number++});
        start = end + 1;
    }
    return lines;
}

// The header of a text SDF: line 1 is the version; then Key = value lines up to a `*` line. `li`
// ends at the line after the `*`, `star_line` is the `*` line's number; every required key must
// be there and the header valid (check_header).
SdfHeader read_text_header(const std::vector<TextLine>& lines, const std::string& name,
                           std::size_t& li, std::size_t& star_line) {
    SdfHeader h;
    bool have[6] = {};  // NumPoints, NumProfiles, Xscale, Yscale, Zscale, DataType
    li = 1;
    star_line = 0;
    for (; li < lines.size(); ++li) {
        const TextLine& line = lines[li];
        const std::string_view t = trim_space(line.text);
        if (t.empty() || t.front() == ';') continue;
        if (t.front() == '*') {
            star_line = line.number;
            ++li;
            break;
        }
        std::string_view key, value;
        if (!split_key_value(t, key, value)) {
            throw tab::error_at(
                name, line.number, 0,
                "expected a header line 'Key = value' or the '*' that ends the header");
        }
        const std::size_t column =
            value.empty() ? 0 : static_cast<std::size_t>(value.data() - line.text.data()) + 1;
        auto integer = [&](long long lo, long long hi) {
            std::string reason;
            const auto v = try_parse_integer(value, lo, hi, reason);
            if (!v) {
                std::string what(key);
                what.append(": ").append(quote_input(value)).append(" is ").append(reason);
                throw tab::error_at(name, line.number, column, what);
            }
            return *v;
        };
        auto number = [&]() {
            std::string reason;
            const auto v = try_parse_number(value, reason);
            if (!v) {
                std::string what(key);
                what.append(": ").append(quote_input(value)).append(" is ").append(reason);
                throw tab::error_at(name, line.number, column, what);
            }
            return *v;
        };
        const long long max_points = static_cast<long long>(kMaxHeightMapPoints);
        if (tab::same_key(key, "NumPoints")) {
            h.nx = static_cast<std::size_t>(integer(1, max_points));
            have[0] = true;
        } else if (tab::same_key(key, "NumProfiles")) {
            h.ny = static_cast<std::size_t>(integer(1, max_points));
            have[1] = true;
        } else if (tab::same_key(key, "Xscale")) {
            h.xscale_m = number();
            have[2] = true;
        } else if (tab::same_key(key, "Yscale")) {
            h.yscale_m = number();
            have[3] = true;
        } else if (tab::same_key(key, "Zscale")) {
            h.zscale_m = number();
            have[4] = true;
        } else if (tab::same_key(key, "DataType")) {
            h.data_type = static_cast<int>(integer(0, 255));
            have[5] = true;
        } else if (tab::same_key(key, "Compression")) {
            h.compression = static_cast<int>(integer(0, 255));
        } else if (tab::same_key(key, "CheckType")) {
            h.check_type = static_cast<int>(integer(0, 255));
        }
    }
    if (star_line == 0) {
        throw DataError(name + ": the header has no '*' line (the end of the header)");
    }
    constexpr const char* kRequired[6] = {"NumPoints", "NumProfiles", "Xscale",
                                          "Yscale",    "Zscale",      "DataType"};
    for (int k = 0; k < 6; ++k) {
        if (!have[k]) {
            std::string what = "the header (ending at the '*') has no ";
            what.append(kRequired[k]).append(" line");
            throw tab::error_at(name, star_line, 0, what);
        }
    }
    check_header(name, h, "header");
    return h;
}

// The `n` values of a text SDF from line `li` on, up to the closing `*` (the trailer starts on
// `trailer_line`, 0 without one), in µm (× Zscale · 1e6; the data type's missing-point marker and
// NaN as missing points). `li` ends after the line of the `*`.
std::vector<double> read_text_values(const std::vector<TextLine>& lines, const std::string& name,
                                     const SdfHeader& h, std::size_t n, std::size_t& li,
                                     std::size_t& trailer_line) {
    std::vector<double> heights;
    heights.reserve(n);
    const auto marker = missing_marker(h.data_type);
    const double factor = h.zscale_m * 1e6;
    trailer_line = 0;
    for (; li < lines.size() && trailer_line == 0; ++li) {
        const TextLine& line = lines[li];
        std::size_t i = 0;
        const std::string_view t = line.text;
        while (i < t.size()) {
            while (i < t.size() && std::isspace(static_cast<unsigned char>(t[i])) != 0) ++i;
            if (i >= t.size()) break;
            const std::size_t start = i;
            while (i < t.size() && std::isspace(static_cast<unsigned char>(t[i])) == 0) ++i;
            const std::string_view token = t.substr(start, i - start);
            if (token.front() == '*') {
                trailer_line = line.number + 1;
                break;
            }
            if (heights.size() == n) {
                std::string what = "more than NumPoints x NumProfiles = ";
                what.append(std::to_string(n)).append(" values before the closing '*'");
                throw tab::error_at(name, line.number, start + 1, what);
            }
            if (tab::is_nan_text(token)) {
                heights.push_back(kNaN);
                continue;
            }
            std::string reason;
            const auto v = try_parse_number(token, reason);
            if (!v) {
                std::string what = "value ";
                what.append(std::to_string(heights.size() + 1))
                    .append(": ")
                    .append(quote_input(token))
                    .append(" is ")
                    .append(reason);
                throw tab::error_at(name, line.number, start + 1, what);
            }
            heights.push_back(marker && *v == *marker ? kNaN : *v * factor);
        }
    }
    if (heights.size() != n) {
        std::string what = "the data holds ";
        what.append(std::to_string(heights.size()))
            .append(" values; NumPoints x NumProfiles = ")
            .append(std::to_string(n))
            .append(" are needed (truncated file?)");
        const std::size_t at = lines.empty() ? 1 : lines.back().number;
        throw tab::error_at(name, at, 0, what);
    }
    return heights;
}

HeightMap decode_text(std::string_view bytes, const std::string& name) {
    const std::vector<TextLine> lines = split_lines(bytes);
    std::size_t li = 1;
    std::size_t star_line = 0;
    const SdfHeader h = read_text_header(lines, name, li, star_line);
    const std::size_t n = h.nx * h.ny;
    // Every value takes at least one character and one separator: bound the allocation by the
    // file before making it.
    const std::size_t data_start =
        li < lines.size() ? static_cast<std::size_t>(lines[li].text.data() - bytes.data())
                          : bytes.size();
    if (n - 1 > (bytes.size() - data_start) / 2) {
        std::string what = "NumPoints x NumProfiles = ";
        what.append(std::to_string(n))
            .append(" values cannot fit in the ")
            .append(std::to_string(bytes.size() - data_start))
            .append(" bytes after the header (truncated file?)");
        throw tab::error_at(name, star_line, 0, what);
    }

    std::size_t trailer_line = 0;
    std::vector<double> heights = read_text_values(lines, name, h, n, li, trailer_line);
    Trailer trailer;
    if (trailer_line != 0 && li < lines.size()) {
        const std::size_t from = static_cast<std::size_t>(lines[li].text.data() - bytes.data());
        read_trailer(name, bytes.substr(from), lines[li].number, std::nullopt, trailer);
    }
    return assemble(h, trailer, std::move(heights));
}

// A scale in metres that reads back (× 1e6) as exactly `um` when one is within a few ulps.
double metres_for(double um) {
    const double first = um / 1e6;
    double down = first;
    double up = first;
    for (int k = 0; k < 4; ++k) {
        if (down * 1e6 == um) return down;
        if (up * 1e6 == um) return up;
        down = std::nextafter(down, 0.0);
        up = std::nextafter(up, std::numeric_limits<double>::infinity());
    }
    return first;
}

std::string trailer_text(const HeightMap& map) {
    std::string out = "*\n";
    out.append("dx_um = ").append(format_roundtrip(map.dx_um, "dx_um")).append("\n");
    out.append("dy_um = ").append(format_roundtrip(map.dy_um, "dy_um")).append("\n");
    out.append("x_offset_um = ")
        .append(format_roundtrip(map.x_offset_um, "x_offset_um"))
        .append("\n");
    out.append("y_offset_um = ")
        .append(format_roundtrip(map.y_offset_um, "y_offset_um"))
        .append("\n");
    out.append("*\n");
    return out;
}

}  // namespace

HeightMap decode_sdf(std::string_view bytes, const std::string& name, const HeightReadOptions&) {
    if (bytes.empty()) throw tab::error_at_offset(name, 0, "empty file (not an SDF file)");
    // ASCII SDF is text: a UTF-8 byte-order mark before its "aISO-1.0" is skipped.
    if (bytes.starts_with("\xEF\xBB\xBF"
                          "a"))
        return tab::finish(decode_text(bytes.substr(3), name), name);
    if (bytes.front() == 'b') return tab::finish(decode_binary(bytes, name), name);
    if (bytes.front() == 'a') return tab::finish(decode_text(bytes, name), name);
    throw tab::error_at_offset(
        name, 0,
        "not an SDF file: it must start with 'b' (binary, bISO-1.0) or 'a' (ASCII, aISO-1.0)");
}

std::string encode_sdf(const HeightMap& map, const HeightWriteOptions& options) {
    const double xscale = metres_for(map.dx_um);
    const double yscale = metres_for(map.dy_um);
    const double zscale = 1e-6;
    std::string out;
    if (options.sdf_binary) {
        if (map.nx > 65535 || map.ny > 65535) {
            throw InvalidArgument(
                "sdf: binary SDF holds at most 65535 points per profile and "
                "65535 profiles (got " +
                std::to_string(map.nx) + " x " + std::to_string(map.ny) +
                "); write ASCII SDF (sdf_binary = false) or another format");
        }
        out.reserve(kBinaryHeaderBytes + map.size() * 8 + 128);
        out.append("bISO-1.0");
        out.append("roughscope");    // ManufacID, 10 characters
        out.append("010119700000");  // CreateDate DDMMYYYYhhmm: fixed, the output is reproducible
        out.append("010119700000");  // ModDate
        tab::store_le(out, static_cast<std::uint16_t>(map.nx));
        tab::store_le(out, static_cast<std::uint16_t>(map.ny));
        tab::store_le(out, xscale);
        tab::store_le(out, yscale);
        tab::store_le(out, zscale);
        tab::store_le(out, zscale);  // Zresolution: not known; the scale
        out.push_back(0);            // Compression
        out.push_back(static_cast<char>(kDouble));
        out.push_back(0);  // CheckType
        for (const double z : map.heights_um) tab::store_le(out, z);
        out.append(trailer_text(map));
        return out;
    }
    out.append("aISO-1.0\n");
    out.append("ManufacID   = roughscope\n");
    out.append("CreateDate  = 010119700000\n");
    out.append("ModDate     = 010119700000\n");
    out.append("NumPoints   = ").append(std::to_string(map.nx)).append("\n");
    out.append("NumProfiles = ").append(std::to_string(map.ny)).append("\n");
    out.append("Xscale      = ").append(format_roundtrip(xscale)).append("\n");
    out.append("Yscale      = ").append(format_roundtrip(yscale)).append("\n");
    out.append("Zscale      = ").append(format_roundtrip(zscale)).append("\n");
    out.append("Zresolution = ").append(format_roundtrip(zscale)).append("\n");
    out.append("Compression = 0\n");
    out.append("DataType    = 7\n");
    out.append("CheckType   = 0\n");
    out.append("*\n");
    for (std::size_t iy = 0; iy < map.ny; ++iy) {
        for (std::size_t ix = 0; ix < map.nx; ++ix) {
            if (ix > 0) out.push_back(' ');
            const double z = map.at(ix, iy);
            out.append(std::isnan(z) ? std::string("NaN") : format_roundtrip(z, "height"));
        }
        out.push_back('\n');
    }
    out.append(trailer_text(map));
    return out;
}

}  // namespace roughscope::surface::formats
