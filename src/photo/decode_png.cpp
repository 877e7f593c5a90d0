// PNG photographs (read.hpp; docs/image.md "PNG"), decoded by io's PNG codec
// (src/io/png_codec.hpp, libpng in memory). Here: the colour types and depths a photograph may
// have, sBIT, the response evidence of the sRGB, iCCP and gAMA chunks and of EXIF, and the
// linear scale.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "decode.hpp"
#include "io/png_codec.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"

namespace roughscope::image::detail {

namespace {

namespace codec = io::codec;

// Deflate cannot expand data more than 1032:1.
constexpr std::uint64_t kDeflateMaxRatio = 1032;

// The response the chunks describe: sRGB, else a known iCCP profile, else gAMA.
Evidence chunk_evidence(const codec::PngHeader& h) {
    if (h.srgb) return {Response::Srgb, 0.0, "PNG sRGB chunk"};
    Evidence evidence;
    if (h.has_icc) {
        evidence = icc_evidence(Bytes(h.icc_profile),
                                concat("PNG iCCP profile ", quote_input(h.icc_name)));
        if (evidence.known()) return evidence;
    }
    if (h.gamma_fixed && *h.gamma_fixed > 0) {
        // gAMA holds the encoding exponent × 100000 (45455 for γ = 2.2).
        const double gamma = 100000.0 / static_cast<double>(*h.gamma_fixed);
        const std::string text = concat("PNG gAMA chunk ", std::to_string(*h.gamma_fixed));
        if (std::abs(gamma - 1.0) <= 0.01) return {Response::Linear, 0.0, text};
        return {Response::Gamma, gamma, text};
    }
    return evidence;
}

// An eXIf chunk as parse_exif takes it (the APP1 form: "Exif\0\0" then the TIFF structure).
ExifFields chunk_exif(const codec::PngHeader& h) {
    if (h.exif.empty()) return {};
    std::vector<std::uint8_t> block{'E', 'x', 'i', 'f', 0, 0};
    block.insert(block.end(), h.exif.begin(), h.exif.end());
    return parse_exif(block);
}

// The colour planes kept (alpha dropped); DataError for a palette image or another depth.
std::size_t colour_channels(const codec::PngHeader& h, const std::string& name) {
    std::size_t channels = 0;
    switch (static_cast<codec::PngColour>(h.colour_type)) {
        case codec::PngColour::Grey:
        case codec::PngColour::GreyAlpha:
            channels = 1;
            break;
        case codec::PngColour::Rgb:
        case codec::PngColour::Rgba:
            channels = 3;
            break;
        default:
            throw DataError(concat(name, ": PNG colour type ", std::to_string(h.colour_type),
                                   " (palette) is not supported; valid: grey, grey + alpha, "
                                   "RGB, RGBA"));
    }
    if (h.bit_depth != 8 && h.bit_depth != 16)
        throw DataError(concat(name, ": PNG of ", std::to_string(h.bit_depth),
                               "-bit samples is not supported; valid: 8 or 16 bits"));
    return channels;
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

// Every row through the linearizer: one row at a time, or the whole image first when it is
// interlaced or its sBIT codes need unscaling.
void read_pixels(codec::PngDecoder& png, Linearizer& lin) {
    const codec::PngHeader& h = png.header();
    const int depth = h.bit_depth;
    const std::size_t row_bytes = png.row_bytes();
    auto put_row = [&](const std::uint8_t* row, std::size_t r) {
        if (depth == 8)
            lin.put_pixels(row, r, h.samples, {0, 1, 2});
        else
            lin.put_pixels(reinterpret_cast<const std::uint16_t*>(row), r, h.samples, {0, 1, 2});
    };
    const bool whole = h.interlaced || h.significant_bits < depth;
    std::vector<std::uint8_t> pixels(whole ? row_bytes * h.height : row_bytes);
    if (!whole) {
        for (std::size_t r = 0; r < h.height; ++r) {
            png.read_rows(pixels.data(), 1);
            put_row(pixels.data(), r);
        }
        return;
    }
    png.read_image(pixels.data());
    if (h.significant_bits < depth) {
        if (depth == 8)
            unscale_significant<std::uint8_t>(pixels, depth, h.significant_bits);
        else
            unscale_significant<std::uint16_t>(pixels, depth, h.significant_bits);
    }
    for (std::size_t r = 0; r < h.height; ++r) put_row(pixels.data() + r * row_bytes, r);
}

}  // namespace

LinearImage decode_png(Bytes bytes, const std::string& name, const ReadOptions& options) {
    LinearImage image;
    image.info.source = name;
    image.info.format = "png";
    codec::PngDecoder png(bytes, name);
    const codec::PngHeader& h = png.read_header();
    Layout layout;
    layout.width = h.width;
    layout.height = h.height;
    layout.channels = colour_channels(h, name);
    layout.bits = h.bit_depth;
    layout.full_scale = static_cast<double>((1U << h.significant_bits) - 1U);
    check_pixel_count(name, h.width, h.height);
    check_expansion(
        name,
        std::uint64_t{h.width} * h.height * h.samples * static_cast<std::uint64_t>(h.bit_depth / 8),
        bytes.size(), kDeflateMaxRatio, "PNG header");
    Evidence evidence = chunk_evidence(h);
    if (!evidence.known()) {
        const Evidence from_exif = exif_color_space_evidence(chunk_exif(h));
        if (from_exif.known()) evidence = from_exif;
    }
    Linearizer lin(image, layout, evidence, options);
    read_pixels(png, lin);
    lin.finish();
    png.read_end();
    const ExifFields exif = chunk_exif(png.header());  // an eXIf chunk after the pixels too
    apply_exif_exposure(exif, image.info);
    warn_orientation(exif.orientation, "EXIF", image.info);
    return image;
}

}  // namespace roughscope::image::detail
