// Files of a roughness map (image/maps.hpp), as bytes: the caller writes them (the CLI through
// io::OutputFile). Layouts in docs/maps.md "Files".
//
//   encode_map_tiff_float  32-bit IEEE float grey TIFF (SampleFormat 3), one strip per row
//                          group, uncompressed, little-endian; missing values stay NaN. Read back
//                          by image/read.hpp read_image (a float TIFF is read unscaled).
//   encode_npy             NumPy .npy version 1.0: magic "\x93NUMPY", 1, 0, a little-endian
//                          uint16 header length, the header dict
//                          {'descr': '<f4', 'fortran_order': False, 'shape': (height, width), }
//                          padded with spaces and ended by '\n' so that the data start at a
//                          multiple of 64 bytes, then the floats row-major (np.load reads it).
//   encode_map_png         8-bit RGB PNG: the layer in a colour map (OpenCV's VIRIDIS) over
//                          [range.lower, range.upper] (values clamped), missing pixels grey
//                          (kMissingGrey), a colour bar on the right with tick labels and the
//                          layer's label (OpenCV putText).
//   encode_class_png       8-bit RGB PNG of the class layer (kClass* codes) with a legend.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

namespace roughscope::image {

inline constexpr std::uint8_t kMissingGrey = 128;  // R = G = B of a missing pixel

// The colours of the classes (R, G, B): slightly, moderately, very rough.
inline constexpr std::array<std::array<std::uint8_t, 3>, 3> kClassColours{{
    {{68, 170, 255}},  // slightly rough: blue
    {{255, 200, 40}},  // moderately rough: amber
    {{220, 50, 50}},   // very rough: red
}};

struct ColourRange {
    double lower = 0.0;
    double upper = 1.0;
};

// The range of the finite values of a layer (lower = upper + 1 apart if it is constant; [0, 1]
// when none is finite).
ColourRange finite_range(std::span<const float> layer);

// All throw InvalidArgument when width · height ≠ layer.size(), a side is 0 or above 65535 (PNG)
// / 2^31 (TIFF, npy), or the colour range is not finite with lower < upper.
std::string encode_map_tiff_float(std::span<const float> layer, std::size_t width,
                                  std::size_t height);
// channels > 1: the layer holds `channels` values per pixel, shape (height, width, channels).
std::string encode_npy(std::span<const float> layer, std::size_t width, std::size_t height,
                       std::size_t channels = 1);
// Maps narrower than 256 pixels are enlarged by an integer factor (nearest neighbour) to at
// least 256 pixels on the longer side, so the bar's labels stay readable.
std::string encode_map_png(std::span<const float> layer, std::size_t width, std::size_t height,
                           ColourRange range, const std::string& label);
std::string encode_class_png(std::span<const std::uint8_t> classes, std::size_t width,
                             std::size_t height);

// A normal map (n_x, n_y, n_z per pixel, NaN where none) as the usual 8-bit RGB encoding
// v = (n + 1)/2 (kMissingGrey where none).
std::string encode_normals_png(std::span<const float> normals, std::size_t width,
                               std::size_t height);

// The colour (R, G, B) the PNG gives a value (VIRIDIS at (v − lower)/(upper − lower) · 255,
// rounded; kMissingGrey for NaN). For tests and plots.
std::array<std::uint8_t, 3> map_colour(float value, ColourRange range);

}  // namespace roughscope::image
