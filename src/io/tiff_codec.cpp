// TIFF through libtiff, in memory (tiff_codec.hpp).
#include "io/tiff_codec.hpp"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string_view>
#include <utility>

#include <tiffio.h>

#include "roughscope/core/text.hpp"

namespace roughscope::io::codec {

namespace {

// The file libtiff reads (bytes) or writes (out), and where it is.
struct Memory {
    Bytes in;
    std::string* out = nullptr;
    std::uint64_t pos = 0;
    bool map = false;

    std::uint64_t size() const { return out != nullptr ? out->size() : in.size(); }
    const std::uint8_t* data() const {
        return out != nullptr ? reinterpret_cast<const std::uint8_t*>(out->data()) : in.data();
    }
};

tmsize_t memory_read(thandle_t handle, void* buffer, tmsize_t length) {
    auto* f = static_cast<Memory*>(handle);
    const std::uint64_t size = f->size();
    if (length <= 0 || f->pos >= size) return 0;
    const auto n = static_cast<std::size_t>(
        std::min<std::uint64_t>(static_cast<std::uint64_t>(length), size - f->pos));
    std::memcpy(buffer, f->data() + f->pos, n);
    f->pos += n;
    return static_cast<tmsize_t>(n);
}

tmsize_t memory_write(thandle_t handle, void* buffer, tmsize_t length) {
    auto* f = static_cast<Memory*>(handle);
    if (f->out == nullptr || length < 0) return -1;
    const auto n = static_cast<std::size_t>(length);
    if (f->out->size() < f->pos + n) f->out->resize(static_cast<std::size_t>(f->pos + n));
    std::memcpy(f->out->data() + f->pos, buffer, n);
    f->pos += n;
    return length;
}

toff_t memory_seek(thandle_t handle, toff_t offset, int whence) {
    auto* f = static_cast<Memory*>(handle);
    std::uint64_t base = 0;
    if (whence == SEEK_CUR) base = f->pos;
    if (whence == SEEK_END) base = f->size();
    const std::uint64_t target = base + offset;
    if (target < base) return static_cast<toff_t>(-1);  // wrapped around
    f->pos = target;
    return target;
}

int memory_close(thandle_t) { return 0; }
toff_t memory_size(thandle_t handle) { return static_cast<Memory*>(handle)->size(); }

// Bytes already in memory: "mapping" them hands libtiff the pointer (read only).
int memory_map(thandle_t handle, void** base, toff_t* size) {
    auto* f = static_cast<Memory*>(handle);
    if (!f->map || f->out != nullptr) return 0;
    *base = const_cast<std::uint8_t*>(f->in.data());
    *size = f->in.size();
    return 1;
}
void memory_unmap(thandle_t, void*, toff_t) {}

int on_error(TIFF*, void* user, const char* module, const char* format, va_list args) {
    auto* message = static_cast<std::string*>(user);
    if (message->empty()) {
        char text[256];
        std::vsnprintf(text, sizeof text, format, args);
        if (module != nullptr && *module != '\0') message->append(module).append(": ");
        message->append(text);
    }
    return 1;  // handled: no global handler, nothing printed
}

int on_warning(TIFF*, void*, const char*, const char*, va_list) { return 1; }

// A TIFF opened on memory, closed on scope exit; `message` keeps libtiff's first error.
class TiffHandle {
  public:
    TiffHandle(const char* name, const char* mode, Memory& memory, std::string& message) {
        TIFFOpenOptions* options = TIFFOpenOptionsAlloc();
        TIFFOpenOptionsSetErrorHandlerExtR(options, on_error, &message);
        TIFFOpenOptionsSetWarningHandlerExtR(options, on_warning, nullptr);
        TIFFOpenOptionsSetMaxSingleMemAlloc(options, tmsize_t{1} << 30);
        tiff_ = TIFFClientOpenExt(name, mode, &memory, memory_read, memory_write, memory_seek,
                                  memory_close, memory_size, memory_map, memory_unmap, options);
        TIFFOpenOptionsFree(options);
    }
    ~TiffHandle() {
        if (tiff_ != nullptr) TIFFClose(tiff_);
    }
    TiffHandle(const TiffHandle&) = delete;
    TiffHandle& operator=(const TiffHandle&) = delete;
    TIFF* get() const { return tiff_; }

