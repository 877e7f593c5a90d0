// Height images (docs/height-files.md, "PNG and TIFF"): 8/16-bit grey PNG through libpng, and
// TIFF through libtiff with uint8/uint16 or 32/64-bit IEEE float samples. Integer samples are
// counts: heights = z_scale_um × count (HeightReadOptions::z_scale_um, required); float samples
// are µm, NaN or ±inf = missing. Neither format carries the spacings here: they come from the
// options (1 µm by default, noted in the map's title).
//
// Both libraries read from memory (png_set_read_fn, TIFFClientOpenExt with memory procedures).
// libpng reports errors by longjmp: every C++ object of decode_png/encode_png with a destructor is
// created before setjmp, so the jump skips none. libtiff's messages go to a per-file handler
// (never to stderr).
#include <algorithm>
#include <cmath>
#include <csetjmp>
#include <cstdarg>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include <png.h>
#include <tiffio.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/surface/formats.hpp"
#include "tab_common.hpp"

namespace roughscope::surface::formats {

namespace {

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

// ---- PNG ------------------------------------------------------------------------------------

struct PngInput {
    std::string_view bytes;
    std::size_t pos = 0;
};

struct PngError {
    char message[256] = {};
};

void png_read_bytes(png_structp png, png_bytep out, png_size_t length) {
    auto* in = static_cast<PngInput*>(png_get_io_ptr(png));
    if (length > in->bytes.size() - in->pos) png_error(png, "unexpected end of file");
    std::memcpy(out, in->bytes.data() + in->pos, length);
    in->pos += length;
}

void png_write_bytes(png_structp png, png_bytep data, png_size_t length) {
    auto* out = static_cast<std::string*>(png_get_io_ptr(png));
    out->append(reinterpret_cast<const char*>(data), length);
}

void png_flush_nothing(png_structp) {}

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

struct PngWriteHandle {
    png_structp png = nullptr;
    png_infop info = nullptr;
    ~PngWriteHandle() { png_destroy_write_struct(&png, &info); }
};

// ---- TIFF -----------------------------------------------------------------------------------

struct TiffMemory {
    std::string_view in;         // reading
    std::string* out = nullptr;  // writing
    std::uint64_t pos = 0;
    std::uint64_t size() const { return out != nullptr ? out->size() : in.size(); }
};

struct TiffError {
    std::string message;
};

tmsize_t tiff_read(thandle_t handle, void* buffer, tmsize_t length) {
    auto* f = static_cast<TiffMemory*>(handle);
    const char* data = f->out != nullptr ? f->out->data() : f->in.data();
    const std::uint64_t size = f->size();
    if (length <= 0 || f->pos >= size) return 0;
    const auto n = static_cast<std::size_t>(
        std::min<std::uint64_t>(static_cast<std::uint64_t>(length), size - f->pos));
    std::memcpy(buffer, data + f->pos, n);
    f->pos += n;
    return static_cast<tmsize_t>(n);
}

tmsize_t tiff_write(thandle_t handle, void* buffer, tmsize_t length) {
    auto* f = static_cast<TiffMemory*>(handle);
    if (f->out == nullptr || length < 0) return -1;
    const auto n = static_cast<std::size_t>(length);
    if (f->out->size() < f->pos + n) f->out->resize(static_cast<std::size_t>(f->pos + n));
    std::memcpy(f->out->data() + f->pos, buffer, n);
    f->pos += n;
    return length;
}

toff_t tiff_seek(thandle_t handle, toff_t offset, int whence) {
    auto* f = static_cast<TiffMemory*>(handle);
    std::uint64_t base = 0;
    if (whence == SEEK_CUR) base = f->pos;
    if (whence == SEEK_END) base = f->size();
    const std::uint64_t target = base + offset;
    if (target < base) return static_cast<toff_t>(-1);  // wrapped around
    f->pos = target;
    return target;
}

int tiff_close(thandle_t) { return 0; }
toff_t tiff_size(thandle_t handle) { return static_cast<TiffMemory*>(handle)->size(); }
int tiff_map(thandle_t, void**, toff_t*) { return 0; }
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

// A TIFF opened on memory, closed on scope exit.
class TiffFile {
  public:
    TiffFile(const char* name, const char* mode, TiffMemory& memory, TiffError& error) {
        TIFFOpenOptions* options = TIFFOpenOptionsAlloc();
        TIFFOpenOptionsSetErrorHandlerExtR(options, tiff_on_error, &error);
        TIFFOpenOptionsSetWarningHandlerExtR(options, tiff_on_warning, nullptr);
        TIFFOpenOptionsSetMaxSingleMemAlloc(options, tmsize_t{1} << 30);
        tiff_ = TIFFClientOpenExt(name, mode, &memory, tiff_read, tiff_write, tiff_seek, tiff_close,
                                  tiff_size, tiff_map, tiff_unmap, options);
        TIFFOpenOptionsFree(options);
    }
    ~TiffFile() { close(); }
    TiffFile(const TiffFile&) = delete;
    TiffFile& operator=(const TiffFile&) = delete;
    TIFF* get() const { return tiff_; }
    void close() {
        if (tiff_ != nullptr) TIFFClose(tiff_);
        tiff_ = nullptr;
    }

