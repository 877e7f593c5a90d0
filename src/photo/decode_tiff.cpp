// TIFF photographs through libtiff, from memory (read.hpp; docs/image.md "TIFF"): 8/16-bit
// unsigned or 32-bit float samples, grey or RGB (extra samples such as alpha dropped), strips or
// tiles, contiguous or separate planes. The file's bytes are handed to libtiff as a memory map (no
// copy of uncompressed strips). libtiff's messages go to a per-file handler, never to stderr.
// TIFF-structured camera RAW files (DNG, CR2, CFA or LinearRaw images, a first IFD that is a
// reduced-resolution preview) are left to decode_raw.
#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include <tiffio.h>

#include "decode.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"

namespace roughscope::image::detail {

namespace {

constexpr std::uint16_t kPhotometricLinearRaw = 34892;  // DNG
// A compressed TIFF is refused when its samples would need more than this many bytes per byte of
// file (LZW peaks near 1340:1 on constant data, deflate at 1032:1).
constexpr std::uint64_t kCompressedMaxRatio = 2048;

struct TiffMemory {
    Bytes in;
    std::uint64_t pos = 0;
};

struct TiffError {
    std::string message;
};

tmsize_t tiff_read(thandle_t handle, void* buffer, tmsize_t length) {
    auto* f = static_cast<TiffMemory*>(handle);
    const std::uint64_t size = f->in.size();
    if (length <= 0 || f->pos >= size) return 0;
    const auto n = static_cast<std::size_t>(
        std::min<std::uint64_t>(static_cast<std::uint64_t>(length), size - f->pos));
    std::memcpy(buffer, f->in.data() + f->pos, n);
    f->pos += n;
    return static_cast<tmsize_t>(n);
}

tmsize_t tiff_write(thandle_t, void*, tmsize_t) { return -1; }

toff_t tiff_seek(thandle_t handle, toff_t offset, int whence) {
    auto* f = static_cast<TiffMemory*>(handle);
    std::uint64_t base = 0;
    if (whence == SEEK_CUR) base = f->pos;
    if (whence == SEEK_END) base = f->in.size();
    const std::uint64_t target = base + offset;
    if (target < base) return static_cast<toff_t>(-1);  // wrapped around
    f->pos = target;
    return target;
}

int tiff_close(thandle_t) { return 0; }
toff_t tiff_size(thandle_t handle) { return static_cast<TiffMemory*>(handle)->in.size(); }

// The bytes are already in memory: "mapping" them hands libtiff the pointer (read only).
int tiff_map(thandle_t handle, void** base, toff_t* size) {
    auto* f = static_cast<TiffMemory*>(handle);
    *base = const_cast<std::uint8_t*>(f->in.data());
    *size = f->in.size();
    return 1;
}
void tiff_unmap(thandle_t, void*, toff_t) {}

int tiff_on_error(TIFF*, void* user, const char* module, const char* format, va_list args) {
    auto* e = static_cast<TiffError*>(user);
    if (e->message.empty()) {
        char text[256];
        std::vsnprintf(text, sizeof text, format, args);
        if (module != nullptr && *module != '\0') e->message.append(module).append(": ");
        e->message.append(text);
    }
    return 1;  // handled: no global handler, nothing printed
}

int tiff_on_warning(TIFF*, void*, const char*, const char*, va_list) { return 1; }

class TiffFile {
  public:
    TiffFile(const std::string& name, TiffMemory& memory, TiffError& error) {
        TIFFOpenOptions* options = TIFFOpenOptionsAlloc();
        TIFFOpenOptionsSetErrorHandlerExtR(options, tiff_on_error, &error);
        TIFFOpenOptionsSetWarningHandlerExtR(options, tiff_on_warning, nullptr);
        TIFFOpenOptionsSetMaxSingleMemAlloc(options, tmsize_t{1} << 30);
        tiff_ = TIFFClientOpenExt(name.c_str(), "r", &memory, tiff_read, tiff_write, tiff_seek,
                                  tiff_close, tiff_size, tiff_map, tiff_unmap, options);
        TIFFOpenOptionsFree(options);
    }
    ~TiffFile() {
        if (tiff_ != nullptr) TIFFClose(tiff_);
    }
    TiffFile(const TiffFile&) = delete;
    TiffFile& operator=(const TiffFile&) = delete;
    TIFF* get() const { return tiff_; }