  private:
    TIFF* tiff_ = nullptr;
};

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

TiffHeader read_header(TIFF* tif) {
    TiffHeader h;
    h.has_size = TIFFGetField(tif, TIFFTAG_IMAGEWIDTH, &h.width) == 1 &&
                 TIFFGetField(tif, TIFFTAG_IMAGELENGTH, &h.height) == 1;
    TIFFGetFieldDefaulted(tif, TIFFTAG_BITSPERSAMPLE, &h.bits);
    TIFFGetFieldDefaulted(tif, TIFFTAG_SAMPLESPERPIXEL, &h.samples);
    TIFFGetFieldDefaulted(tif, TIFFTAG_SAMPLEFORMAT, &h.sample_format);
    TIFFGetFieldDefaulted(tif, TIFFTAG_PLANARCONFIG, &h.planar);
    TIFFGetFieldDefaulted(tif, TIFFTAG_COMPRESSION, &h.compression);
    TIFFGetFieldDefaulted(tif, TIFFTAG_ORIENTATION, &h.orientation);
    std::uint16_t photometric = 0;
    if (TIFFGetField(tif, TIFFTAG_PHOTOMETRIC, &photometric) == 1) h.photometric = photometric;
    TIFFGetField(tif, TIFFTAG_SUBFILETYPE, &h.subfile_type);
    void* dng_version = nullptr;
    h.dng = TIFFGetField(tif, TIFFTAG_DNGVERSION, &dng_version) == 1;
    h.codec_available = TIFFIsCODECConfigured(h.compression) != 0;
    h.tiled = TIFFIsTiled(tif) != 0;
    toff_t exif_offset = 0;
    h.has_exif = TIFFGetField(tif, TIFFTAG_EXIFIFD, &exif_offset) == 1 && exif_offset != 0;
    std::uint32_t icc_bytes = 0;
    void* icc = nullptr;
    if (TIFFGetField(tif, TIFFTAG_ICCPROFILE, &icc_bytes, &icc) == 1 && icc != nullptr) {
        const auto* p = static_cast<const std::uint8_t*>(icc);
        h.icc_profile.assign(p, p + icc_bytes);
    }
    return h;
}

}  // namespace

// ---- decoding ---------------------------------------------------------------------------------

struct TiffDecoder::State {
    Memory memory;
    std::string message;
    std::unique_ptr<TiffHandle> handle;
};

TiffDecoder::TiffDecoder(Bytes bytes, const std::string& name, bool map)
    : state_(std::make_unique<State>()), name_(name) {
    state_->memory.in = bytes;
    state_->memory.map = map;
    state_->handle = std::make_unique<TiffHandle>(name.c_str(), map ? "r" : "rm", state_->memory,
                                                  state_->message);
    if (ok()) header_ = read_header(state_->handle->get());
}

TiffDecoder::~TiffDecoder() = default;

bool TiffDecoder::ok() const { return state_->handle->get() != nullptr; }

std::string TiffDecoder::reason() const {
    return state_->message.empty() ? std::string("libtiff reported no detail") : state_->message;
}

TiffExif TiffDecoder::read_exif() {
    TIFF* tif = state_->handle->get();
    TiffExif fields;
    toff_t offset = 0;
    if (TIFFGetField(tif, TIFFTAG_EXIFIFD, &offset) != 1 || offset == 0) return fields;
    if (TIFFReadEXIFDirectory(tif, offset) == 1) {
        fields.exposure_s = exif_rational(tif, EXIFTAG_EXPOSURETIME);
        fields.f_number = exif_rational(tif, EXIFTAG_FNUMBER);
        std::uint16_t count = 0;
        std::uint16_t* iso = nullptr;
        if (TIFFGetField(tif, EXIFTAG_ISOSPEEDRATINGS, &count, &iso) == 1 && count >= 1 &&
            iso != nullptr && iso[0] > 0)
            fields.iso = iso[0];
        std::uint16_t color_space = 0;
        if (TIFFGetField(tif, EXIFTAG_COLORSPACE, &color_space) == 1)
            fields.color_space = color_space;
    }
    if (TIFFSetDirectory(tif, 0) != 1)
        throw DataError(concat(name_,
                               ": TIFF: cannot return to the first image after its EXIF "
                               "directory (",
                               reason(), ")"));
    return fields;
}

void TiffDecoder::read_rows(const RowSink& row, std::size_t planes) {
    if (header_.tiled)
        read_tiles(row);
    else
        read_strips(row, planes);
}

void TiffDecoder::read_strips(const RowSink& row, std::size_t planes) {
    TIFF* tif = state_->handle->get();
    const bool separate = header_.separate();
    const tmsize_t line_size = TIFFScanlineSize(tif);
    const std::size_t line_needed =
        std::size_t{header_.width} * header_.sample_bytes() * (separate ? 1 : header_.samples);
    if (line_size <= 0 || static_cast<std::size_t>(line_size) < line_needed)
        throw DataError(concat(name_, ": TIFF scanline size does not match its width (corrupt)"));
    std::vector<std::uint8_t> line(static_cast<std::size_t>(line_size));
    const std::size_t plane_count = separate ? planes : 1;
    for (std::size_t s = 0; s < plane_count; ++s) {
        for (std::uint32_t r = 0; r < header_.height; ++r) {
            if (TIFFReadScanline(tif, line.data(), r, static_cast<std::uint16_t>(s)) < 0)
                throw DataError(concat(name_, ": TIFF row ", std::to_string(r),
                                       ": truncated or corrupt (", reason(), ")"));
            row(line.data(), r, separate ? static_cast<int>(s) : -1);
        }
    }
}

// Tiles are put together into bands of rows (every sample of each pixel, planes interleaved).
void TiffDecoder::read_tiles(const RowSink& row) {
    TIFF* tif = state_->handle->get();
    const std::uint32_t width = header_.width;
    const std::uint32_t height = header_.height;
    const std::size_t sample_bytes = header_.sample_bytes();
    const std::size_t samples = header_.samples;
    const bool separate = header_.separate();
    const std::size_t pixel_bytes = samples * sample_bytes;
    std::uint32_t tile_width = 0;
    std::uint32_t tile_height = 0;
    TIFFGetField(tif, TIFFTAG_TILEWIDTH, &tile_width);
    TIFFGetField(tif, TIFFTAG_TILELENGTH, &tile_height);
    const tmsize_t tile_size = TIFFTileSize(tif);
    const std::uint64_t needed =
        std::uint64_t{tile_width} * tile_height * (separate ? sample_bytes : pixel_bytes);
    const std::uint64_t image_bytes = std::uint64_t{width} * height * pixel_bytes;
    if (tile_width == 0 || tile_height == 0 || tile_size <= 0 ||
        static_cast<std::uint64_t>(tile_size) < needed ||
        static_cast<std::uint64_t>(tile_size) > 4 * image_bytes + (1U << 20))
        throw DataError(concat(name_, ": TIFF tiles of ", std::to_string(tile_width), " x ",
                               std::to_string(tile_height),
                               " pixels do not fit the image (corrupt)"));
    std::vector<std::uint8_t> tile(static_cast<std::size_t>(tile_size));
    std::vector<std::uint8_t> band(std::size_t{std::min(tile_height, height)} * width *
                                   pixel_bytes);
    const std::size_t planes = separate ? samples : 1;
    for (std::uint32_t y0 = 0; y0 < height; y0 += tile_height) {
        const std::uint32_t rows = std::min(tile_height, height - y0);
        for (std::uint32_t x0 = 0; x0 < width; x0 += tile_width) {
            const std::uint32_t cols = std::min(tile_width, width - x0);
            for (std::size_t s = 0; s < planes; ++s) {
                if (TIFFReadTile(tif, tile.data(), x0, y0, 0, static_cast<std::uint16_t>(s)) < 0)
                    throw DataError(concat(name_, ": TIFF tile at column ", std::to_string(x0),
                                           ", row ", std::to_string(y0), ": truncated or corrupt (",
                                           reason(), ")"));
                for (std::uint32_t r = 0; r < rows; ++r) {
                    std::uint8_t* out = band.data() + (std::size_t{r} * width + x0) * pixel_bytes;
                    if (!separate) {
                        std::memcpy(out, tile.data() + std::size_t{r} * tile_width * pixel_bytes,
                                    std::size_t{cols} * pixel_bytes);
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
        for (std::uint32_t r = 0; r < rows; ++r)
            row(band.data() + std::size_t{r} * width * pixel_bytes, y0 + r, -1);
    }
}

ImageBuffer decode_tiff(Bytes bytes, const std::string& name,
                        const std::function<void(const TiffHeader&)>& check) {
    TiffDecoder decoder(bytes, name);
    if (!decoder.ok())
        throw DataError(concat(name, ": corrupt or truncated TIFF (", decoder.reason(), ")"));
    const TiffHeader& h = decoder.header();
    if (!h.has_size) throw DataError(concat(name, ": TIFF without ImageWidth or ImageLength"));
    if (check) check(h);
    const bool is_float =
        h.sample_format == tiff::kSampleFormatFloat && (h.bits == 32 || h.bits == 64);
    const bool is_uint =
        h.sample_format != tiff::kSampleFormatFloat && (h.bits == 8 || h.bits == 16);
    if (!is_float && !is_uint)
        throw DataError(concat(name, ": TIFF samples of ", std::to_string(h.bits),
                               " bits in sample format ", std::to_string(h.sample_format),
                               " are not supported; valid: 8- or 16-bit unsigned, 32- or 64-bit "
                               "float"));
    if (!h.codec_available)
        throw DataError(concat(name, ": TIFF compression ", std::to_string(h.compression),
                               " is not available in libtiff"));
    ImageBuffer image(h.width, h.height, h.samples, {h.bits, is_float});
    const std::size_t row_bytes = image.view().row_bytes();
    const std::size_t sample_bytes = image.type.bytes();
    decoder.read_rows(
        [&](const std::uint8_t* samples, std::uint32_t y, int plane) {
            std::uint8_t* out = image.data.data() + std::size_t{y} * row_bytes;
            if (plane < 0) {
                std::memcpy(out, samples, row_bytes);
                return;
            }
            for (std::size_t x = 0; x < image.width; ++x)
                std::memcpy(
                    out + (x * image.channels + static_cast<std::size_t>(plane)) * sample_bytes,
                    samples + x * sample_bytes, sample_bytes);
        },
        h.samples);
    return image;
}

// ---- encoding ---------------------------------------------------------------------------------

namespace {

void set_dng_tags(TIFF* tif, const DngTags& dng) {
    TIFFSetField(tif, TIFFTAG_MAKE, dng.make.c_str());
    TIFFSetField(tif, TIFFTAG_MODEL, dng.model.c_str());
    TIFFSetField(tif, TIFFTAG_DNGVERSION, dng.version.data());
    TIFFSetField(tif, TIFFTAG_DNGBACKWARDVERSION, dng.backward_version.data());
    TIFFSetField(tif, TIFFTAG_UNIQUECAMERAMODEL, dng.unique_camera_model.c_str());
    TIFFSetField(tif, TIFFTAG_BLACKLEVEL, static_cast<std::uint16_t>(dng.black_level.size()),
                 dng.black_level.data());
    TIFFSetField(tif, TIFFTAG_WHITELEVEL, static_cast<std::uint16_t>(dng.white_level.size()),
                 dng.white_level.data());
    TIFFSetField(tif, TIFFTAG_COLORMATRIX1, static_cast<std::uint16_t>(dng.color_matrix1.size()),
                 dng.color_matrix1.data());
    TIFFSetField(tif, TIFFTAG_ASSHOTNEUTRAL, static_cast<std::uint16_t>(dng.as_shot_neutral.size()),
                 dng.as_shot_neutral.data());
    TIFFSetField(tif, TIFFTAG_CALIBRATIONILLUMINANT1, dng.calibration_illuminant1);
}

[[noreturn]] void writer_failed(const std::string& what, std::string_view failed,
                                const std::string& message) {
    throw Error(concat(what, ": libtiff ", failed, ": ",
                       message.empty() ? std::string("no detail") : message));
}

}  // namespace

std::string encode_tiff(const ImageView& image, const TiffEncodeOptions& options,
                        const std::string& what) {
    if (image.width == 0 || image.height == 0 || image.width > 0xffffffffU ||
        image.height > 0xffffffffU)
        throw InvalidArgument(concat(what, ": each side must be in [1, 2^32 - 1] pixels"));
    std::string out;
    out.reserve(image.row_bytes() * image.height + 4096);
    Memory memory;
    memory.out = &out;
    std::string message;
    {
        TiffHandle handle(what.c_str(), options.mode, memory, message);
        TIFF* tif = handle.get();
        if (tif == nullptr) writer_failed(what, "could not start", message);
        if (options.subfile_type) TIFFSetField(tif, TIFFTAG_SUBFILETYPE, 0);
        TIFFSetField(tif, TIFFTAG_IMAGEWIDTH, static_cast<std::uint32_t>(image.width));
        TIFFSetField(tif, TIFFTAG_IMAGELENGTH, static_cast<std::uint32_t>(image.height));
        TIFFSetField(tif, TIFFTAG_BITSPERSAMPLE, image.type.bits);
        TIFFSetField(tif, TIFFTAG_SAMPLESPERPIXEL, static_cast<int>(image.channels));
        TIFFSetField(tif, TIFFTAG_SAMPLEFORMAT,
                     image.type.is_float ? SAMPLEFORMAT_IEEEFP : SAMPLEFORMAT_UINT);
        const std::uint16_t photometric =
            options.photometric != 0
                ? options.photometric
                : (image.channels == 1 ? tiff::kPhotometricMinIsBlack : tiff::kPhotometricRgb);
        TIFFSetField(tif, TIFFTAG_PHOTOMETRIC, photometric);
        TIFFSetField(tif, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
        TIFFSetField(tif, TIFFTAG_COMPRESSION, COMPRESSION_NONE);
        if (options.orientation) TIFFSetField(tif, TIFFTAG_ORIENTATION, ORIENTATION_TOPLEFT);
        TIFFSetField(tif, TIFFTAG_ROWSPERSTRIP, TIFFDefaultStripSize(tif, 0));
        if (!options.software.empty())
            TIFFSetField(tif, TIFFTAG_SOFTWARE, options.software.c_str());
        if (options.dng) set_dng_tags(tif, *options.dng);
        for (std::size_t r = 0; r < image.height; ++r) {
            // libtiff takes a non-const buffer but does not modify it when writing uncompressed.
            auto* samples = const_cast<std::uint8_t*>(image.row(r));
            if (TIFFWriteScanline(tif, samples, static_cast<std::uint32_t>(r), 0) < 0)
                writer_failed(what, concat("could not write row ", std::to_string(r)), message);
        }
        if (TIFFFlush(tif) != 1) writer_failed(what, "could not finish", message);
    }
    return out;
}

}  // namespace roughscope::io::codec