  private:
    TIFF* tiff_ = nullptr;
};

std::string tiff_reason(const TiffError& error) {
    return error.message.empty() ? std::string("libtiff reported no detail") : error.message;
}

}  // namespace

HeightMap decode_png(std::string_view bytes, const std::string& name,
                     const HeightReadOptions& options) {
    const double z_scale = z_scale_for(options, name, "a PNG height image");
    if (bytes.size() < 8 ||
        png_sig_cmp(reinterpret_cast<png_const_bytep>(bytes.data()), 0, 8) != 0) {
        throw tab::error_at_offset(name, 0, "not a PNG file (the 8-byte PNG signature is missing)");
    }
    // Everything with a destructor lives before setjmp (see the file comment).
    PngInput input{bytes, 0};
    PngError error;
    PngReadHandle h;
    std::vector<unsigned char> pixels;
    std::vector<png_bytep> rows;
    HeightMap map;
    h.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &error, png_fail, png_ignore_warning);
    if (h.png == nullptr) throw DataError(name + ": libpng could not start");
    h.info = png_create_info_struct(h.png);
    if (h.info == nullptr) throw DataError(name + ": libpng could not start");
    if (setjmp(png_jmpbuf(h.png)) != 0) {
        throw tab::error_at_offset(name, input.pos, std::string("PNG: ") + error.message);
    }
    png_set_read_fn(h.png, &input, png_read_bytes);
    png_read_info(h.png, h.info);
    png_uint_32 width = 0;
    png_uint_32 height = 0;
    int depth = 0;
    int color = 0;
    int interlace = 0;
    png_get_IHDR(h.png, h.info, &width, &height, &depth, &color, &interlace, nullptr, nullptr);
    if (color != PNG_COLOR_TYPE_GRAY || (depth != 8 && depth != 16)) {
        throw tab::error_at_offset(name, 16,
                                   "PNG colour type " + std::to_string(color) + " with " +
                                       std::to_string(depth) +
                                       "-bit samples: a height image is 8- or 16-bit grey "
                                       "(colour type 0)");
    }
    tab::check_grid_size(name, width, height, "PNG header");
    const std::size_t sample_bytes = static_cast<std::size_t>(depth) / 8;
    const std::size_t row_bytes = static_cast<std::size_t>(width) * sample_bytes;
    if (row_bytes * height / kPngMaxExpansion > bytes.size()) {
        throw tab::error_at_offset(
            name, 16,
            "PNG header asks for " + std::to_string(width) + " x " + std::to_string(height) +
                " pixels, more than a file of " + std::to_string(bytes.size()) +
                " bytes can hold at deflate's largest compression ratio (1032:1)");
    }
    if (interlace != PNG_INTERLACE_NONE) png_set_interlace_handling(h.png);
    png_read_update_info(h.png, h.info);
    pixels.resize(row_bytes * height);
    rows.resize(height);
    for (std::size_t iy = 0; iy < height; ++iy) rows[iy] = pixels.data() + iy * row_bytes;
    png_read_image(h.png, rows.data());
    png_read_end(h.png, nullptr);

    map = image_map(width, height, options);
    map.heights_um.resize(static_cast<std::size_t>(width) * height);
    const std::size_t n = map.heights_um.size();
    for (std::size_t i = 0; i < n; ++i) {
        const unsigned count = depth == 16
                                   ? (static_cast<unsigned>(pixels[2 * i]) << 8) | pixels[2 * i + 1]
                                   : pixels[i];
        map.heights_um[i] = z_scale * static_cast<double>(count);
    }
    return tab::finish(std::move(map), name);
}

