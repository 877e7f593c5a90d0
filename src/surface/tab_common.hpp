// Helpers shared by the table, SDF, image and raw height-file readers (format_table.cpp,
// format_sdf.cpp, format_image.cpp, format_raw.cpp): messages that name the file and the place,
// the final check of a decoded map, option checks, byte-order access and length units.
#pragma once

#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/surface/formats.hpp"
#include "roughscope/surface/height_map.hpp"

namespace roughscope::surface::tab {

// "name:line:column: what" (line and column 1-based; column 0 = the whole line).
inline DataError error_at(const std::string& name, std::size_t line, std::size_t column,
                          std::string_view what) {
    std::string message = name;
    message.append(":").append(std::to_string(line));
    if (column > 0) message.append(":").append(std::to_string(column));
    message.append(": ").append(what);
    return DataError(message);
}

// "name: byte offset N: what".
inline DataError error_at_offset(const std::string& name, std::size_t offset,
                                 std::string_view what) {
    std::string message = name;
    message.append(": byte offset ").append(std::to_string(offset)).append(": ").append(what);
    return DataError(message);
}

// The last step of every reader: infinities become NaN (missing), then validate(); a broken
// invariant of a map read from a file is a DataError naming the file.
inline HeightMap finish(HeightMap map, const std::string& name) {
    for (double& z : map.heights_um) {
        if (std::isinf(z)) z = std::nan("");
    }
    try {
        validate(map, name);
    } catch (const InvalidArgument& e) {
        throw DataError(e.what());
    }
    return map;
}

// Throws DataError unless nx, ny >= 1 and nx·ny <= kMaxHeightMapPoints (checked before any
// allocation, so a corrupt header cannot ask for terabytes).
inline void check_grid_size(const std::string& name, std::size_t nx, std::size_t ny,
                            std::string_view where) {
    if (nx < 1 || ny < 1 || nx > kMaxHeightMapPoints / ny) {
        std::string message = name;
        message.append(": ")
            .append(where)
            .append(": a grid of ")
            .append(std::to_string(nx))
            .append(" x ")
            .append(std::to_string(ny))
            .append(" points is outside 1 to ")
            .append(std::to_string(kMaxHeightMapPoints))
            .append(" points");
        throw DataError(message);
    }
}

// An optional spacing/scale option: nullopt stays nullopt; a given value must be finite and > 0.
inline std::optional<double> positive_option(const std::optional<double>& value,
                                             std::string_view option, std::string_view unit) {
    if (value) check::positive(option, *value, unit);
    return value;
}

// dx_um/dy_um for formats without spacings (PNG, TIFF, CSV matrix without a header): the options,
// dy defaulting to dx, both to 1 µm; `assumed` is set when a default was used.
struct Spacings {
    double dx_um = 1.0;
    double dy_um = 1.0;
    bool assumed = false;
};
inline Spacings spacings_from(const HeightReadOptions& options) {
    const auto dx = positive_option(options.dx_um, "dx_um", " um");
    const auto dy = positive_option(options.dy_um, "dy_um", " um");
    Spacings s;
    s.assumed = !dx && !dy;
    s.dx_um = dx ? *dx : (dy ? *dy : 1.0);
    s.dy_um = dy ? *dy : s.dx_um;
    return s;
}

// Length units of numbers in text files. Values are converted with the exact operation that is
// correctly rounded for the decimal intent: µm as is, nm divided by 1000, mm multiplied by 1000,
// m multiplied by 1e6.
enum class LengthUnit { um, nm, mm, m };

inline std::optional<LengthUnit> parse_length_unit(std::string_view text) {
    const std::string_view t = trim_space(text);
    if (t == "um" || t == "µm" || t == "\xB5m" || t == "micrometre" || t == "micrometer" ||
        t == "micron") {
        return LengthUnit::um;
    }
    if (t == "nm") return LengthUnit::nm;
    if (t == "mm") return LengthUnit::mm;
    if (t == "m") return LengthUnit::m;
    return std::nullopt;
}

inline double to_um(double value, LengthUnit unit) {
    switch (unit) {
        case LengthUnit::um:
            return value;
        case LengthUnit::nm:
            return value / 1000.0;
        case LengthUnit::mm:
            return value * 1000.0;
        case LengthUnit::m:
            return value * 1e6;
    }
    return value;
}

// The length unit option (InvalidArgument naming it for anything else); nullopt when not given.
inline std::optional<LengthUnit> unit_option(const HeightReadOptions& options) {
    if (!options.length_unit) return std::nullopt;
    if (auto unit = parse_length_unit(*options.length_unit)) return unit;
    throw InvalidArgument("length_unit: " + quote_input(*options.length_unit) +
                          " is not one of m, mm, um, nm");
}

// Little/big-endian access to unaligned bytes.
template <class T>
T load(const char* p, bool big_endian) {
    static_assert(sizeof(T) == 1 || sizeof(T) == 2 || sizeof(T) == 4 || sizeof(T) == 8);
    unsigned char b[sizeof(T)];
    std::memcpy(b, p, sizeof(T));
    if (big_endian != (std::endian::native == std::endian::big)) {
        for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
    }
    T value;
    std::memcpy(&value, b, sizeof(T));
    return value;
}

template <class T>
void store_le(std::string& out, T value) {
    unsigned char b[sizeof(T)];
    std::memcpy(b, &value, sizeof(T));
    if constexpr (std::endian::native == std::endian::big) {
        for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
    }
    out.append(reinterpret_cast<const char*>(b), sizeof(T));
}

// Case-insensitive ASCII comparison of keys.
inline bool same_key(std::string_view a, std::string_view b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i) {
        const auto lower = [](char c) {
            return (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c;
        };
        if (lower(a[i]) != lower(b[i])) return false;
    }
    return true;
}

// "nan" in any case: the spelling of a missing point in text files.
inline bool is_nan_text(std::string_view text) { return same_key(trim_space(text), "nan"); }

// Count of a height in an integer image: heights = z_scale_um × count; the writers refuse what
// does not fit (names the point and the range).
inline std::uint32_t count_for(double z_um, double z_scale_um, std::uint32_t max_count,
                               std::size_t index, std::string_view format) {
    if (std::isnan(z_um)) {
        std::string message(format);
        message.append(": point ")
            .append(std::to_string(index))
            .append(
                " is missing (NaN), and integer samples have no missing-point value; fill "
                "or crop the missing points, or write a float format");
        throw InvalidArgument(message);
    }
    const double count = std::nearbyint(z_um / z_scale_um);
    if (!(count >= 0.0 && count <= static_cast<double>(max_count))) {
        std::string message(format);
        message.append(": height ")
            .append(format_message(z_um))
            .append(" um at point ")
            .append(std::to_string(index))
            .append(" is ")
            .append(format_message(z_um / z_scale_um))
            .append(" counts of z_scale_um = ")
            .append(format_message(z_scale_um))
            .append(", outside 0 to ")
            .append(std::to_string(max_count))
            .append(" (level the map so its minimum is >= 0, or choose a larger z_scale_um)");
        throw InvalidArgument(message);
    }
    return static_cast<std::uint32_t>(count);
}

// A height as a float32 sample; refuses finite values outside float's range (they would read
// back as infinities, i.e. missing points). NaN stays NaN.
inline float float_sample(double z_um, std::size_t index, std::string_view format) {
    const auto f = static_cast<float>(z_um);
    if (std::isfinite(z_um) && !std::isfinite(f)) {
        std::string message(format);
        message.append(": height ")
            .append(format_message(z_um))
            .append(" um at point ")
            .append(std::to_string(index))
            .append(" is outside the range of float32 samples (magnitude < 3.4e38)");
        throw InvalidArgument(message);
    }
    return f;
}

}  // namespace roughscope::surface::tab
