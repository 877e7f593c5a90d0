// A digitised surface: heights on a regular grid (paper §3.1), the value type every height-data
// reader returns, every statistic takes and the generator produces.
//
// Layout: nx columns along x, ny rows along y, row-major: z(ix, iy) = heights_um[iy * nx + ix],
// ix in [0, nx), iy in [0, ny). Spacings dx_um, dy_um > 0. A profile is a map with ny = 1 (dy_um
// is then kept but unused). Heights are micrometres; a missing point (a NaN or an infinity in a
// file, a point a validity bitmap marks invalid) is stored as NaN and is the only non-finite value
// a HeightMap holds. The first sample sits at (x_offset_um, y_offset_um).
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace roughscope::surface {

struct HeightMap {
    std::size_t nx = 0;  // points along x (columns)
    std::size_t ny = 0;  // points along y (rows); 1 for a profile
    double dx_um = 1.0;  // spacing along x, µm
    double dy_um = 1.0;  // spacing along y, µm
    double x_offset_um = 0.0;
    double y_offset_um = 0.0;
    std::vector<double> heights_um;  // nx * ny, row-major; NaN = missing point
    std::string title;               // free text from the file (may be empty)

    std::size_t size() const { return nx * ny; }
    bool is_profile() const { return ny == 1; }
    double& at(std::size_t ix, std::size_t iy) { return heights_um[iy * nx + ix]; }
    double at(std::size_t ix, std::size_t iy) const { return heights_um[iy * nx + ix]; }
    bool is_valid(std::size_t ix, std::size_t iy) const { return !std::isnan(at(ix, iy)); }
    double length_x_um() const { return static_cast<double>(nx) * dx_um; }
    double length_y_um() const { return static_cast<double>(ny) * dy_um; }

    // Number of measured (non-NaN) points.
    std::size_t count_valid() const;
    // 1 where a point is measured, 0 where it is missing (nx * ny, row-major).
    std::vector<std::uint8_t> mask() const;
    bool has_missing() const { return count_valid() != size(); }

    friend bool operator==(const HeightMap&, const HeightMap&) = default;
};

// A map of nx × ny points with the given spacings, every height 0. Throws InvalidArgument unless
// nx, ny ≥ 1, nx·ny ≤ kMaxHeightMapPoints and the spacings lie in [1e-30, 1e30] µm.
HeightMap make_height_map(std::size_t nx, std::size_t ny, double dx_um, double dy_um);

// Checks the invariants above (sizes; spacings in [kMinLengthUm, kMaxLengthUm] = [1e-30, 1e30] µm
// like every length of the library; heights NaN or within ±1e30 µm; offsets within ±1e30 µm; at
// least one valid point);
// throws InvalidArgument naming `what` (a file name, "heights") and the broken rule. Readers call
// it on what they built, so a HeightMap that leaves the library is always well formed.
void validate(const HeightMap& map, const std::string& what);

// The height rule of validate over z[0, n): the first index whose height is beyond ±1e30 µm (±inf
// included; NaN is a missing point), or n when none is; and whether any height is not NaN.
struct HeightsScan {
    std::size_t first_out_of_range = 0;
    bool any_valid = false;
};
HeightsScan scan_heights(const double* z, std::size_t n);

// validate with the heights already scanned by the caller (a reader that scans them chunk by
// chunk while they are in cache, merging the chunks' results): the same rules and messages.
void validate(const HeightMap& map, const std::string& what, const HeightsScan& heights);

// Largest map accepted anywhere (2^28 points = 2 GiB of doubles): protects against a corrupt
// header asking for terabytes.
inline constexpr std::size_t kMaxHeightMapPoints = std::size_t{1} << 28;

// Two maps equal bit for bit (NaN == NaN, +0 != -0): what the round-trip tests compare.
bool bitwise_equal(const HeightMap& a, const HeightMap& b);

}  // namespace roughscope::surface
