// The CUReT BRDF database (Dana, van Ginneken, Nayar, Koenderink, ACM TOG 18(1), 1999), as the
// paper uses it in §5.3. The files are never part of the project: they are read from a directory
// (../shared/data/curet beside the project as io/data_locator.hpp finds it, a path the user
// gives, or $ROUGHSCOPE_CURET).
//
// Files (whitespace-separated text):
//  * table.txt   205 lines `measurement theta_v phi_v theta_i phi_i`, radians, sample frame
//                (v = viewing/camera direction, i = illumination; see brdf_table.hpp)
//  * abrdf.dat   one line per sample: the sample number, then the 205 BRDF values (1/sr) averaged
//                over the red, green and blue channels. rbrdf.dat, gbrdf.dat, bbrdf.dat: the same
//                per channel, when present.
//  * rover.dat, gover.dat, bover.dat (optional): per-measurement fractions of saturated pixels,
//                assumed in the same layout as the BRDF files (sample number + 205 values in
//                [0, 1]). For the mean channel aover.dat is used when present, else the largest
//                fraction over whichever channel files exist.
// 43 of the 12,505 values of abrdf.dat are ≤ 0 (calibration noise): they are loaded as they are.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "roughscope/brdf/table.hpp"
#include "roughscope/scattering/reflectance_models.hpp"

namespace roughscope {

inline constexpr int kCuretMeasurementCount = 205;
inline constexpr int kCuretSampleCount = 61;
// §5.3 / Table 3: the two normal-view measurements used for the two-point estimate
// (81: θi = 45°, 112: θi = 67.5°, both with θv = 0).
inline constexpr int kCuretTwoPointMeasurement1 = 81;
inline constexpr int kCuretTwoPointMeasurement2 = 112;

// Colour channel of the BRDF file: mean → abrdf.dat, red → rbrdf.dat, green → gbrdf.dat,
// blue → bbrdf.dat.
enum class CuretChannel { Mean, Red, Green, Blue };
std::string_view to_string(CuretChannel channel);         // "mean", "red", "green", "blue"
CuretChannel parse_curet_channel(std::string_view name);  // also "a", "r", "g", "b"; throws
                                                          // InvalidArgument listing the names
std::string curet_brdf_file_name(CuretChannel channel);   // "abrdf.dat", ...

// One row of table.txt.
struct CuretAngles {
    int measurement = 0;
    double theta_v_rad = 0.0;
    double phi_v_rad = 0.0;
    double theta_i_rad = 0.0;
    double phi_i_rad = 0.0;
};

// The database for one channel, as loaded.
struct CuretDatabase {
    std::filesystem::path directory;
    CuretChannel channel = CuretChannel::Mean;
    std::vector<CuretAngles> angles;        // 205 rows, measurement j at angles[j − 1]
    std::vector<int> samples;               // sample numbers in file order
    std::vector<std::vector<double>> brdf;  // brdf[row][j − 1], 1/sr, row as in `samples`
    std::vector<std::vector<double>>
        overflow;                             // same shape when an overflow file exists, else empty
    std::vector<std::string> overflow_files;  // the overflow files that were read

    // Row of `sample` in `samples`; throws InvalidArgument naming the sample and the valid range.
    std::size_t row(int sample) const;
    // The sample's 205 measurements as a BrdfTable (geometry in the paper's frame).
    BrdfTable sample_table(int sample) const;
};

// Where the CUReT files are: `explicit_dir` when given (must exist and hold table.txt and
// abrdf.dat); else the reference-data locator's data/curet (io/data_locator.hpp:
// $ROUGHSCOPE_SHARED_DIR, else ../shared searched upward from the current directory); else
// $ROUGHSCOPE_CURET. Otherwise throws DataError saying where the database comes from and which
// files are needed.
std::filesystem::path find_curet_directory(
    const std::optional<std::filesystem::path>& explicit_dir = std::nullopt);

// Loads table.txt and the channel's BRDF file (plus the overflow files when present) from `dir`.
// Throws DataError "<file>:<line>: <reason>" for a missing or malformed file (wrong field count,
// bad number, angle out of range, measurement numbers not 1..205 in order, duplicate sample).
CuretDatabase load_curet(const std::filesystem::path& dir,
                         CuretChannel channel = CuretChannel::Mean);

// Names the paper gives (Table 3 / Fig. 9): 25 "Quarry tile", 34 "Slate b", 41 "Brick b";
// empty for other samples.
std::string_view curet_sample_name(int sample);

// Oren–Nayar parameters the paper lists in Table 3 (taken from the CUReT database) for samples
// 25, 34, 41; std::nullopt for the others.
std::optional<OrenNayarParams> paper_oren_nayar_params(int sample);

}  // namespace roughscope
