// Headerless float32/float64 height files (docs/height-files.md, "Raw"): nx × ny samples in µm,
// row-major, little or big endian; the file says nothing else, so nx, ny and dx_um come from the
// options (dy_um defaults to dx_um). NaN or ±inf samples are missing points.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "roughscope/core/errors.hpp"
#include "roughscope/surface/formats.hpp"
#include "tab_common.hpp"

namespace roughscope::surface::formats {

namespace {

void require(bool given, const char* option, const std::string& name) {
    if (!given) {
        std::string message = name;
        message.append(": raw height files carry no header; give ")
            .append(option)
            .append(" (nx, ny >= 1 points, dx_um > 0 um)");
        throw InvalidArgument(message);
    }
}

}  // namespace

HeightMap decode_raw(std::string_view bytes, const std::string& name,
                     const HeightReadOptions& options) {
    require(options.nx.has_value(), "nx", name);
    require(options.ny.has_value(), "ny", name);
    require(options.dx_um.has_value(), "dx_um", name);
    const std::size_t nx = *options.nx;
    const std::size_t ny = *options.ny;
    if (nx < 1 || ny < 1 || nx > kMaxHeightMapPoints / ny) {
        throw InvalidArgument("nx x ny = " + std::to_string(nx) + " x " + std::to_string(ny) +
                              " must be 1 to " + std::to_string(kMaxHeightMapPoints) +
                              " points with nx, ny >= 1");
    }
    const tab::Spacings spacings = tab::spacings_from(options);
    const bool f32 = options.raw_type == RawSampleType::Float32;
    const std::size_t size = f32 ? 4 : 8;
    const std::size_t n = nx * ny;
    if (bytes.size() != n * size) {
        std::string what = "the file holds ";
        what.append(std::to_string(bytes.size()))
            .append(" bytes; nx x ny x ")
            .append(std::to_string(size))
            .append(f32 ? " (float32) = " : " (float64) = ")
            .append(std::to_string(nx))
            .append(" x ")
            .append(std::to_string(ny))
            .append(" x ")
            .append(std::to_string(size))
            .append(" = ")
            .append(std::to_string(n * size))
            .append(" bytes are expected");
        throw tab::error_at_offset(name, std::min(bytes.size(), n * size), what);
    }
    HeightMap map;
    map.nx = nx;
    map.ny = ny;
    map.dx_um = spacings.dx_um;
    map.dy_um = spacings.dy_um;
    map.heights_um.resize(n);
    const char* p = bytes.data();
    const bool big = options.raw_big_endian;
    if (!f32 && big == (std::endian::native == std::endian::big)) {
        std::memcpy(map.heights_um.data(), p, n * 8);
    } else {
        for (std::size_t i = 0; i < n; ++i) {
            map.heights_um[i] = f32 ? static_cast<double>(tab::load<float>(p + i * 4, big))
                                    : tab::load<double>(p + i * 8, big);
        }
    }
    return tab::finish(std::move(map), name);
}

std::string encode_raw(const HeightMap& map, const HeightWriteOptions& options) {
    std::string out;
    if (options.raw_type == RawSampleType::Float32) {
        out.reserve(map.size() * 4);
        for (std::size_t i = 0; i < map.size(); ++i) {
            tab::store_le(out, tab::float_sample(map.heights_um[i], i, "raw float32"));
        }
    } else {
        out.reserve(map.size() * 8);
        for (const double z : map.heights_um) tab::store_le(out, z);
    }
    return out;
}

}  // namespace roughscope::surface::formats
