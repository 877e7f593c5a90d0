// Independent minimal writers for the image-reader tests: PNG through libpng directly (with the
// chunks the reader takes evidence from), and TIFF structures built byte by byte from the TIFF 6.0
// and DNG specifications (baseline TIFF, an EXIF sub-IFD, a Bayer DNG), little-endian.
#pragma once

#include <algorithm>
#include <cmath>
#include <csetjmp>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <png.h>

#include "../io/test_files.hpp"
#include "roughscope/io/output_file.hpp"

namespace roughscope::testing {

using ByteVector = std::vector<std::uint8_t>;

// IEC 61966-2-1, written out here (not the library's srgb_decode).
inline double srgb_to_linear(double v) {
    return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
}
inline double linear_to_srgb(double u) {
    return u <= 0.0031308 ? 12.92 * u : 1.055 * std::pow(u, 1.0 / 2.4) - 0.055;
}

inline std::filesystem::path write_bytes(const ByteVector& bytes, const std::string& dir,
                                         const std::string& name) {
    const std::filesystem::path path = fresh_dir(dir) / name;
    io::write_file_atomic(path, std::string(bytes.begin(), bytes.end()));
    return path;
}

// ---- PNG ---------------------------------------------------------------------------------------

struct PngSpec {
    std::uint32_t width = 1;
    std::uint32_t height = 1;
    int color_type = PNG_COLOR_TYPE_GRAY;
    int depth = 8;
    std::vector<std::uint16_t> samples;  // interleaved, row-major
    bool srgb_chunk = false;
    std::optional<double> gama;  // the gAMA chunk's encoding exponent (1/2.2 for γ = 2.2)
    ByteVector icc_profile;      // iCCP
    std::string icc_name = "profile";
    int significant_bits = 0;     // sBIT (0: none)
    bool shift_to_depth = false;  // samples hold significant_bits-bit codes; libpng scales them
    ByteVector exif;              // eXIf chunk (a TIFF structure)
    bool interlaced = false;
};

inline int png_get_channels_for(int color_type) {
    switch (color_type) {
        case PNG_COLOR_TYPE_GRAY:
            return 1;
        case PNG_COLOR_TYPE_GRAY_ALPHA:
            return 2;
        case PNG_COLOR_TYPE_RGB:
            return 3;
        case PNG_COLOR_TYPE_RGB_ALPHA:
            return 4;
        default:
            return 1;
    }
}

inline ByteVector png_bytes(const PngSpec& spec) {
    const int channels = png_get_channels_for(spec.color_type);
    const std::size_t bytes_per_sample = spec.depth == 16 ? 2 : 1;
    const std::size_t row_bytes = spec.width * channels * bytes_per_sample;
    std::vector<unsigned char> pixels(row_bytes * spec.height);
    for (std::size_t i = 0; i < spec.samples.size(); ++i) {
        if (spec.depth == 16) {
            pixels[2 * i] = static_cast<unsigned char>(spec.samples[i] >> 8);
            pixels[2 * i + 1] = static_cast<unsigned char>(spec.samples[i] & 0xff);
        } else {
            pixels[i] = static_cast<unsigned char>(spec.samples[i]);
        }
    }
    std::vector<png_bytep> rows(spec.height);
    for (std::size_t r = 0; r < spec.height; ++r) rows[r] = pixels.data() + r * row_bytes;
    ByteVector out;
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    png_infop info = png_create_info_struct(png);
    if (setjmp(png_jmpbuf(png)) != 0) {
        png_destroy_write_struct(&png, &info);
        throw std::runtime_error("test PNG writer failed");
    }
    png_set_write_fn(
        png, &out,
        [](png_structp p, png_bytep data, png_size_t n) {
            auto* o = static_cast<ByteVector*>(png_get_io_ptr(p));
            o->insert(o->end(), data, data + n);
        },
        [](png_structp) {});
    png_set_IHDR(png, info, spec.width, spec.height, spec.depth, spec.color_type,
                 spec.interlaced ? PNG_INTERLACE_ADAM7 : PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    if (spec.srgb_chunk) png_set_sRGB(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
    if (spec.gama) png_set_gAMA(png, info, *spec.gama);
    if (!spec.icc_profile.empty())
        png_set_iCCP(png, info, spec.icc_name.c_str(), 0, spec.icc_profile.data(),
                     static_cast<png_uint_32>(spec.icc_profile.size()));
    png_color_8 sbit{};
    if (spec.significant_bits > 0) {
        sbit.gray = sbit.red = sbit.green = sbit.blue =
            static_cast<png_byte>(spec.significant_bits);
        png_set_sBIT(png, info, &sbit);
    }
    if (!spec.exif.empty())
        png_set_eXIf_1(png, info, static_cast<png_uint_32>(spec.exif.size()),
                       const_cast<png_bytep>(spec.exif.data()));
    png_write_info(png, info);
    if (spec.shift_to_depth) png_set_shift(png, &sbit);
    if (spec.interlaced) png_set_interlace_handling(png);
    png_write_image(png, rows.data());
    png_write_end(png, nullptr);
    png_destroy_write_struct(&png, &info);
    return out;
}

// ---- TIFF structures ---------------------------------------------------------------------------

enum TiffType : std::uint16_t {
    kByte = 1,
    kAscii = 2,
    kShort = 3,
    kLong = 4,
    kRational = 5,
    kSRational = 10,
    kFloat = 11,
};

struct TiffEntry {
    std::uint16_t tag = 0;
    std::uint16_t type = kShort;
    std::uint32_t count = 0;
    ByteVector data;  // little-endian values
};

inline void put16(ByteVector& b, std::uint32_t v) {
    b.push_back(static_cast<std::uint8_t>(v & 0xff));
    b.push_back(static_cast<std::uint8_t>((v >> 8) & 0xff));
}
inline void put32(ByteVector& b, std::uint32_t v) {
    for (int k = 0; k < 4; ++k) b.push_back(static_cast<std::uint8_t>((v >> (8 * k)) & 0xff));
}

inline TiffEntry shorts(std::uint16_t tag, std::vector<std::uint32_t> values) {
    TiffEntry e{tag, kShort, static_cast<std::uint32_t>(values.size()), {}};
    for (auto v : values) put16(e.data, v);
    return e;
}
inline TiffEntry longs(std::uint16_t tag, std::vector<std::uint32_t> values) {
    TiffEntry e{tag, kLong, static_cast<std::uint32_t>(values.size()), {}};
    for (auto v : values) put32(e.data, v);
    return e;
}
inline TiffEntry bytes_entry(std::uint16_t tag, std::vector<std::uint8_t> values) {
    return TiffEntry{tag, kByte, static_cast<std::uint32_t>(values.size()), values};
}
inline TiffEntry ascii(std::uint16_t tag, const std::string& text) {
    TiffEntry e{tag, kAscii, static_cast<std::uint32_t>(text.size() + 1), {}};
    e.data.assign(text.begin(), text.end());
    e.data.push_back(0);
    return e;
}
inline TiffEntry rationals(std::uint16_t tag,
                           std::vector<std::pair<std::uint32_t, std::uint32_t>> v,
                           bool is_signed = false) {
    TiffEntry e{tag, is_signed ? kSRational : kRational, static_cast<std::uint32_t>(v.size()), {}};
    for (auto [n, d] : v) {
        put32(e.data, n);
        put32(e.data, d);
    }
    return e;
}

// One IFD at `offset` (entries sorted by tag; values over 4 bytes right after it), `next` the
// offset of the next IFD (0: none).
inline ByteVector ifd_bytes(std::vector<TiffEntry> entries, std::uint32_t offset,
                            std::uint32_t next = 0) {
    std::sort(entries.begin(), entries.end(),
              [](const TiffEntry& a, const TiffEntry& b) { return a.tag < b.tag; });
    ByteVector table;
    ByteVector overflow;
    const std::uint32_t overflow_at =
        offset + 2 + 12 * static_cast<std::uint32_t>(entries.size()) + 4;
    put16(table, static_cast<std::uint32_t>(entries.size()));
    for (const TiffEntry& e : entries) {
        put16(table, e.tag);
        put16(table, e.type);
        put32(table, e.count);
        if (e.data.size() <= 4) {
            ByteVector v = e.data;
            v.resize(4, 0);
            table.insert(table.end(), v.begin(), v.end());
        } else {
            put32(table, overflow_at + static_cast<std::uint32_t>(overflow.size()));
            overflow.insert(overflow.end(), e.data.begin(), e.data.end());
            if (overflow.size() % 2 != 0) overflow.push_back(0);
        }
    }
    put32(table, next);
    table.insert(table.end(), overflow.begin(), overflow.end());
    return table;
}

inline std::uint32_t ifd_size(const std::vector<TiffEntry>& entries) {
    return static_cast<std::uint32_t>(ifd_bytes(entries, 0).size());
}

// A TIFF file (or, with no pixel data, the TIFF structure of an EXIF block): header, pixel data
// (one strip at offset 8) when given, IFD0, then the EXIF IFD when `exif` is not empty (IFD0 gets
// the ExifIFD pointer, tag 34665). `ifd0` must not hold StripOffsets/StripByteCounts: they are
// added here for non-empty `pixels`.
inline ByteVector tiff_file(std::vector<TiffEntry> ifd0, const ByteVector& pixels,
                            const std::vector<TiffEntry>& exif = {}) {
    ByteVector out = {'I', 'I', 42, 0};
    std::uint32_t pixels_at = 8;
    std::uint32_t ifd0_at = pixels_at + static_cast<std::uint32_t>(pixels.size());
    ifd0_at += ifd0_at % 2;
    if (!pixels.empty()) {
        ifd0.push_back(longs(273, {pixels_at}));
        ifd0.push_back(longs(279, {static_cast<std::uint32_t>(pixels.size())}));
    }
    if (!exif.empty()) ifd0.push_back(longs(34665, {0}));
    const std::uint32_t exif_at = ifd0_at + ifd_size(ifd0);
    if (!exif.empty()) ifd0.back() = longs(34665, {exif_at});
    put32(out, ifd0_at);
    out.insert(out.end(), pixels.begin(), pixels.end());
    out.resize(ifd0_at, 0);
    const ByteVector table = ifd_bytes(ifd0, ifd0_at);
    out.insert(out.end(), table.begin(), table.end());
    if (!exif.empty()) {
        const ByteVector e = ifd_bytes(exif, exif_at);
        out.insert(out.end(), e.begin(), e.end());
    }
    return out;
}

// The EXIF entries of an exposure: ExposureTime 1/exposure_denominator s, FNumber, ISO and
// ColorSpace.
inline std::vector<TiffEntry> exif_exposure(std::uint32_t exposure_denominator,
                                            std::uint32_t f_number_x10, std::uint32_t iso,
                                            std::uint32_t color_space = 1) {
    return {rationals(33434, {{1, exposure_denominator}}), rationals(33437, {{f_number_x10, 10}}),
            shorts(34855, {iso}), shorts(40961, {color_space})};
}

// Baseline uncompressed TIFF: grey (1 sample) or RGB (3); sample format 1 (unsigned), 2
// (signed) or 3 (float).
inline ByteVector tiff_image(std::uint32_t width, std::uint32_t height, std::uint32_t samples,
                             std::uint32_t bits, std::uint32_t sample_format,
                             const ByteVector& pixels, std::vector<TiffEntry> extra = {},
                             const std::vector<TiffEntry>& exif = {}) {
    std::vector<TiffEntry> ifd0 = {
        longs(256, {width}),
        longs(257, {height}),
        shorts(258, std::vector<std::uint32_t>(samples, bits)),
        shorts(259, {1}),
        shorts(262, {samples == 3 ? 2U : 1U}),
        shorts(277, {samples}),
        longs(278, {height}),
        shorts(284, {1}),
        shorts(339, std::vector<std::uint32_t>(samples, sample_format)),
    };
    ifd0.insert(ifd0.end(), extra.begin(), extra.end());
    return tiff_file(ifd0, pixels, exif);
}

template <class T>
ByteVector raw_bytes(const std::vector<T>& values) {
    ByteVector b(values.size() * sizeof(T));
    std::memcpy(b.data(), values.data(), b.size());  // little-endian host, as the header says
    return b;
}

// A Bayer DNG (DNG 1.4): one IFD, CFA photometric, 16-bit sites, RGGB pattern, the given black
// levels (BlackLevelRepeatDim `repeat`, by default 1 x 1 for one value, 2 x 2 for four) and white
// level,
// AsShotNeutral, identity ColorMatrix1, and an EXIF IFD `exif` (by default ExposureTime 1/250 s,
// FNumber 8, ISO 400).
inline ByteVector bayer_dng(
    std::uint32_t width, std::uint32_t height, const std::vector<std::uint16_t>& sites,
    const std::vector<std::uint32_t>& black, std::uint32_t white,
    std::vector<std::pair<std::uint32_t, std::uint32_t>> neutral = {{1, 1}, {1, 1}, {1, 1}},
    std::pair<std::uint32_t, std::uint32_t> repeat = {0, 0},
    const std::vector<TiffEntry>& exif = exif_exposure(250, 80, 400)) {
    if (repeat.first == 0) repeat = black.size() == 4 ? std::pair{2U, 2U} : std::pair{1U, 1U};
    std::vector<TiffEntry> ifd0 = {
        longs(254, {0}),
        longs(256, {width}),
        longs(257, {height}),
        shorts(258, {16}),
        shorts(259, {1}),
        shorts(262, {32803}),
        ascii(271, "Roughscope"),
        ascii(272, "Test Bayer"),
        shorts(277, {1}),
        longs(278, {height}),
        shorts(284, {1}),
        shorts(33421, {2, 2}),
        bytes_entry(33422, {0, 1, 1, 2}),
        bytes_entry(50706, {1, 4, 0, 0}),
        bytes_entry(50707, {1, 1, 0, 0}),
        ascii(50708, "Roughscope Test Bayer"),
        bytes_entry(50710, {0, 1, 2}),
        shorts(50711, {1}),
        shorts(50713, {repeat.first, repeat.second}),
        longs(50714, black),
        longs(50717, {white}),
        rationals(50721, {{1, 1}, {0, 1}, {0, 1}, {0, 1}, {1, 1}, {0, 1}, {0, 1}, {0, 1}, {1, 1}},
                  true),
        rationals(50728, neutral),
        shorts(50778, {21}),
    };
    return tiff_file(ifd0, raw_bytes(sites), exif);
}

}  // namespace roughscope::testing
