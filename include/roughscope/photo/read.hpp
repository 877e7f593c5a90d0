// Reading photographs into LinearImage (image/image.hpp); the details are in docs/image.md.
//
// Formats, chosen by the file's first bytes (never by its extension):
//   PNG   8/16-bit grey, grey + alpha, RGB, RGBA (alpha dropped), through libpng;
//   TIFF  8/16-bit unsigned and 32-bit float, grey or RGB (extra samples dropped), strips or
//         tiles, contiguous or separate planes, through libtiff;
//   JPEG  8-bit grey or colour (baseline or progressive), through libjpeg;
//   RAW   camera RAW files (DNG, CR2, NEF, ARW, ...) through LibRaw: the sensor values, linear,
//         without demosaicing: a colour-filter-array sensor gives a half-size RGB image (each 2 x 2
//         Bayer block, or 3 x 3 X-Trans block, one pixel: the mean of its sites of each colour).
//         A TIFF-structured file is read as RAW when it is a DNG, a CR2, a CFA or LinearRaw image,
//         or its first image is a reduced-resolution preview; any other file that is not PNG,
//         JPEG or TIFF is offered to LibRaw.
//
// The linear scale. Each stored code q (per channel) is first brought back to a linear code
//   s = F · R⁻¹(q / F)      F: the file's full scale (2^bits − 1; 1 for float; RAW: LibRaw's
//                           maximum), R: the response (linear: s = q; sRGB: IEC 61966-2-1
//                           decode; gamma γ: s = F · (q/F)^γ),
// then value = (s − black) / (white − black), with black and white levels in the units of s
// (linear DN). Flags (per pixel): kPixelSaturated when a channel has s ≥ white, kPixelClippedLow
// when a channel has s ≤ black (RAW: per sensor site, against its own black level), kPixelMissing
// when a sample of a float file is NaN (value 0); an infinite float sample is a DataError.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "roughscope/core/response.hpp"
#include "roughscope/photo/image.hpp"

namespace roughscope::image {

// The largest image read (width × height, before a RAW file's half-size binning): larger files
// are refused with a DataError before their pixels are allocated.
inline constexpr std::size_t kMaxImagePixels = 400'000'000;

struct ReadOptions {
    // The response to invert. Unset: the file's evidence (ImageInfo::file_response: a PNG sRGB,
    // gAMA or iCCP chunk, a TIFF ICC profile, EXIF ColorSpace sRGB, a JPEG, a RAW), else linear
    // for RAW, float and 16-bit files and sRGB for 8-bit ones.
    std::optional<Response> response;
    double gamma = 0.0;  // Response::Gamma only: γ, finite and > 0 (0 otherwise)
    // Black level per plane (R, G, B; one value for every plane), linear DN, finite and ≥ 0.
    // Unset: 0, or LibRaw's per-channel black level for RAW.
    std::optional<std::vector<double>> black_level_dn;
    // White level, linear DN, finite and > 0 (and above every black level). Unset: the file's full
    // scale F (RAW: LibRaw's maximum).
    std::optional<double> white_level_dn;
    // RAW only: multiply each plane by the camera's white balance (as-shot multipliers,
    // normalised to green = 1). Off by default: the values stay the sensor's own.
    bool white_balance = false;
};

// Throws InvalidArgument naming the field and its valid range.
void check_read_options(const ReadOptions& options);

// Reads a photograph. Throws DataError naming `path` when it is missing, unreadable, truncated,
// corrupt, of an unsupported kind (bit depth, channels, layout) or larger than kMaxImagePixels;
// InvalidArgument for bad options (also a black level list that does not match the planes, or a
// white level not above the black level).
LinearImage read_image(const std::string& path, const ReadOptions& options = {});

// The same from the file's bytes; `name` stands for the file in ImageInfo::source and messages.
LinearImage decode_image(std::span<const std::uint8_t> bytes, const std::string& name,
                         const ReadOptions& options = {});

}  // namespace roughscope::image
