// Height images (docs/height-files.md, "PNG and TIFF"): 8/16-bit grey PNG, and TIFF with
// uint8/uint16 or 32/64-bit IEEE float samples, through io's codecs (src/io/png_codec.hpp,
// tiff_codec.hpp: libpng and libtiff in memory). Integer samples are counts: heights =
// z_scale_um × count (HeightReadOptions::z_scale_um, required); float samples are µm, NaN or
// ±inf = missing. Neither format carries the spacings here: they come from the options (1 µm by
// default, noted in the map's title).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "io/png_codec.hpp"
#include "io/tiff_codec.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/surface/formats.hpp"
#include "tab_common.hpp"

namespace roughscope::surface::formats {

namespace {

namespace codec = io::codec;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Deflate cannot expand data more than 1032:1: a PNG whose pixels would need more than this
// many bytes per byte of file is refused before any allocation (decompression bombs).
constexpr std::size_t kPngMaxExpansion = 1032;

double z_scale_for(const HeightReadOptions& options, const std::string& name,
                   std::string_view what) {
    if (!options.z_scale_um) {
        std::string message = name;
        message.append(": ").append(what).append(
            " holds integer counts; give z_scale_um (heights = z_scale_um x count, "
            "a finite value > 0 um)");
        throw InvalidArgument(message);
    }
    check::positive("z_scale_um", *options.z_scale_um, " um");
    return *options.z_scale_um;
}

double write_z_scale(const HeightWriteOptions& options, std::string_view what) {
    if (!options.z_scale_um) {
        std::string message(what);
        message.append(" stores integer counts; give z_scale_um (um per count, > 0)");
        throw InvalidArgument(message);
    }
    check::positive("z_scale_um", *options.z_scale_um, " um");
    return *options.z_scale_um;
}

HeightMap image_map(std::size_t nx, std::size_t ny, const HeightReadOptions& options) {
    const tab::Spacings s = tab::spacings_from(options);
    HeightMap map;
    map.nx = nx;
    map.ny = ny;
    map.dx_um = s.dx_um;
    map.dy_um = s.dy_um;
    if (s.assumed) map.title = "(dx = dy = 1 um assumed: the image holds no spacing)";
    return map;
}

}  // namespace

HeightMap decode_png(std::string_view bytes, const std::string& name,
                     const HeightReadOptions& options) {
    const double z_scale = z_scale_for(options, name, "a PNG height image");
    static constexpr std::string_view kSignature("\x89PNG\r\n\x1a\n", 8);
    if (bytes.substr(0, 8) != kSignature) {
        throw tab::error_at_offset(name, 0, "not a PNG file (the 8-byte PNG signature is missing)");
    }
    auto check = [&](const codec::PngHeader& h) {
        if (h.colour_type != static_cast<int>(codec::PngColour::Grey) ||
            (h.bit_depth != 8 && h.bit_depth != 16)) {
            throw tab::error_at_offset(name, 16,
                                       "PNG colour type " + std::to_string(h.colour_type) +
                                           " with " + std::to_string(h.bit_depth) +
                                           "-bit samples: a height image is 8- or 16-bit grey "
                                           "(colour type 0)");
        }
        tab::check_grid_size(name, h.width, h.height, "PNG header");
        const std::size_t row_bytes =
            std::size_t{h.width} * static_cast<std::size_t>(h.bit_depth) / 8;
        if (row_bytes * h.height / kPngMaxExpansion > bytes.size()) {
            throw tab::error_at_offset(
                name, 16,
                "PNG header asks for " + std::to_string(h.width) + " x " +
                    std::to_string(h.height) + " pixels, more than a file of " +
                    std::to_string(bytes.size()) +
                    " bytes can hold at deflate's largest compression ratio (1032:1)");
        }
    };
    codec::ImageBuffer image;
    try {
        image = codec::decode_png(codec::as_bytes(bytes), name, check);
    } catch (const codec::PngError& e) {
        throw tab::error_at_offset(name, e.offset(), "PNG: " + e.detail());
    }
    HeightMap map = image_map(image.width, image.height, options);
    map.heights_um.resize(image.width * image.height);
    for (std::size_t iy = 0; iy < image.height; ++iy)
        for (std::size_t ix = 0; ix < image.width; ++ix)
            map.heights_um[iy * image.width + ix] = z_scale * image.sample(ix, iy);
    return tab::finish(std::move(map), name);
}

std::string encode_png(const HeightMap& map, const HeightWriteOptions& options) {
    const double z_scale = write_z_scale(options, "png: a 16-bit PNG");
    if (map.nx > 0x7fffffffU || map.ny > 0x7fffffffU) {
        throw InvalidArgument("png: at most 2^31 - 1 pixels per side");
    }
    std::vector<std::uint16_t> counts(map.size());
    for (std::size_t i = 0; i < map.size(); ++i) {
        counts[i] =
            static_cast<std::uint16_t>(tab::count_for(map.heights_um[i], z_scale, 65535, i, "png"));
    }
    return codec::encode_png({counts.data(), map.nx, map.ny, 1, {16, false}, 0});
}

HeightMap decode_tiff(std::string_view bytes, const std::string& name,
                      const HeightReadOptions& options) {
    if (bytes.size() < 8 || !(bytes.substr(0, 4) == std::string_view("II*\0", 4) ||
                              bytes.substr(0, 4) == std::string_view("MM\0*", 4) ||
                              bytes.substr(0, 4) == std::string_view("II+\0", 4) ||
                              bytes.substr(0, 4) == std::string_view("MM\0+", 4))) {
        throw tab::error_at_offset(name, 0,
                                   "not a TIFF file (it must start with II*\\0 or MM\\0*)");
    }
    codec::TiffDecoder tiff(codec::as_bytes(bytes), name, false);
    if (!tiff.ok()) {
        throw DataError(name + ": not a readable TIFF: " + tiff.reason());
    }
    const codec::TiffHeader& h = tiff.header();
    if (!h.has_size) {
        throw DataError(name + ": TIFF without ImageWidth/ImageLength");
    }
    if (h.samples != 1) {
        throw DataError(name + ": TIFF with " + std::to_string(h.samples) +
                        " samples per pixel: a height image has 1 (grey)");
    }
    const bool is_float =
        h.sample_format == codec::tiff::kSampleFormatFloat && (h.bits == 32 || h.bits == 64);
    const bool is_uint =
        h.sample_format == codec::tiff::kSampleFormatUint && (h.bits == 8 || h.bits == 16);
    if (!is_float && !is_uint) {
        throw DataError(name + ": TIFF samples of " + std::to_string(h.bits) +
                        " bits in sample format " + std::to_string(h.sample_format) +
                        ": a height image has uint8/uint16 (format 1) or 32/64-bit float "
                        "(format 3) samples");
    }
    if (h.tiled) throw DataError(name + ": tiled TIFF is not supported (strips only)");
    const double z_scale = is_uint ? z_scale_for(options, name, "an integer TIFF") : 1.0;
    tab::check_grid_size(name, h.width, h.height, "TIFF header");
    // Strips may share their compressed data, so a file of a few hundred bytes can claim
    // gigabytes of rows. No codec of libtiff packs real samples beyond 4096:1 (deflate ≤ 1032:1,
    // an LZW code < 4096 bytes), so more than 4096 × the file (+ 1 MiB) is refused before any
    // row is decoded.
    const double decoded_bytes = static_cast<double>(h.width) * static_cast<double>(h.height) *
                                 static_cast<double>(h.sample_bytes());
    const double most_bytes = 4096.0 * static_cast<double>(bytes.size()) + 1048576.0;
    if (decoded_bytes > most_bytes)
        throw DataError(name + ": the TIFF header's " + std::to_string(h.width) + " x " +
                        std::to_string(h.height) + " samples of " + std::to_string(h.bits) +
                        " bits are more than 4096 times the file's " +
                        std::to_string(bytes.size()) +
                        " bytes: no compression packs real heights that far (a damaged or "
                        "crafted file)");
    HeightMap map = image_map(h.width, h.height, options);
    const codec::SampleType type{h.bits, is_float};
    // The map grows row by row as rows decode, so a header that lies about its size costs no
    // more memory than the data that is really there.
    tiff.read_rows(
        [&](const std::uint8_t* samples, std::uint32_t, int) {
            const std::size_t base = map.heights_um.size();
            map.heights_um.resize(base + h.width);
            double* row = map.heights_um.data() + base;
            for (std::size_t ix = 0; ix < h.width; ++ix) {
                const double v =
                    z_scale * codec::ImageBuffer::sample_at(samples + ix * type.bytes(), type);
                row[ix] = std::isinf(v) ? kNaN : v;
            }
        },
        1);
    return tab::finish(std::move(map), name);
}

std::string encode_tiff(const HeightMap& map, const HeightWriteOptions& options) {
    const bool as_float = options.tiff_float;
    const double z_scale = as_float ? 1.0 : write_z_scale(options, "tiff: a uint16 TIFF");
    if (map.nx > 0xffffffffU || map.ny > 0xffffffffU) {
        throw InvalidArgument("tiff: at most 2^32 - 1 pixels per side");
    }
    // Samples first (the checks may throw), then libtiff.
    if (as_float) {
        std::vector<float> floats(map.size());
        for (std::size_t i = 0; i < map.size(); ++i) {
            floats[i] = tab::float_sample(map.heights_um[i], i, "tiff float32");
        }
        return codec::encode_tiff({floats.data(), map.nx, map.ny, 1, {32, true}, 0});
    }
    std::vector<std::uint16_t> counts(map.size());
    for (std::size_t i = 0; i < map.size(); ++i) {
        counts[i] = static_cast<std::uint16_t>(
            tab::count_for(map.heights_um[i], z_scale, 65535, i, "tiff uint16"));
    }
    return codec::encode_tiff({counts.data(), map.nx, map.ny, 1, {16, false}, 0});
}

}  // namespace roughscope::surface::formats
