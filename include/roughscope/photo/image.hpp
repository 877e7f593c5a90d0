// Photographs on a linear scale: the value type every part of the image topic works on.
//
// A LinearImage holds what a camera pixel measured, brought back to a scale proportional to the
// light that reached it: the stored code values with the camera's black level subtracted, the
// response (sRGB, gamma) inverted, divided by (white level − black level), so 0 is black and 1
// the largest value the file can hold. It is *not* divided by the exposure time: the measurement
// does that (image/measure.hpp), from the capture file or the file's metadata.
//
// Layout: planar, row-major, row 0 at the top. Plane c (0 = R, 1 = G, 2 = B; a grey image has one
// plane), row r, column x is values[(c · height + r) · width + x]. Per pixel (not per channel),
// `flags` marks pixels that must never enter a measurement: a channel at the white level or
// clipped by the camera (kSaturated), or a channel at code 0 after the black level, where the
// true value may lie below what was recorded (kClippedLow).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "roughscope/core/memory.hpp"
#include "roughscope/core/response.hpp"

namespace roughscope::image {

// Bits of LinearImage::flags.
inline constexpr std::uint8_t kPixelSaturated = 1;    // a channel at or above the white level
                                                      // (or clipped by the camera)
inline constexpr std::uint8_t kPixelClippedLow = 2;   // a channel at or below the black level
inline constexpr std::uint8_t kPixelNoFlatField = 4;  // no usable flat-field value (the flat is
                                                      // ≤ 0 or flagged there): not corrected
                                                      // (image/radiometry.hpp)
inline constexpr std::uint8_t kPixelMissing = 8;      // no value: a NaN sample of a float file
                                                      // (e.g. a roughscope map's cells without
                                                      // an estimate); the value is stored as 0

// What the file said about itself and what reading it did.
struct ImageInfo {
    std::string source;           // the path (or the name given to decode_image)
    std::string format;           // "png", "tiff", "jpeg", "raw" (any LibRaw format)
    std::string raw_format;       // RAW only: LibRaw's make/model or format name; else empty
    int bits_per_sample = 0;      // 8, 16, 32 (float) as stored; RAW: bits of the sensor data
    bool is_float = false;        // float samples (TIFF)
    double white_level_dn = 0.0;  // the stored code of full scale (float: 1)
    std::vector<double> black_level_dn;    // per plane, subtracted (0 unless RAW or given)
    Response response = Response::Linear;  // the response that was inverted
    double gamma = 0.0;                    // Response::Gamma only
    // What the file's own metadata says of its response, when it says anything: an sRGB, gAMA or
    // iCCP chunk (PNG), a JPEG (sRGB unless stated otherwise), an EXIF colour space, a RAW
    // (linear). `file_response_evidence` names the evidence ("PNG sRGB chunk").
    std::optional<Response> file_response;
    std::string file_response_evidence;
    // From EXIF or the RAW metadata, when present.
    std::optional<double> exposure_s;
    std::optional<double> f_number;
    std::optional<double> iso;
    std::vector<std::string> warnings;  // e.g. a declared response that the file contradicts
};

struct LinearImage {
    std::size_t width = 0;
    std::size_t height = 0;
    std::size_t channels = 0;  // 1 (grey) or 3 (R, G, B)
    // channels · height · width, see the layout above (a std::vector<float> whose resize does
    // not zero-fill: a decoder writes every value)
    std::vector<float, DefaultInitAllocator<float>> values;
    std::vector<std::uint8_t> flags;  // height · width, kPixel* bits
    ImageInfo info;

    std::size_t pixel_count() const { return width * height; }
    float value(std::size_t channel, std::size_t row, std::size_t col) const {
        return values[(channel * height + row) * width + col];
    }
    const float* plane(std::size_t channel) const {
        return values.data() + channel * height * width;
    }
};

// Throws InvalidArgument (naming info.source) unless the image is consistent: width, height ≥ 1,
// channels 1 or 3, values.size() = channels · height · width, flags.size() = height · width,
// every value finite.
void check_linear_image(const LinearImage& image);

// The same checks but the finiteness of the values: for a caller that reads only some of them
// (region_statistics: the region's used pixels) and checks those itself.
void check_linear_image_layout(const LinearImage& image);

// Throws the InvalidArgument of check_linear_image for the non-finite values[sample].
[[noreturn]] void throw_non_finite_value(const LinearImage& image, std::size_t sample);

// Pixels whose flags have any bit of `mask` set.
std::size_t count_flagged(const LinearImage& image, std::uint8_t mask);

}  // namespace roughscope::image
