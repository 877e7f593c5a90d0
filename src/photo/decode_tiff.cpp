// TIFF photographs (read.hpp; docs/image.md "TIFF"), decoded by io's TIFF codec
// (src/io/tiff_codec.hpp, libtiff in memory, the bytes handed over as a memory map): 8/16-bit
// unsigned or 32-bit float samples, grey or RGB (extra samples such as alpha dropped), strips or
// tiles, contiguous or separate planes. Here: what a photograph may hold, the response evidence
// of the ICC profile and EXIF, and the linear scale. TIFF-structured camera RAW files (DNG, CR2,
// CFA or LinearRaw images, a first IFD that is a reduced-resolution preview) are left to
// decode_raw, after a check of their structure.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "decode.hpp"
#include "io/tiff_codec.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"

namespace roughscope::image::detail {

namespace {

namespace codec = io::codec;
namespace tiff = io::codec::tiff;

// A compressed TIFF is refused when its samples would need more than this many bytes per byte of
// file (LZW peaks near 1340:1 on constant data, deflate at 1032:1).
constexpr std::uint64_t kCompressedMaxRatio = 2048;

// A TIFF-structured camera RAW: a DNG, a CFA or LinearRaw image, or a first image that is a
// reduced-resolution preview.
bool is_raw(const codec::TiffHeader& h) {
    return h.dng ||
           (h.photometric && (*h.photometric == tiff::kPhotometricCfa ||
                              *h.photometric == tiff::kPhotometricLinearRaw)) ||
           (h.subfile_type & tiff::kFileTypeReducedImage) != 0;
}

// The photograph's layout from the header: grey or RGB planes of 8/16-bit unsigned or 32-bit
// float samples, within the pixel and expansion limits; DataError otherwise.
Layout photo_layout(const codec::TiffHeader& h, const std::string& name, std::size_t file_bytes) {
    if (!h.has_size)
        throw DataError(concat(name, ": TIFF without ImageWidth or ImageLength (corrupt)"));
    const std::uint16_t photometric = h.photometric.value_or(
        h.samples >= 3 ? tiff::kPhotometricRgb : tiff::kPhotometricMinIsBlack);
    std::size_t channels = 0;
    if (photometric == tiff::kPhotometricMinIsBlack)
        channels = 1;
    else if (photometric == tiff::kPhotometricRgb)
        channels = 3;
    else
        throw DataError(concat(name, ": TIFF photometric interpretation ",
                               std::to_string(photometric),
                               " is not supported; valid: 1 (grey, min-is-black) or 2 (RGB)"));
    if (h.samples < channels || h.samples > 16)
        throw DataError(concat(name, ": TIFF with ", std::to_string(h.samples),
                               " samples per pixel for ", channels == 1 ? "grey" : "RGB",
                               "; valid: ", std::to_string(channels), " to 16"));
    const bool is_float = h.sample_format == tiff::kSampleFormatFloat && h.bits == 32;
    const bool is_uint = (h.sample_format == tiff::kSampleFormatUint ||
                          h.sample_format == tiff::kSampleFormatVoid) &&
                         (h.bits == 8 || h.bits == 16);
    if (!is_float && !is_uint)
        throw DataError(concat(name, ": TIFF samples of ", std::to_string(h.bits),
                               " bits in sample format ", std::to_string(h.sample_format),
                               " are not supported; valid: 8- or 16-bit unsigned (format 1), "
                               "32-bit float (format 3)"));
    if (!h.codec_available)
        throw DataError(concat(name, ": TIFF compression ", std::to_string(h.compression),
                               " is not available in libtiff"));
    check_pixel_count(name, h.width, h.height);
    check_expansion(name, std::uint64_t{h.width} * h.height * h.samples * h.sample_bytes(),
                    file_bytes, h.compression == tiff::kCompressionNone ? 1 : kCompressedMaxRatio,
                    "TIFF header");
    Layout layout;
    layout.width = h.width;
    layout.height = h.height;
    layout.channels = channels;
    layout.bits = h.bits;
    layout.is_float = is_float;
    layout.full_scale = is_float ? 1.0 : static_cast<double>((1U << h.bits) - 1U);
    return layout;
}

// The response evidence (ICC profile, else EXIF ColorSpace), exposure and orientation.
Evidence read_metadata(codec::TiffDecoder& tif, ImageInfo& info) {
    const codec::TiffHeader& h = tif.header();
    Evidence evidence;
    if (!h.icc_profile.empty()) evidence = icc_evidence(Bytes(h.icc_profile), "TIFF ICC profile");
    ExifFields exif;
    if (h.has_exif) {
        const codec::TiffExif fields = tif.read_exif();
        exif.exposure_s = fields.exposure_s;
        exif.f_number = fields.f_number;
        exif.iso = fields.iso;
        exif.color_space = fields.color_space;
    }
    if (!evidence.known()) evidence = exif_color_space_evidence(exif);
    apply_exif_exposure(exif, info);
    if (h.orientation != tiff::kOrientationTopLeft)
        warn_orientation(static_cast<int>(h.orientation), "TIFF", info);
    return evidence;
}

// One row of samples (every sample of a pixel `stride` apart, or one plane) to the linearizer.
template <class T>
void put_samples(Linearizer& lin, const std::uint8_t* row, std::uint32_t y, int plane,
                 std::size_t stride) {
    const auto* samples = reinterpret_cast<const T*>(row);
    if (plane < 0)
        lin.put_pixels(samples, y, stride, {0, 1, 2});
    else
        lin.put(samples, y, 1, 0, static_cast<std::size_t>(plane));
}

}  // namespace

// A TIFF-structured camera RAW goes to LibRaw, whose TIFF parser trusts the file (Debian's LibRaw
// 0.20 reads out of bounds on some malformed directories). Its structure is checked here first:
// every directory reachable from the header (the IFD chain, SubIFDs, the EXIF and GPS IFDs) lies
// inside the file, has at most 1000 entries of a known type (1 to 13) whose values lie inside the
// file. Classic TIFF only; with any_version, whatever the two bytes after the byte order say
// (LibRaw parses every file that starts with II or MM as TIFF directories from offset 4).
RawTiffFacts check_raw_structure(Bytes bytes, const std::string& name, bool any_version) {
    auto fail = [&](const std::string& what) {
        throw DataError(concat(name, ": camera RAW with a corrupt TIFF structure (", what, ")"));
    };
    if (bytes.size() < 8) fail("no header");
    const bool little = bytes[0] == 'I';
    auto u16 = [&](std::size_t at) {
        return little ? static_cast<std::uint32_t>(bytes[at] | (bytes[at + 1] << 8))
                      : static_cast<std::uint32_t>((bytes[at] << 8) | bytes[at + 1]);
    };
    auto u32 = [&](std::size_t at) {
        return little ? (std::uint32_t{bytes[at]} | std::uint32_t{bytes[at + 1]} << 8 |
                         std::uint32_t{bytes[at + 2]} << 16 | std::uint32_t{bytes[at + 3]} << 24)
                      : (std::uint32_t{bytes[at]} << 24 | std::uint32_t{bytes[at + 1]} << 16 |
                         std::uint32_t{bytes[at + 2]} << 8 | std::uint32_t{bytes[at + 3]});
    };
    if (!any_version && u16(2) != 42) fail("BigTIFF or an unknown version");
    static constexpr std::uint32_t kTypeBytes[14] = {0, 1, 1, 2, 4, 8, 1, 1, 2, 4, 8, 4, 8, 4};
    std::vector<std::uint32_t> pending = {u32(4)};
    std::vector<std::uint32_t> seen;
    // Per tag (ExposureTime, FNumber): seen with the value 0, seen with another value.
    bool zero[2] = {false, false};
    bool nonzero[2] = {false, false};
    while (!pending.empty()) {
        const std::uint32_t at = pending.back();
        pending.pop_back();
        if (at == 0 || std::find(seen.begin(), seen.end(), at) != seen.end()) continue;
        if (seen.size() >= 64) fail("more than 64 directories");
        seen.push_back(at);
        if (std::uint64_t{at} + 2 > bytes.size()) fail("a directory outside the file");
        const std::uint32_t entries = u16(at);
        if (entries > 1000) fail("a directory of more than 1000 entries");
        if (std::uint64_t{at} + 2 + 12ULL * entries + 4 > bytes.size())
            fail("a directory running past the end of the file");
        for (std::uint32_t k = 0; k < entries; ++k) {
            const std::size_t entry = at + 2 + 12 * std::size_t{k};
            const std::uint32_t tag = u16(entry);
            const std::uint32_t type = u16(entry + 2);
            const std::uint32_t count = u32(entry + 4);
            if (type == 0 || type > 13)
                fail(
                    concat("tag ", std::to_string(tag), " of unknown type ", std::to_string(type)));
            const std::uint64_t size = std::uint64_t{count} * kTypeBytes[type];
            const std::uint64_t value_at = size <= 4 ? entry + 8 : u32(entry + 8);
            if (value_at + size > bytes.size())
                fail(concat("tag ", std::to_string(tag), " values outside the file"));
            if ((tag == 33434 || tag == 33437) && type == 5 && count >= 1) {  // RATIONAL
                const std::size_t which = tag == 33434 ? 0 : 1;
                (u32(static_cast<std::size_t>(value_at)) == 0 ? zero : nonzero)[which] = true;
            }
            const bool is_ifd = tag == 330 || tag == 34665 || tag == 34853;  // SubIFDs, EXIF, GPS
            if (is_ifd && (type == 4 || type == 13))
                for (std::uint32_t i = 0; i < std::min<std::uint32_t>(count, 64); ++i)
                    pending.push_back(u32(static_cast<std::size_t>(value_at) + 4 * std::size_t{i}));
        }
        pending.push_back(u32(at + 2 + 12 * std::size_t{entries}));  // the next IFD
    }
    RawTiffFacts facts;
    facts.exposure_time_zero = zero[0] && !nonzero[0];
    facts.f_number_zero = zero[1] && !nonzero[1];
    return facts;
}

std::optional<LinearImage> decode_tiff(Bytes bytes, const std::string& name,
                                       const ReadOptions& options) {
    // Canon CR2: a TIFF header followed by "CR" and the format's version.
    if (bytes.size() >= 10 && bytes[8] == 'C' && bytes[9] == 'R') {
        check_raw_structure(bytes, name, false);
        return std::nullopt;
    }
    codec::TiffDecoder tif(bytes, name);
    if (!tif.ok())
        throw DataError(concat(name, ": corrupt or truncated TIFF (", tif.reason(), ")"));
    const codec::TiffHeader& h = tif.header();
    if (is_raw(h)) {
        check_raw_structure(bytes, name, false);
        return std::nullopt;
    }
    const Layout layout = photo_layout(h, name, bytes.size());
    LinearImage image;
    image.info.source = name;
    image.info.format = "tiff";
    const Evidence evidence = read_metadata(tif, image.info);
    Linearizer lin(image, layout, evidence, options);
    tif.read_rows(
        [&](const std::uint8_t* row, std::uint32_t y, int plane) {
            if (layout.is_float)
                put_samples<float>(lin, row, y, plane, h.samples);
            else if (layout.bits == 16)
                put_samples<std::uint16_t>(lin, row, y, plane, h.samples);
            else
                put_samples<std::uint8_t>(lin, row, y, plane, h.samples);
        },
        layout.channels);
    lin.finish();
    return image;
}

}  // namespace roughscope::image::detail