std::string encode_png(const HeightMap& map, const HeightWriteOptions& options) {
    const double z_scale = write_z_scale(options, "png: a 16-bit PNG");
    if (map.nx > 0x7fffffffU || map.ny > 0x7fffffffU) {
        throw InvalidArgument("png: at most 2^31 - 1 pixels per side");
    }
    std::vector<unsigned char> pixels(map.size() * 2);
    for (std::size_t i = 0; i < map.size(); ++i) {
        const std::uint32_t count = tab::count_for(map.heights_um[i], z_scale, 65535, i, "png");
        pixels[2 * i] = static_cast<unsigned char>(count >> 8);
        pixels[2 * i + 1] = static_cast<unsigned char>(count & 0xff);
    }
    std::vector<png_bytep> rows(map.ny);
    for (std::size_t iy = 0; iy < map.ny; ++iy) rows[iy] = pixels.data() + iy * map.nx * 2;
    std::string out;
    PngError error;
    PngWriteHandle h;
    h.png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &error, png_fail, png_ignore_warning);
    if (h.png == nullptr) throw Error("png: libpng could not start");
    h.info = png_create_info_struct(h.png);
    if (h.info == nullptr) throw Error("png: libpng could not start");
    if (setjmp(png_jmpbuf(h.png)) != 0) throw Error(std::string("png: libpng: ") + error.message);
    png_set_write_fn(h.png, &out, png_write_bytes, png_flush_nothing);
    png_set_IHDR(h.png, h.info, static_cast<png_uint_32>(map.nx), static_cast<png_uint_32>(map.ny),
                 16, PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    png_write_info(h.png, h.info);
    png_write_image(h.png, rows.data());
    png_write_end(h.png, nullptr);
    return out;
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
    TiffMemory memory{bytes, nullptr, 0};
    TiffError error;
    TiffFile file(name.c_str(), "rm", memory, error);
    TIFF* tif = file.get();
    if (tif == nullptr) {
        throw DataError(name + ": not a readable TIFF: " + tiff_reason(error));
    }
    std::uint32_t width = 0;
    std::uint32_t height = 0;
    std::uint16_t bits = 1;
    std::uint16_t samples = 1;
    std::uint16_t format = SAMPLEFORMAT_UINT;
    if (TIFFGetField(tif, TIFFTAG_IMAGEWIDTH, &width) != 1 ||
        TIFFGetField(tif, TIFFTAG_IMAGELENGTH, &height) != 1) {
        throw DataError(name + ": TIFF without ImageWidth/ImageLength");
    }
    TIFFGetFieldDefaulted(tif, TIFFTAG_BITSPERSAMPLE, &bits);
    TIFFGetFieldDefaulted(tif, TIFFTAG_SAMPLESPERPIXEL, &samples);
    TIFFGetFieldDefaulted(tif, TIFFTAG_SAMPLEFORMAT, &format);
    if (samples != 1) {
        throw DataError(name + ": TIFF with " + std::to_string(samples) +
                        " samples per pixel: a height image has 1 (grey)");
    }
    const bool is_float = format == SAMPLEFORMAT_IEEEFP && (bits == 32 || bits == 64);
    const bool is_uint = format == SAMPLEFORMAT_UINT && (bits == 8 || bits == 16);
    if (!is_float && !is_uint) {
        throw DataError(name + ": TIFF samples of " + std::to_string(bits) +
                        " bits in sample format " + std::to_string(format) +
                        ": a height image has uint8/uint16 (format 1) or 32/64-bit float "
                        "(format 3) samples");
    }
    if (TIFFIsTiled(tif) != 0)
        throw DataError(name + ": tiled TIFF is not supported (strips only)");
    const double z_scale = is_uint ? z_scale_for(options, name, "an integer TIFF") : 1.0;
    tab::check_grid_size(name, width, height, "TIFF header");
    const tmsize_t line_bytes = TIFFScanlineSize(tif);
    const std::size_t sample_bytes = bits / 8U;
    // Strips may share their compressed data, so a file of a few hundred bytes can claim
    // gigabytes of rows. No codec of libtiff packs real samples beyond 4096:1 (deflate ≤ 1032:1,
    // an LZW code < 4096 bytes), so more than 4096 × the file (+ 1 MiB) is refused before any
    // row is decoded.
    const double decoded_bytes = static_cast<double>(width) * static_cast<double>(height) *
                                 static_cast<double>(sample_bytes);
    const double most_bytes = 4096.0 * static_cast<double>(bytes.size()) + 1048576.0;
    if (decoded_bytes > most_bytes)
        throw DataError(name + ": the TIFF header's " + std::to_string(width) + " x " +
                        std::to_string(height) + " samples of " + std::to_string(bits) +
                        " bits are more than 4096 times the file's " +
                        std::to_string(bytes.size()) +
                        " bytes: no compression packs real heights that far (a damaged or "
                        "crafted file)");
    if (line_bytes < 0 || static_cast<std::size_t>(line_bytes) < width * sample_bytes) {
        throw DataError(name + ": TIFF scanline size does not match its width");
    }
    std::vector<unsigned char> line(static_cast<std::size_t>(line_bytes));
    HeightMap map = image_map(width, height, options);
    // The map grows row by row as rows decode, so a header that lies about its size costs no
    // more memory than the data that is really there.
    for (std::uint32_t iy = 0; iy < height; ++iy) {
        if (TIFFReadScanline(tif, line.data(), iy, 0) < 0) {
            throw DataError(name + ": TIFF row " + std::to_string(iy) + ": " + tiff_reason(error));
        }
        const std::size_t base = map.heights_um.size();
        map.heights_um.resize(base + width);
        double* row = map.heights_um.data() + base;
        const unsigned char* p = line.data();
        for (std::size_t ix = 0; ix < width; ++ix) {
            double v = 0;
            if (bits == 8) {
                v = z_scale * p[ix];
            } else if (bits == 16) {
                std::uint16_t c = 0;
                std::memcpy(&c, p + 2 * ix, 2);
                v = z_scale * c;
            } else if (bits == 32) {
                float f = 0;
                std::memcpy(&f, p + 4 * ix, 4);
                v = f;
            } else {
                std::memcpy(&v, p + 8 * ix, 8);
            }
            row[ix] = std::isinf(v) ? kNaN : v;
        }
    }
    return tab::finish(std::move(map), name);
}

