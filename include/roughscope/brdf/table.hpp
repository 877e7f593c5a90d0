// Measured BRDF tables (CUReT or any user table) and their conversion to the paper's frame and to
// camera-like brightness (paper §2 and §5.3).
//
// Frame convention of a BRDF table (the one CUReT uses, and the one the CSV reader expects):
//  * θi, θv are polar angles of the illumination and viewing directions from the sample normal;
//  * φi, φv are their azimuths, both measured in ONE frame fixed to the sample (any origin).
// The paper's frame (geometry.hpp) turns the sample so that the light azimuth is π; in it
//    θs = θv,   φs = φv − φi + π (mod 2π)            (geometry_from_two_azimuths, §2 / Fig. 2)
// so φs = 0 is the specular half-plane and φs = π retro-reflection. A table already in the
// paper's frame is written with φi = 180° and φv = φs (the conversion is then the identity).
//
// Brightness: a camera pixel viewing the sample under a small, constant source measures
//    E ∝ f(θi, φi, θs, φs) cos θi                     (§2 and §5.3)
// with f the BRDF. Non-positive BRDF values (measurement noise around zero) are carried, never
// dropped silently: see comparison.hpp for what each use does with them.
#pragma once

#include <cmath>
#include <cstddef>
#include <filesystem>
#include <iosfwd>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "roughscope/scattering/geometry.hpp"

namespace roughscope {

// One BRDF measurement.
struct BrdfMeasurement {
    int index = 0;             // measurement number (CUReT: 1..205; CSV: column or row order)
    double theta_i_rad = 0.0;  // illumination polar angle θi, [0, π/2)
    double phi_i_rad = 0.0;    // illumination azimuth φi (sample frame)
    double theta_v_rad = 0.0;  // viewing polar angle θv, [0, π/2)
    double phi_v_rad = 0.0;    // viewing azimuth φv (sample frame)
    double value = 0.0;        // BRDF f in 1/sr; may be ≤ 0 (noise), always finite
    double weight = 1.0;       // weight in error sums and fits, finite and ≥ 0
    std::optional<double> overflow_fraction;  // fraction of saturated pixels, when published
    Geometry geometry;  // the same directions in the paper's frame (θi, θs, φs)
};

// A BRDF table: the measurements of one sample in one colour channel.
struct BrdfTable {
    std::string name;     // e.g. "CUReT sample 25" or the file name
    std::string channel;  // "mean", "red", ... or the CSV channel; empty when not given
    std::vector<BrdfMeasurement> measurements;

    std::size_t size() const { return measurements.size(); }
    // Position of the measurement with this index, or std::nullopt.
    std::optional<std::size_t> find(int index) const;
};

// §5.3: camera-like brightness from the BRDF, E ∝ f cos θi (source solid angle and radiance
// dropped: constant for one sample).
inline double brightness_from_brdf(double f_per_sr, double theta_i_rad) {
    return f_per_sr * std::cos(theta_i_rad);
}

// Builds a validated measurement: θi, θv in [0, π/2), azimuths finite, value finite (any sign),
// weight finite and ≥ 0, overflow (when given) in [0, 1]. Fills `geometry` with
// geometry_from_two_azimuths. Throws InvalidArgument naming the input otherwise.
BrdfMeasurement make_brdf_measurement(int index, double theta_i_rad, double phi_i_rad,
                                      double theta_v_rad, double phi_v_rad, double value,
                                      double weight = 1.0,
                                      std::optional<double> overflow_fraction = std::nullopt);

// CSV reader options.
struct BrdfCsvOptions {
    // Keep only the rows of this channel. Required when the file has a `channel` column with
    // more than one distinct value (the error lists them).
    std::optional<std::string> channel;
};

// Reads a BRDF table from comma-separated text with a header line.
//  Required columns: theta_i, phi_i, theta_s, phi_s (degrees; θs, φs = the viewing direction in
//  the sample frame of the file comment) and value (BRDF, 1/sr, any sign).
//  Optional columns: weight (≥ 0, default 1), channel (text), measurement (integer index;
//  default: the data row number, 1-based). Other columns are ignored.
//  Read with the library's CSV reader (io/csv.hpp): blank lines and lines starting with '#' are
//  skipped; fields are trimmed; CRLF and a UTF-8 byte-order mark accepted; numbers strict (in
//  every row, also rows of channels not selected).
// Throws DataError "<source>:<line>: <reason>" naming the column for anything malformed
// (missing column, bad number, angle out of range, duplicate measurement index, no data rows).
BrdfTable parse_brdf_csv(std::string_view text, std::string_view source_name,
                         const BrdfCsvOptions& options = {});
// The same from a stream, read row by row.
BrdfTable parse_brdf_csv(std::istream& in, std::string_view source_name,
                         const BrdfCsvOptions& options = {});

// The same from a file; DataError when the file cannot be read.
BrdfTable read_brdf_csv(const std::filesystem::path& path, const BrdfCsvOptions& options = {});

}  // namespace roughscope
