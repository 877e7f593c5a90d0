// Capture files (simulation/capture.hpp, docs/simulation-captures.md "Files"): PNG through libpng,
// TIFF and DNG through libtiff, all encoded in memory (the caller writes the bytes atomically).
// libpng reports errors by longjmp: every object with a destructor is created before setjmp.
// libtiff's messages go to a per-file handler, never to stderr.
#include <algorithm>
#include <array>
#include <csetjmp>
#include <cstdarg>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include <png.h>
#include <tiffio.h>

#include "io/memory_image_writers.hpp"
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

using io::detail::PngMemoryWriter;
using TiffWriter = io::detail::TiffMemoryWriter;

void set_common_tags(TIFF* tif, const Capture& c, int bits, int samples, int sample_format,
                     int photometric) {
    TIFFSetField(tif, TIFFTAG_SUBFILETYPE, 0);
    TIFFSetField(tif, TIFFTAG_IMAGEWIDTH, static_cast<std::uint32_t>(c.width));
    TIFFSetField(tif, TIFFTAG_IMAGELENGTH, static_cast<std::uint32_t>(c.height));
    TIFFSetField(tif, TIFFTAG_BITSPERSAMPLE, bits);
    TIFFSetField(tif, TIFFTAG_SAMPLESPERPIXEL, samples);
    TIFFSetField(tif, TIFFTAG_SAMPLEFORMAT, sample_format);
    TIFFSetField(tif, TIFFTAG_PHOTOMETRIC, photometric);
    TIFFSetField(tif, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
    TIFFSetField(tif, TIFFTAG_COMPRESSION, COMPRESSION_NONE);
    TIFFSetField(tif, TIFFTAG_ORIENTATION, ORIENTATION_TOPLEFT);
    TIFFSetField(tif, TIFFTAG_ROWSPERSTRIP, TIFFDefaultStripSize(tif, 0));
    TIFFSetField(tif, TIFFTAG_SOFTWARE, "roughscope simulate capture");
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
    const bool eight = capture.bit_depth == 8;
    const std::size_t bytes_per_pixel = eight ? 1 : 2;
    const std::size_t row_bytes = capture.width * bytes_per_pixel;
    std::vector<unsigned char> pixels(row_bytes * capture.height);
    for (std::size_t i = 0; i < capture.dn.size(); ++i) {
        if (eight) {
            pixels[i] = static_cast<unsigned char>(capture.dn[i]);
        } else {
            pixels[2 * i] = static_cast<unsigned char>(capture.dn[i] >> 8);  // big-endian
            pixels[2 * i + 1] = static_cast<unsigned char>(capture.dn[i] & 0xff);
        }
    }
    std::vector<png_bytep> rows(capture.height);
    for (std::size_t r = 0; r < capture.height; ++r) rows[r] = pixels.data() + r * row_bytes;
    std::string out;
    out.reserve(pixels.size() + pixels.size() / 8 + 1024);
    PngMemoryWriter w(out);
    if (setjmp(png_jmpbuf(w.png())) != 0) throw Error(w.message());
    // Fast settings: the images are noise, which deflate barely shrinks.
    png_set_compression_level(w.png(), 1);
    png_set_filter(w.png(), PNG_FILTER_TYPE_BASE, PNG_FILTER_NONE);
    png_set_IHDR(w.png(), w.info(), static_cast<png_uint_32>(capture.width),
                 static_cast<png_uint_32>(capture.height), eight ? 8 : 16, PNG_COLOR_TYPE_GRAY,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_color_8 significant{};
    significant.gray = static_cast<png_byte>(capture.bit_depth);
    png_set_sBIT(w.png(), w.info(), &significant);
    png_write_info(w.png(), w.info());
    png_write_image(w.png(), rows.data());
    png_write_end(w.png(), nullptr);
    return out;
}

std::string encode_capture_tiff(const Capture& capture) {
    check_capture(capture);
    std::string out;
    out.reserve(capture.dn.size() * 2 + 4096);
    {
        TiffWriter writer(out, "w", "tiff");
        set_common_tags(writer.get(), capture, 16, 1, SAMPLEFORMAT_UINT, PHOTOMETRIC_MINISBLACK);
        writer.write_rows(reinterpret_cast<const unsigned char*>(capture.dn.data()),
                          capture.width * 2, capture.height);
        writer.finish();
    }
    return out;
}

std::string encode_capture_tiff_float(const Capture& capture) {
    check_capture(capture);
    if (capture.expected_dn.size() != capture.width * capture.height)
        throw InvalidArgument(
            "capture: a float TIFF holds expected_dn, which this capture did not keep "
            "(CaptureOptions::keep_expected_dn)");
    std::string out;
    out.reserve(capture.expected_dn.size() * 4 + 4096);
    {
        TiffWriter writer(out, "w", "tiff");
        set_common_tags(writer.get(), capture, 32, 1, SAMPLEFORMAT_IEEEFP, PHOTOMETRIC_MINISBLACK);
        writer.write_rows(reinterpret_cast<const unsigned char*>(capture.expected_dn.data()),
                          capture.width * 4, capture.height);
        writer.finish();
    }
    return out;
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
    std::string out;
    out.reserve(rgb.size() * 2 + 4096);
    {
        TiffWriter writer(out, "w", "tiff");
        TIFF* tif = writer.get();
        set_common_tags(tif, capture, 16, 3, SAMPLEFORMAT_UINT, 34892 /* LinearRaw */);
        TIFFSetField(tif, TIFFTAG_MAKE, "roughscope");
        TIFFSetField(tif, TIFFTAG_MODEL, "synthetic capture");
        const std::array<std::uint8_t, 4> version{1, 4, 0, 0};
        const std::array<std::uint8_t, 4> backward{1, 1, 0, 0};
        TIFFSetField(tif, TIFFTAG_DNGVERSION, version.data());
        TIFFSetField(tif, TIFFTAG_DNGBACKWARDVERSION, backward.data());
        TIFFSetField(tif, TIFFTAG_UNIQUECAMERAMODEL, "roughscope synthetic capture");
        const std::array<float, 3> black{static_cast<float>(camera.black_level_dn),
                                         static_cast<float>(camera.black_level_dn),
                                         static_cast<float>(camera.black_level_dn)};
        TIFFSetField(tif, TIFFTAG_BLACKLEVEL, std::uint16_t{3}, black.data());
        const auto white_dn = static_cast<std::uint32_t>(camera.white_level_dn());
        const std::array<std::uint32_t, 3> white{white_dn, white_dn, white_dn};
        TIFFSetField(tif, TIFFTAG_WHITELEVEL, std::uint16_t{3}, white.data());
        const std::array<float, 9> identity{1, 0, 0, 0, 1, 0, 0, 0, 1};
        TIFFSetField(tif, TIFFTAG_COLORMATRIX1, std::uint16_t{9}, identity.data());
        const std::array<float, 3> neutral{1, 1, 1};
        TIFFSetField(tif, TIFFTAG_ASSHOTNEUTRAL, std::uint16_t{3}, neutral.data());
        TIFFSetField(tif, TIFFTAG_CALIBRATIONILLUMINANT1, std::uint16_t{21});
        writer.write_rows(reinterpret_cast<const unsigned char*>(rgb.data()), capture.width * 6,
                          capture.height);
        writer.finish();
    }
    return out;
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