  private:
    TIFF* tiff_ = nullptr;
};

std::string reason(const TiffError& error) {
    return error.message.empty() ? std::string("libtiff reported no detail") : error.message;
}

// An EXIF rational tag: libtiff hands it out as a float or a double depending on its version
// (TIFFFieldSetGetSize says which).
std::optional<double> exif_rational(TIFF* tif, std::uint32_t tag) {
    const TIFFField* field = TIFFFieldWithTag(tif, tag);
    if (field == nullptr) return std::nullopt;
    double value = 0.0;
    if (TIFFFieldSetGetSize(field) == 4) {
        float f = 0.0F;
        if (TIFFGetField(tif, tag, &f) != 1) return std::nullopt;
        value = f;
    } else if (TIFFFieldSetGetSize(field) == 8) {
        if (TIFFGetField(tif, tag, &value) != 1) return std::nullopt;
    } else {
        return std::nullopt;
    }
    if (!(std::isfinite(value) && value > 0.0)) return std::nullopt;
    return value;
}

ExifFields read_exif_ifd(TIFF* tif) {
    ExifFields fields;
    toff_t offset = 0;
    if (TIFFGetField(tif, TIFFTAG_EXIFIFD, &offset) != 1 || offset == 0) return fields;
    if (TIFFReadEXIFDirectory(tif, offset) != 1) return fields;
    fields.exposure_s = exif_rational(tif, EXIFTAG_EXPOSURETIME);
    fields.f_number = exif_rational(tif, EXIFTAG_FNUMBER);
    std::uint16_t count = 0;
    std::uint16_t* iso = nullptr;
    if (TIFFGetField(tif, EXIFTAG_ISOSPEEDRATINGS, &count, &iso) == 1 && count >= 1 &&
        iso != nullptr && iso[0] > 0)
        fields.iso = iso[0];
    std::uint16_t color_space = 0;
    if (TIFFGetField(tif, EXIFTAG_COLORSPACE, &color_space) == 1) fields.color_space = color_space;
    return fields;
}

// One plane (or every sample, contiguous) of a band of rows into `band`, `samples` samples per
// pixel, from tiles.
struct TileReader {
    TIFF* tif;
    const std::string& name;
    const TiffError& error;
    std::uint32_t width, height, tile_width, tile_height;
    std::size_t samples, sample_bytes;
    bool separate;
    std::vector<std::uint8_t> tile;

