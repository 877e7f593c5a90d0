#include "roughscope/surface/height_map.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <string>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/scattering/beckmann.hpp"

namespace roughscope::surface {

std::size_t HeightMap::count_valid() const {
    return static_cast<std::size_t>(std::count_if(heights_um.begin(), heights_um.end(),
                                                  [](double z) { return !std::isnan(z); }));
}

std::vector<std::uint8_t> HeightMap::mask() const {
    std::vector<std::uint8_t> out(heights_um.size());
    std::transform(heights_um.begin(), heights_um.end(), out.begin(),
                   [](double z) { return static_cast<std::uint8_t>(!std::isnan(z)); });
    return out;
}

namespace {

void check_dimensions(const std::string& what, std::size_t nx, std::size_t ny) {
    if (nx < 1 || ny < 1 || nx > kMaxHeightMapPoints / ny) {
        std::string message = what;
        message.append(": the grid must have 1 to ")
            .append(std::to_string(kMaxHeightMapPoints))
            .append(" points with nx, ny >= 1 (got nx = ")
            .append(std::to_string(nx))
            .append(", ny = ")
            .append(std::to_string(ny))
            .append(")");
        throw InvalidArgument(message);
    }
}

void check_spacing(const std::string& what, const char* name, double value_um) {
    if (!(value_um >= kMinLengthUm && value_um <= kMaxLengthUm)) {
        std::string message = what;
        message.append(": ")
            .append(name)
            .append(" must be a spacing in [")
            .append(format_message(kMinLengthUm))
            .append(", ")
            .append(format_message(kMaxLengthUm))
            .append("] um (got ")
            .append(format_message(value_um))
            .append(")");
        throw InvalidArgument(message);
    }
}

}  // namespace

HeightMap make_height_map(std::size_t nx, std::size_t ny, double dx_um, double dy_um) {
    check_dimensions("height map", nx, ny);
    check_spacing("height map", "dx_um", dx_um);
    check_spacing("height map", "dy_um", dy_um);
    HeightMap map;
    map.nx = nx;
    map.ny = ny;
    map.dx_um = dx_um;
    map.dy_um = dy_um;
    map.heights_um.assign(nx * ny, 0.0);
    return map;
}

void validate(const HeightMap& map, const std::string& what, const HeightsScan& heights) {
    check_dimensions(what, map.nx, map.ny);
    check_spacing(what, "dx_um", map.dx_um);
    check_spacing(what, "dy_um", map.dy_um);
    if (!(std::abs(map.x_offset_um) <= kMaxLengthUm && std::abs(map.y_offset_um) <= kMaxLengthUm)) {
        std::string message = what;
        message.append(": the grid offsets must lie within +-")
            .append(format_message(kMaxLengthUm))
            .append(" um");
        throw InvalidArgument(message);
    }
    if (map.heights_um.size() != map.nx * map.ny) {
        std::string message = what;
        message.append(": ")
            .append(std::to_string(map.heights_um.size()))
            .append(" heights for a grid of ")
            .append(std::to_string(map.nx))
            .append(" x ")
            .append(std::to_string(map.ny))
            .append(" points");
        throw InvalidArgument(message);
    }
    if (heights.first_out_of_range < map.heights_um.size()) {
        std::string message = what;
        message.append(": heights must be NaN (missing) or within +-")
            .append(format_message(kMaxLengthUm))
            .append(" um (got ")
            .append(format_message(map.heights_um[heights.first_out_of_range]))
            .append(")");
        throw InvalidArgument(message);
    }
    if (!heights.any_valid)
        throw InvalidArgument(what + ": every point is missing (no valid height)");
}

void validate(const HeightMap& map, const std::string& what) {
    validate(map, what, scan_heights(map.heights_um.data(), map.heights_um.size()));
}

HeightsScan scan_heights(const double* z, std::size_t n) {
    // Blocks of 1024 counted branch-free (double counts of compares: a loop the compiler
    // vectorises with SSE2); only a block with a height out of range is searched for it. NaN
    // compares false: missing, never out of range; ±inf is out of range.
    constexpr std::size_t kBlock = 1024;
    HeightsScan scan{n, false};
    for (std::size_t start = 0; start < n; start += kBlock) {
        const std::size_t end = std::min(n, start + kBlock);
        double out_of_range = 0.0;
        double valid = 0.0;
        for (std::size_t i = start; i < end; ++i) {
            const double a = std::abs(z[i]);
            out_of_range += a > kMaxLengthUm ? 1.0 : 0.0;
            valid += a == a ? 1.0 : 0.0;  // not NaN
        }
        scan.any_valid = scan.any_valid || valid > 0.0;
        if (out_of_range > 0.0) {
            for (std::size_t i = start; i < end; ++i)
                if (std::abs(z[i]) > kMaxLengthUm) {
                    scan.first_out_of_range = i;
                    return scan;
                }
        }
    }
    return scan;
}

bool bitwise_equal(const HeightMap& a, const HeightMap& b) {
    auto same = [](double u, double v) {
        return std::bit_cast<std::uint64_t>(u) == std::bit_cast<std::uint64_t>(v);
    };
    if (a.nx != b.nx || a.ny != b.ny || !same(a.dx_um, b.dx_um) || !same(a.dy_um, b.dy_um) ||
        !same(a.x_offset_um, b.x_offset_um) || !same(a.y_offset_um, b.y_offset_um) ||
        a.heights_um.size() != b.heights_um.size()) {
        return false;
    }
    for (std::size_t i = 0; i < a.heights_um.size(); ++i) {
        const double u = a.heights_um[i];
        const double v = b.heights_um[i];
        if (std::isnan(u) && std::isnan(v)) continue;
        if (!same(u, v)) return false;
    }
    return true;
}

}  // namespace roughscope::surface
