// Capture files (simulation/capture.hpp, docs/simulation-captures.md "Files"): PNG, TIFF and DNG
// encoded in memory by io's codecs (src/io/png_codec.hpp, tiff_codec.hpp); the caller writes the
// bytes atomically.
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "io/png_codec.hpp"
#include "io/tiff_codec.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/names.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/simulation/capture.hpp"

namespace roughscope::simulation {

namespace {

constexpr std::array<NameEntry<CaptureFormat>, 5> kFormatNames{{
    {"png", CaptureFormat::Png},
    {"tiff", CaptureFormat::Tiff},
    {"tiff_float", CaptureFormat::TiffFloat},
    {"dng", CaptureFormat::Dng},
    {"tif", CaptureFormat::Tiff},
}};

namespace codec = io::codec;

// Grey samples of the capture's size in strips, with the tags every capture TIFF carries.
std::string encode_capture_samples(const Capture& c, const void* samples, codec::SampleType type,
                                   std::size_t channels, codec::TiffEncodeOptions options) {
    options.subfile_type = true;
    options.orientation = true;
    options.software = "roughscope simulate capture";
    return codec::encode_tiff({samples, c.width, c.height, channels, type, 0}, options);
}

void check_capture(const Capture& c) {
    if (c.width == 0 || c.height == 0 || c.dn.size() != c.width * c.height)
        throw InvalidArgument("capture: empty, or its images do not match width x height");
}

}  // namespace

std::string_view to_string(CaptureFormat format) { return name_of(kFormatNames, format); }
CaptureFormat parse_capture_format(std::string_view name) {
    return parse_name(kFormatNames, "capture format", name);
}
CaptureOptions capture_options_for_file(CaptureFormat format, bool several_regions) {
    CaptureOptions o;
    o.keep_geometry = several_regions;
    o.keep_radiance = false;
    o.keep_expected_dn = format == CaptureFormat::TiffFloat;
    return o;
}

std::string_view file_extension(CaptureFormat format) {
    switch (format) {
        case CaptureFormat::Png:
            return "png";
        case CaptureFormat::Tiff:
        case CaptureFormat::TiffFloat:
            return "tiff";
        case CaptureFormat::Dng:
            return "dng";
    }
    return "bin";
}

std::string encode_capture_png(const Capture& capture) {
    check_capture(capture);
    codec::PngEncodeOptions options;
    // Fast settings: the images are noise, which deflate barely shrinks.
    options.compression_level = 1;
    options.filter = false;
    options.significant_bits = capture.bit_depth;
    if (capture.bit_depth == 8) {
        const std::vector<std::uint8_t> codes(capture.dn.begin(), capture.dn.end());
        return codec::encode_png({codes.data(), capture.width, capture.height, 1, {8, false}, 0},
                                 options);
    }
    return codec::encode_png({capture.dn.data(), capture.width, capture.height, 1, {16, false}, 0},
                             options);
}

std::string encode_capture_tiff(const Capture& capture) {
    check_capture(capture);
    return encode_capture_samples(capture, capture.dn.data(), {16, false}, 1, {});
}

std::string encode_capture_tiff_float(const Capture& capture) {
    check_capture(capture);
    if (capture.expected_dn.size() != capture.width * capture.height)
        throw InvalidArgument(
            "capture: a float TIFF holds expected_dn, which this capture did not keep "
            "(CaptureOptions::keep_expected_dn)");
    return encode_capture_samples(capture, capture.expected_dn.data(), {32, true}, 1, {});
}

// DNG 1.4 (Adobe DNG specification, chapter "Tags"): a LinearRaw image of 3 samples per pixel
// (each the pixel's DN), BlackLevel and WhiteLevel of the camera, an identity ColorMatrix1 (the
// grey value maps to itself), AsShotNeutral 1 1 1, CalibrationIlluminant1 D65 (21).
std::string encode_capture_dng(const Capture& capture, const CameraModel& camera) {
    check_capture(capture);
    if (camera.response != Response::Linear)
        throw InvalidArgument(concat("format dng holds linear raw values; response ",
                                     to_string(camera.response),
                                     " is not allowed (use response linear)"));
    const std::size_t n = capture.dn.size();
    std::vector<std::uint16_t> rgb(3 * n);
    for (std::size_t i = 0; i < n; ++i)
        rgb[3 * i] = rgb[3 * i + 1] = rgb[3 * i + 2] = capture.dn[i];
    codec::DngTags dng;
    dng.make = "roughscope";
    dng.model = "synthetic capture";
    dng.unique_camera_model = "roughscope synthetic capture";
    const auto black = static_cast<float>(camera.black_level_dn);
    dng.black_level = {black, black, black};
    const auto white = static_cast<std::uint32_t>(camera.white_level_dn());
    dng.white_level = {white, white, white};
    dng.color_matrix1 = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    dng.as_shot_neutral = {1, 1, 1};
    dng.calibration_illuminant1 = 21;
    codec::TiffEncodeOptions options;
    options.photometric = codec::tiff::kPhotometricLinearRaw;
    options.dng = dng;
    return encode_capture_samples(capture, rgb.data(), {16, false}, 3, options);
}

std::string encode_capture(const Capture& capture, const CameraModel& camera,
                           CaptureFormat format) {
    switch (format) {
        case CaptureFormat::Png:
            return encode_capture_png(capture);
        case CaptureFormat::Tiff:
            return encode_capture_tiff(capture);
        case CaptureFormat::TiffFloat:
            return encode_capture_tiff_float(capture);
        case CaptureFormat::Dng:
            return encode_capture_dng(capture, camera);
    }
    throw InvalidArgument("capture format: unknown");
}

}  // namespace roughscope::simulation
