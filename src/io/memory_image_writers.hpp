// libpng and libtiff writing into a std::string, for the encoders that return file bytes (the
// synthetic captures, simulation/capture.hpp; the roughness-map files, image/map_files.hpp); the
// caller writes the bytes through io::OutputFile. Internal (src/): the topics that use it link
// libpng and libtiff themselves.
//
// libpng reports errors by longjmp: the caller creates every object with a destructor first,
// then calls setjmp(png_jmpbuf(writer.png())) in its own frame and throws message() when it
// returns non-zero. libtiff's messages go to the writer's handler, never to stderr.
#pragma once

#include <algorithm>
#include <cstdarg>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <string_view>
#include <utility>

#include <png.h>
#include <tiffio.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"

namespace roughscope::io::detail {

// ---- PNG ------------------------------------------------------------------------------------

class PngMemoryWriter {
  public:
    // Throws Error when libpng cannot start. The bytes are appended to `out`.
    explicit PngMemoryWriter(std::string& out) {
        png_ = png_create_write_struct(PNG_LIBPNG_VER_STRING, this, on_error, on_warning);
        if (png_ == nullptr) throw Error("png: libpng could not start");
        info_ = png_create_info_struct(png_);
        if (info_ == nullptr) {
            png_destroy_write_struct(&png_, nullptr);
            throw Error("png: libpng could not start");
        }
        png_set_write_fn(png_, &out, append, flush);
    }
    ~PngMemoryWriter() { png_destroy_write_struct(&png_, &info_); }
    PngMemoryWriter(const PngMemoryWriter&) = delete;
    PngMemoryWriter& operator=(const PngMemoryWriter&) = delete;

    png_structp png() const { return png_; }
    png_infop info() const { return info_; }
    // libpng's message of the error that longjmp'd.
    std::string message() const { return concat("png: libpng: ", message_); }

  private:
    static void append(png_structp png, png_bytep data, png_size_t length) {
        static_cast<std::string*>(png_get_io_ptr(png))
            ->append(reinterpret_cast<const char*>(data), length);
    }
    static void flush(png_structp) {}
    [[noreturn]] static void on_error(png_structp png, png_const_charp message) {
        auto* self = static_cast<PngMemoryWriter*>(png_get_error_ptr(png));
        std::snprintf(self->message_, sizeof self->message_, "%s", message);
        png_longjmp(png, 1);
    }
    static void on_warning(png_structp, png_const_charp) {}

    png_structp png_ = nullptr;
    png_infop info_ = nullptr;
    char message_[256] = {};
};

// ---- TIFF -----------------------------------------------------------------------------------

class TiffMemoryWriter {
  public:
    // `mode` as TIFFOpen's ("w", "wl" little-endian, "w8" BigTIFF); `what` names the file kind
    // in messages ("capture tiff", "map tiff"). Throws Error when libtiff cannot start.
    TiffMemoryWriter(std::string& out, const char* mode, std::string what)
        : sink_{&out, 0}, what_(std::move(what)) {
        TIFFOpenOptions* options = TIFFOpenOptionsAlloc();
        TIFFOpenOptionsSetErrorHandlerExtR(options, on_error, &message_);
        TIFFOpenOptionsSetWarningHandlerExtR(options, on_warning, nullptr);
        tiff_ = TIFFClientOpenExt(what_.c_str(), mode, &sink_, read, write, seek, close, size, map,
                                  unmap, options);
        TIFFOpenOptionsFree(options);
        if (tiff_ == nullptr) fail("could not start");
    }
    ~TiffMemoryWriter() {
        if (tiff_ != nullptr) TIFFClose(tiff_);
    }
    TiffMemoryWriter(const TiffMemoryWriter&) = delete;
    TiffMemoryWriter& operator=(const TiffMemoryWriter&) = delete;

    TIFF* get() const { return tiff_; }
    [[noreturn]] void fail(std::string_view what) const {
        throw Error(concat(what_, ": libtiff ", what, ": ",
                           message_.empty() ? std::string("no detail") : message_));
    }
    // Writes `rows` rows of `row_bytes` bytes each, as scanlines.
    void write_rows(const unsigned char* data, std::size_t row_bytes, std::size_t rows) {
        for (std::size_t r = 0; r < rows; ++r) {
            // libtiff takes a non-const buffer but does not modify it when writing uncompressed.
            auto* row = const_cast<unsigned char*>(data + r * row_bytes);
            if (TIFFWriteScanline(tiff_, row, static_cast<std::uint32_t>(r), 0) < 0)
                fail(concat("could not write row ", std::to_string(r)));
        }
    }
    void finish() {
        if (TIFFFlush(tiff_) != 1) fail("could not finish");
    }

  private:
    struct Sink {
        std::string* out = nullptr;
        std::uint64_t pos = 0;
    };
    static tmsize_t read(thandle_t handle, void* buffer, tmsize_t length) {
        auto* f = static_cast<Sink*>(handle);
        const std::uint64_t n_all = f->out->size();
        if (length <= 0 || f->pos >= n_all) return 0;
        const auto n = static_cast<std::size_t>(
            std::min<std::uint64_t>(static_cast<std::uint64_t>(length), n_all - f->pos));
        std::memcpy(buffer, f->out->data() + f->pos, n);
        f->pos += n;
        return static_cast<tmsize_t>(n);
    }
    static tmsize_t write(thandle_t handle, void* buffer, tmsize_t length) {
        auto* f = static_cast<Sink*>(handle);
        if (length < 0) return -1;
        const auto n = static_cast<std::size_t>(length);
        if (f->out->size() < f->pos + n) f->out->resize(static_cast<std::size_t>(f->pos + n));
        std::memcpy(f->out->data() + f->pos, buffer, n);
        f->pos += n;
        return length;
    }
    static toff_t seek(thandle_t handle, toff_t offset, int whence) {
        auto* f = static_cast<Sink*>(handle);
        std::uint64_t base = 0;
        if (whence == SEEK_CUR) base = f->pos;
        if (whence == SEEK_END) base = f->out->size();
        f->pos = base + offset;
        return f->pos;
    }
    static int close(thandle_t) { return 0; }
    static toff_t size(thandle_t handle) { return static_cast<Sink*>(handle)->out->size(); }
    static int map(thandle_t, void**, toff_t*) { return 0; }
    static void unmap(thandle_t, void*, toff_t) {}
    static int on_error(TIFF*, void* user, const char* module, const char* format, va_list args) {
        auto* message = static_cast<std::string*>(user);
        if (message->empty()) {
            char text[256];
            std::vsnprintf(text, sizeof text, format, args);
            if (module != nullptr && *module != '\0') message->append(module).append(": ");
            message->append(text);
        }
        return 1;
    }
    static int on_warning(TIFF*, void*, const char*, const char*, va_list) { return 1; }

    Sink sink_;
    std::string what_;
    std::string message_;
    TIFF* tiff_ = nullptr;
};

}  // namespace roughscope::io::detail