std::string encode_tiff(const HeightMap& map, const HeightWriteOptions& options) {
    const bool as_float = options.tiff_float;
    const double z_scale = as_float ? 1.0 : write_z_scale(options, "tiff: a uint16 TIFF");
    if (map.nx > 0xffffffffU || map.ny > 0xffffffffU) {
        throw InvalidArgument("tiff: at most 2^32 - 1 pixels per side");
    }
    // Samples first (the checks may throw), then libtiff.
    std::vector<float> floats;
    std::vector<std::uint16_t> counts;
    if (as_float) {
        floats.resize(map.size());
        for (std::size_t i = 0; i < map.size(); ++i) {
            floats[i] = tab::float_sample(map.heights_um[i], i, "tiff float32");
        }
    } else {
        counts.resize(map.size());
        for (std::size_t i = 0; i < map.size(); ++i) {
            counts[i] = static_cast<std::uint16_t>(
                tab::count_for(map.heights_um[i], z_scale, 65535, i, "tiff uint16"));
        }
    }
    std::string out;
    TiffMemory memory{{}, &out, 0};
    TiffError error;
    {
        TiffFile file("height map", "w", memory, error);
        TIFF* tif = file.get();
        if (tif == nullptr) throw Error("tiff: libtiff could not start: " + tiff_reason(error));
        const auto nx = static_cast<std::uint32_t>(map.nx);
        const auto ny = static_cast<std::uint32_t>(map.ny);
        TIFFSetField(tif, TIFFTAG_IMAGEWIDTH, nx);
        TIFFSetField(tif, TIFFTAG_IMAGELENGTH, ny);
        TIFFSetField(tif, TIFFTAG_BITSPERSAMPLE, as_float ? 32 : 16);
        TIFFSetField(tif, TIFFTAG_SAMPLESPERPIXEL, 1);
        TIFFSetField(tif, TIFFTAG_SAMPLEFORMAT, as_float ? SAMPLEFORMAT_IEEEFP : SAMPLEFORMAT_UINT);
        TIFFSetField(tif, TIFFTAG_PHOTOMETRIC, PHOTOMETRIC_MINISBLACK);
        TIFFSetField(tif, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
        TIFFSetField(tif, TIFFTAG_COMPRESSION, COMPRESSION_NONE);
        TIFFSetField(tif, TIFFTAG_ROWSPERSTRIP, TIFFDefaultStripSize(tif, 0));
        for (std::uint32_t iy = 0; iy < ny; ++iy) {
            void* row = as_float ? static_cast<void*>(floats.data() + std::size_t{iy} * nx)
                                 : static_cast<void*>(counts.data() + std::size_t{iy} * nx);
            if (TIFFWriteScanline(tif, row, iy, 0) < 0) {
                throw Error("tiff: libtiff could not write row " + std::to_string(iy) + ": " +
                            tiff_reason(error));
            }
        }
        if (TIFFFlush(tif) != 1)
            throw Error("tiff: libtiff could not finish: " + tiff_reason(error));
    }
    return out;
}

}  // namespace roughscope::surface::formats