    void read_band(std::uint32_t y0, std::vector<std::uint8_t>& band) {
        const std::uint32_t rows = std::min(tile_height, height - y0);
        const std::size_t pixel_bytes = samples * sample_bytes;
        for (std::uint32_t x0 = 0; x0 < width; x0 += tile_width) {
            const std::uint32_t cols = std::min(tile_width, width - x0);
            const std::size_t planes = separate ? samples : 1;
            for (std::size_t s = 0; s < planes; ++s) {
                if (TIFFReadTile(tif, tile.data(), x0, y0, 0, static_cast<std::uint16_t>(s)) < 0)
                    throw DataError(concat(name, ": TIFF tile at column ", std::to_string(x0),
                                           ", row ", std::to_string(y0), ": truncated or corrupt (",
                                           reason(error), ")"));
                for (std::uint32_t r = 0; r < rows; ++r) {
                    std::uint8_t* out = band.data() + (std::size_t{r} * width + x0) * pixel_bytes;
                    if (!separate) {
                        const std::uint8_t* in =
                            tile.data() + std::size_t{r} * tile_width * pixel_bytes;
                        std::memcpy(out, in, std::size_t{cols} * pixel_bytes);
                        continue;
                    }
                    const std::uint8_t* in =
                        tile.data() + std::size_t{r} * tile_width * sample_bytes;
                    for (std::uint32_t x = 0; x < cols; ++x)
                        std::memcpy(out + x * pixel_bytes + s * sample_bytes, in + x * sample_bytes,
                                    sample_bytes);
                }
            }
        }
    }
};

void put_row(Linearizer& lin, int bits, bool is_float, const std::uint8_t* row, std::size_t r,
             std::size_t stride) {
    if (is_float)
        lin.put_pixels(reinterpret_cast<const float*>(row), r, stride, {0, 1, 2});
    else if (bits == 16)
        lin.put_pixels(reinterpret_cast<const std::uint16_t*>(row), r, stride, {0, 1, 2});
    else
        lin.put_pixels(row, r, stride, {0, 1, 2});
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
    TiffMemory memory{bytes, 0};
    TiffError error;
    TiffFile file(name, memory, error);
    TIFF* tif = file.get();
    if (tif == nullptr)
        throw DataError(concat(name, ": corrupt or truncated TIFF (", reason(error), ")"));

    void* dng_version = nullptr;
    std::uint16_t photometric = 0;
    const bool has_photometric = TIFFGetField(tif, TIFFTAG_PHOTOMETRIC, &photometric) == 1;
    std::uint32_t subfile = 0;
    TIFFGetField(tif, TIFFTAG_SUBFILETYPE, &subfile);
    if (TIFFGetField(tif, TIFFTAG_DNGVERSION, &dng_version) == 1 ||
        (has_photometric &&
         (photometric == PHOTOMETRIC_CFA || photometric == kPhotometricLinearRaw)) ||
        (subfile & FILETYPE_REDUCEDIMAGE) != 0) {
        check_raw_structure(bytes, name, false);
        return std::nullopt;
    }

    std::uint32_t width = 0;
    std::uint32_t height = 0;
    if (TIFFGetField(tif, TIFFTAG_IMAGEWIDTH, &width) != 1 ||
        TIFFGetField(tif, TIFFTAG_IMAGELENGTH, &height) != 1)
        throw DataError(concat(name, ": TIFF without ImageWidth or ImageLength (corrupt)"));
    std::uint16_t bits = 1;
    std::uint16_t samples = 1;
    std::uint16_t format = SAMPLEFORMAT_UINT;
    std::uint16_t planar = PLANARCONFIG_CONTIG;
    std::uint16_t compression = COMPRESSION_NONE;
    std::uint16_t orientation = ORIENTATION_TOPLEFT;
    TIFFGetFieldDefaulted(tif, TIFFTAG_BITSPERSAMPLE, &bits);
    TIFFGetFieldDefaulted(tif, TIFFTAG_SAMPLESPERPIXEL, &samples);
    TIFFGetFieldDefaulted(tif, TIFFTAG_SAMPLEFORMAT, &format);
    TIFFGetFieldDefaulted(tif, TIFFTAG_PLANARCONFIG, &planar);
    TIFFGetFieldDefaulted(tif, TIFFTAG_COMPRESSION, &compression);
    TIFFGetFieldDefaulted(tif, TIFFTAG_ORIENTATION, &orientation);
    if (!has_photometric) photometric = samples >= 3 ? PHOTOMETRIC_RGB : PHOTOMETRIC_MINISBLACK;

    std::size_t channels = 0;
    if (photometric == PHOTOMETRIC_MINISBLACK)
        channels = 1;
    else if (photometric == PHOTOMETRIC_RGB)
        channels = 3;
    else
        throw DataError(concat(name, ": TIFF photometric interpretation ",
                               std::to_string(photometric),
                               " is not supported; valid: 1 (grey, min-is-black) or 2 (RGB)"));
    if (samples < channels || samples > 16)
        throw DataError(concat(name, ": TIFF with ", std::to_string(samples),
                               " samples per pixel for ", channels == 1 ? "grey" : "RGB",
                               "; valid: ", std::to_string(channels), " to 16"));
    const bool is_float = format == SAMPLEFORMAT_IEEEFP && bits == 32;
    const bool is_uint =
        (format == SAMPLEFORMAT_UINT || format == SAMPLEFORMAT_VOID) && (bits == 8 || bits == 16);
    if (!is_float && !is_uint)
        throw DataError(concat(name, ": TIFF samples of ", std::to_string(bits),
                               " bits in sample format ", std::to_string(format),
                               " are not supported; valid: 8- or 16-bit unsigned (format 1), "
                               "32-bit float (format 3)"));
    if (TIFFIsCODECConfigured(compression) == 0)
        throw DataError(concat(name, ": TIFF compression ", std::to_string(compression),
                               " is not available in libtiff"));
    check_pixel_count(name, width, height);
    const std::size_t sample_bytes = bits / 8U;
    const std::uint64_t image_bytes = std::uint64_t{width} * height * samples * sample_bytes;
    check_expansion(name, image_bytes, bytes.size(),
                    compression == COMPRESSION_NONE ? 1 : kCompressedMaxRatio, "TIFF header");

    LinearImage image;
    image.info.source = name;
    image.info.format = "tiff";
    Evidence evidence;
    std::uint32_t icc_bytes = 0;
    void* icc = nullptr;
    if (TIFFGetField(tif, TIFFTAG_ICCPROFILE, &icc_bytes, &icc) == 1 && icc != nullptr)
        evidence = icc_evidence(Bytes(static_cast<const std::uint8_t*>(icc), icc_bytes),
                                "TIFF ICC profile");
    const bool has_exif = [&] {
        toff_t offset = 0;
        return TIFFGetField(tif, TIFFTAG_EXIFIFD, &offset) == 1 && offset != 0;
    }();
    ExifFields exif;
    if (has_exif) {
        exif = read_exif_ifd(tif);
        if (TIFFSetDirectory(tif, 0) != 1)
            throw DataError(concat(name,
                                   ": TIFF: cannot return to the first image after its EXIF "
                                   "directory (",
                                   reason(error), ")"));
    }
    if (!evidence.known()) evidence = exif_color_space_evidence(exif);
    apply_exif_exposure(exif, image.info);
    if (orientation != ORIENTATION_TOPLEFT)
        warn_orientation(static_cast<int>(orientation), "TIFF", image.info);

    Layout layout;
    layout.width = width;
    layout.height = height;
    layout.channels = channels;
    layout.bits = bits;
    layout.is_float = is_float;
    layout.full_scale = is_float ? 1.0 : static_cast<double>((1U << bits) - 1U);
    Linearizer lin(image, layout, evidence, options);

    const bool separate = planar == PLANARCONFIG_SEPARATE && samples > 1;
    const std::size_t pixel_bytes = samples * sample_bytes;
    if (TIFFIsTiled(tif) != 0) {
        std::uint32_t tile_width = 0;
        std::uint32_t tile_height = 0;
        TIFFGetField(tif, TIFFTAG_TILEWIDTH, &tile_width);
        TIFFGetField(tif, TIFFTAG_TILELENGTH, &tile_height);
        const tmsize_t tile_size = TIFFTileSize(tif);
        const std::uint64_t needed =
            std::uint64_t{tile_width} * tile_height * (separate ? sample_bytes : pixel_bytes);
        if (tile_width == 0 || tile_height == 0 || tile_size <= 0 ||
            static_cast<std::uint64_t>(tile_size) < needed ||
            static_cast<std::uint64_t>(tile_size) > 4 * image_bytes + (1U << 20))
            throw DataError(concat(name, ": TIFF tiles of ", std::to_string(tile_width), " x ",
                                   std::to_string(tile_height),
                                   " pixels do not fit the image (corrupt)"));
        TileReader reader{tif,         name,    error,        width,    height, tile_width,
                          tile_height, samples, sample_bytes, separate, {}};
        reader.tile.resize(static_cast<std::size_t>(tile_size));
        std::vector<std::uint8_t> band(std::size_t{std::min(tile_height, height)} * width *
                                       pixel_bytes);
        for (std::uint32_t y0 = 0; y0 < height; y0 += tile_height) {
            reader.read_band(y0, band);
            const std::uint32_t rows = std::min(tile_height, height - y0);
            for (std::uint32_t r = 0; r < rows; ++r)
                put_row(lin, bits, is_float, band.data() + std::size_t{r} * width * pixel_bytes,
                        y0 + r, samples);
        }
    } else {
        const tmsize_t line_size = TIFFScanlineSize(tif);
        const std::size_t line_needed =
            std::size_t{width} * (separate ? sample_bytes : pixel_bytes);
        if (line_size <= 0 || static_cast<std::size_t>(line_size) < line_needed)
            throw DataError(
                concat(name, ": TIFF scanline size does not match its width (corrupt)"));
        std::vector<std::uint8_t> line(static_cast<std::size_t>(line_size));
        const std::size_t planes = separate ? channels : 1;
        for (std::size_t s = 0; s < planes; ++s) {
            for (std::uint32_t r = 0; r < height; ++r) {
                if (TIFFReadScanline(tif, line.data(), r, static_cast<std::uint16_t>(s)) < 0)
                    throw DataError(concat(name, ": TIFF row ", std::to_string(r),
                                           ": truncated or corrupt (", reason(error), ")"));
                if (separate) {
                    if (is_float)
                        lin.put(reinterpret_cast<const float*>(line.data()), r, 1, 0, s);
                    else if (bits == 16)
                        lin.put(reinterpret_cast<const std::uint16_t*>(line.data()), r, 1, 0, s);
                    else
                        lin.put(line.data(), r, 1, 0, s);
                } else {
                    put_row(lin, bits, is_float, line.data(), r, samples);
                }
            }
        }
    }
    lin.finish();
    return image;
}

}  // namespace roughscope::image::detail
