// PNG photographs through libpng, from memory (read.hpp; docs/image.md "PNG").
//
// libpng reports errors by longjmp. Every object with a destructor lives in a PngState owned by
// decode_png; the libpng calls run in png_body, whose locals are all trivial, so the jump skips
// no destructor and leaves no object half-updated in a register. Our own errors are exceptions
// thrown by png_body between libpng calls (never from a libpng callback).
#include <algorithm>
#include <bit>
#include <cmath>
#include <csetjmp>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include <png.h>

#include "decode.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"

namespace roughscope::image::detail {

namespace {

// Deflate cannot expand data more than 1032:1.
constexpr std::uint64_t kDeflateMaxRatio = 1032;

struct PngInput {
    Bytes bytes;
    std::size_t pos = 0;
};

struct PngError {
    char message[256] = {};
};

void png_read_bytes(png_structp png, png_bytep out, png_size_t length) {
    auto* in = static_cast<PngInput*>(png_get_io_ptr(png));
    if (length > in->bytes.size() - in->pos) png_error(png, "unexpected end of file (truncated)");
    std::memcpy(out, in->bytes.data() + in->pos, length);
    in->pos += length;
}

[[noreturn]] void png_fail(png_structp png, png_const_charp message) {
    auto* e = static_cast<PngError*>(png_get_error_ptr(png));
    std::snprintf(e->message, sizeof e->message, "%s", message);
    png_longjmp(png, 1);
}

void png_ignore_warning(png_structp, png_const_charp) {}

struct PngReadHandle {
    png_structp png = nullptr;
    png_infop info = nullptr;
    ~PngReadHandle() { png_destroy_read_struct(&png, &info, nullptr); }
};

// Everything decode_png owns (see the file comment).
struct PngState {
    const std::string* name = nullptr;
    const ReadOptions* options = nullptr;
    PngInput input;
    PngError error;
    PngReadHandle h;
    LinearImage image;
    std::optional<Linearizer> linearizer;
    Layout layout;
    Evidence evidence;
    std::vector<std::uint8_t> exif_block;
    std::vector<std::uint8_t> pixels;  // the whole image (interlaced or sBIT), else one row
};

// sBIT: the significant bits of the colour channels, when fewer than the sample depth.
int significant_bits(png_structp png, png_infop info, int color, int depth) {
    png_color_8p sbit = nullptr;
    if (png_get_sBIT(png, info, &sbit) == 0 || sbit == nullptr) return depth;
    int bits = (color & PNG_COLOR_MASK_COLOR) != 0
                   ? std::max({int{sbit->red}, int{sbit->green}, int{sbit->blue}})
                   : int{sbit->gray};
    return bits >= 1 && bits < depth ? bits : depth;
}

void gather_evidence(PngState& st) {
    png_structp png = st.h.png;
    png_infop info = st.h.info;
    if (png_get_valid(png, info, PNG_INFO_sRGB) != 0) {
        st.evidence = {Response::Srgb, 0.0, "PNG sRGB chunk"};
        return;
    }
    png_charp profile_name = nullptr;
    int compression = 0;
    png_bytep profile = nullptr;
    png_uint_32 profile_bytes = 0;
    if (png_get_iCCP(png, info, &profile_name, &compression, &profile, &profile_bytes) != 0 &&
        profile != nullptr) {
        st.evidence = icc_evidence(
            Bytes(profile, profile_bytes),
            concat("PNG iCCP profile ", quote_input(profile_name ? profile_name : "")));
        if (st.evidence.known()) return;
    }
    png_fixed_point file_gamma = 0;
    if (png_get_gAMA_fixed(png, info, &file_gamma) != 0 && file_gamma > 0) {
        // gAMA holds the encoding exponent × 100000 (45455 for γ = 2.2).
        const double gamma = 100000.0 / static_cast<double>(file_gamma);
        const std::string text = concat("PNG gAMA chunk ", std::to_string(file_gamma));
        if (std::abs(gamma - 1.0) <= 0.01)
            st.evidence = {Response::Linear, 0.0, text};
        else
            st.evidence = {Response::Gamma, gamma, text};
    }
}

void take_exif(PngState& st) {
    png_uint_32 size = 0;
    png_bytep exif = nullptr;
    if (!st.exif_block.empty()) return;
    if (png_get_eXIf_1(st.h.png, st.h.info, &size, &exif) == 0 || exif == nullptr) return;
    st.exif_block.assign({'E', 'x', 'i', 'f', 0, 0});
    st.exif_block.insert(st.exif_block.end(), exif, exif + size);
}

// PNG samples with sBIT fewer than the sample depth: the specification scales them to the full
// depth (left shift with bit replication), but some writers store the s-bit codes unscaled.
// Codes that all fit in s bits, with some low bit set, are unscaled; otherwise they are shifted
// back down. Either way the codes end up in [0, 2^s − 1].
template <class T>
void unscale_significant(std::vector<std::uint8_t>& pixels, int depth, int significant) {
    const std::size_t n = pixels.size() / sizeof(T);
    auto* samples = reinterpret_cast<T*>(pixels.data());
    const unsigned shift = static_cast<unsigned>(depth - significant);
    const unsigned top = (1U << significant) - 1U;
    const unsigned low_mask = (1U << shift) - 1U;
    bool fits = true;
    bool low_bits = false;
    for (std::size_t i = 0; i < n; ++i) {
        fits = fits && samples[i] <= top;
        low_bits = low_bits || (samples[i] & low_mask) != 0;
    }
    if (fits && low_bits) return;
    for (std::size_t i = 0; i < n; ++i) samples[i] = static_cast<T>(samples[i] >> shift);
}

bool png_body(PngState& st) {
    if (setjmp(png_jmpbuf(st.h.png)) != 0) return false;
    png_structp png = st.h.png;
    png_infop info = st.h.info;
    const std::string& name = *st.name;
    png_set_read_fn(png, &st.input, png_read_bytes);
    png_read_info(png, info);
    png_uint_32 width = 0;
    png_uint_32 height = 0;
    int depth = 0;
    int color = 0;
    int interlace = 0;
    png_get_IHDR(png, info, &width, &height, &depth, &color, &interlace, nullptr, nullptr);
    std::size_t samples_per_pixel = 0;
    std::size_t channels = 0;
    switch (color) {
        case PNG_COLOR_TYPE_GRAY:
            samples_per_pixel = channels = 1;
            break;
        case PNG_COLOR_TYPE_GRAY_ALPHA:
            samples_per_pixel = 2;
            channels = 1;
            break;
        case PNG_COLOR_TYPE_RGB:
            samples_per_pixel = channels = 3;
            break;
        case PNG_COLOR_TYPE_RGB_ALPHA:
            samples_per_pixel = 4;
            channels = 3;
            break;
        default:
            throw DataError(concat(name, ": PNG colour type ", std::to_string(color),
                                   " (palette) is not supported; valid: grey, grey + alpha, "
                                   "RGB, RGBA"));
    }
    if (depth != 8 && depth != 16)
        throw DataError(concat(name, ": PNG of ", std::to_string(depth),
                               "-bit samples is not supported; valid: 8 or 16 bits"));
    const std::size_t sample_bytes = static_cast<std::size_t>(depth) / 8;
    check_pixel_count(name, width, height);
    check_expansion(name, std::uint64_t{width} * height * samples_per_pixel * sample_bytes,
                    st.input.bytes.size(), kDeflateMaxRatio, "PNG header");
    gather_evidence(st);
    take_exif(st);
    const int significant = significant_bits(png, info, color, depth);
    if (depth == 16 && std::endian::native == std::endian::little) png_set_swap(png);
    const int passes = interlace != PNG_INTERLACE_NONE ? png_set_interlace_handling(png) : 1;
    png_read_update_info(png, info);

    Layout& layout = st.layout;
    layout.width = width;
    layout.height = height;
    layout.channels = channels;
    layout.bits = depth;
    layout.full_scale = static_cast<double>((1U << significant) - 1U);
    const ExifFields exif = st.exif_block.empty() ? ExifFields{} : parse_exif(st.exif_block);
    if (!st.evidence.known()) {
        const Evidence from_exif = exif_color_space_evidence(exif);
        if (from_exif.known()) st.evidence = from_exif;
    }
    st.linearizer.emplace(st.image, layout, st.evidence, *st.options);
    const std::size_t row_bytes = std::size_t{width} * samples_per_pixel * sample_bytes;
    const bool whole = passes > 1 || significant < depth;
    st.pixels.resize(whole ? row_bytes * height : row_bytes);
    auto put_row = [&](const std::uint8_t* row, std::size_t r) {
        if (depth == 8)
            st.linearizer->put_pixels(row, r, samples_per_pixel, {0, 1, 2});
        else
            st.linearizer->put_pixels(reinterpret_cast<const std::uint16_t*>(row), r,
                                      samples_per_pixel, {0, 1, 2});
    };
    if (!whole) {
        for (std::size_t r = 0; r < height; ++r) {
            png_read_row(png, st.pixels.data(), nullptr);
            put_row(st.pixels.data(), r);
        }
    } else {
        for (int pass = 0; pass < passes; ++pass)
            for (std::size_t r = 0; r < height; ++r)
                png_read_row(png, st.pixels.data() + r * row_bytes, nullptr);
        if (significant < depth) {
            if (depth == 8)
                unscale_significant<std::uint8_t>(st.pixels, depth, significant);
            else
                unscale_significant<std::uint16_t>(st.pixels, depth, significant);
        }
        for (std::size_t r = 0; r < height; ++r) put_row(st.pixels.data() + r * row_bytes, r);
    }
    st.linearizer->finish();
    png_read_end(png, info);
    take_exif(st);
    return true;
}

}  // namespace

LinearImage decode_png(Bytes bytes, const std::string& name, const ReadOptions& options) {
    PngState st;
    st.name = &name;
    st.options = &options;
    st.input.bytes = bytes;
    st.image.info.source = name;
    st.image.info.format = "png";
    st.h.png =
        png_create_read_struct(PNG_LIBPNG_VER_STRING, &st.error, png_fail, png_ignore_warning);
    if (st.h.png == nullptr) throw DataError(concat(name, ": libpng could not start"));
    st.h.info = png_create_info_struct(st.h.png);
    if (st.h.info == nullptr) throw DataError(concat(name, ": libpng could not start"));
    // Ancillary-chunk errors (a bad CRC or profile in iCCP, say) drop the chunk; critical ones
    // (IHDR, IDAT) stay errors.
    png_set_benign_errors(st.h.png, 1);
    png_set_crc_action(st.h.png, PNG_CRC_DEFAULT, PNG_CRC_WARN_DISCARD);
    // The pixels are checked against the file size (deflate's ratio); this lifts libpng's own
    // one-million-pixel-per-side default to what kMaxImagePixels allows.
    png_set_user_limits(st.h.png, 0x7fffffffU, 0x7fffffffU);
    // png_body throws our own errors (never from inside libpng) and returns false after a
    // libpng error.
    if (!png_body(st))
        throw DataError(
            concat(name, ": corrupt or truncated PNG (libpng: ", st.error.message, ")"));
    const ExifFields exif = st.exif_block.empty() ? ExifFields{} : parse_exif(st.exif_block);
    apply_exif_exposure(exif, st.image.info);
    warn_orientation(exif.orientation, "EXIF", st.image.info);
    return std::move(st.image);
}

}  // namespace roughscope::image::detail
