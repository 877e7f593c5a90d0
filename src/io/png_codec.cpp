// PNG through libpng, in memory (png_codec.hpp). See the header for how libpng's longjmp is kept
// away from C++ objects.
#include "io/png_codec.hpp"

#include <algorithm>
#include <bit>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <utility>

#include <png.h>

#include "roughscope/core/text.hpp"

namespace roughscope::io::codec {

namespace {

[[noreturn]] void on_error(png_structp png, png_const_charp message) {
    auto* text = static_cast<char*>(png_get_error_ptr(png));
    std::snprintf(text, 256, "%s", message);
    png_longjmp(png, 1);
}

void on_warning(png_structp, png_const_charp) {}

int colour_type_for(std::size_t channels) {
    switch (channels) {
        case 1:
            return PNG_COLOR_TYPE_GRAY;
        case 2:
            return PNG_COLOR_TYPE_GRAY_ALPHA;
        case 3:
            return PNG_COLOR_TYPE_RGB;
        default:
            return PNG_COLOR_TYPE_RGB_ALPHA;
    }
}

}  // namespace

PngError::PngError(const std::string& name, std::string detail, std::size_t offset)
    : DataError(concat(name, ": corrupt or truncated PNG (libpng: ", detail, ")")),
      detail_(std::move(detail)),
      offset_(offset) {}

// ---- decoding ---------------------------------------------------------------------------------

struct PngDecoder::State {
    png_structp png = nullptr;
    png_infop info = nullptr;
    Bytes bytes;
    std::size_t pos = 0;
    bool started = false;  // transforms set and png_read_update_info done
    char message[256] = {};
    ~State() { png_destroy_read_struct(&png, &info, nullptr); }

    static void read(png_structp png, png_bytep out, png_size_t length) {
        auto* in = static_cast<State*>(png_get_io_ptr(png));
        if (length > in->bytes.size() - in->pos)
            png_error(png, "unexpected end of file (truncated)");
        std::memcpy(out, in->bytes.data() + in->pos, length);
        in->pos += length;
    }
};

PngDecoder::PngDecoder(Bytes bytes, std::string name)
    : state_(std::make_unique<State>()), name_(std::move(name)) {
    State& st = *state_;
    st.bytes = bytes;
    st.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, st.message, on_error, on_warning);
    if (st.png == nullptr) throw DataError(concat(name_, ": libpng could not start"));
    st.info = png_create_info_struct(st.png);
    if (st.info == nullptr) throw DataError(concat(name_, ": libpng could not start"));
    png_set_read_fn(st.png, &st, State::read);
    png_set_benign_errors(st.png, 1);
    png_set_crc_action(st.png, PNG_CRC_DEFAULT, PNG_CRC_WARN_DISCARD);
    png_set_user_limits(st.png, 0x7fffffffU, 0x7fffffffU);
}

PngDecoder::~PngDecoder() = default;

void PngDecoder::fail() const { throw PngError(name_, state_->message, state_->pos); }

const PngHeader& PngDecoder::read_header() {
    png_structp png = state_->png;
    png_infop info = state_->info;
    if (setjmp(png_jmpbuf(png)) != 0) fail();
    png_read_info(png, info);
    png_uint_32 width = 0;
    png_uint_32 height = 0;
    int depth = 0;
    int colour = 0;
    int interlace = 0;
    png_get_IHDR(png, info, &width, &height, &depth, &colour, &interlace, nullptr, nullptr);
    header_.width = width;
    header_.height = height;
    header_.bit_depth = depth;
    header_.colour_type = colour;
    header_.samples = png_get_channels(png, info);
    header_.interlaced = interlace != PNG_INTERLACE_NONE;
    header_.significant_bits = depth;
    png_color_8p sbit = nullptr;
    if (png_get_sBIT(png, info, &sbit) != 0 && sbit != nullptr) {
        const int bits = (colour & PNG_COLOR_MASK_COLOR) != 0
                             ? std::max({int{sbit->red}, int{sbit->green}, int{sbit->blue}})
                             : int{sbit->gray};
        if (bits >= 1 && bits < depth) header_.significant_bits = bits;
    }
    header_.srgb = png_get_valid(png, info, PNG_INFO_sRGB) != 0;
    png_charp profile_name = nullptr;
    int compression = 0;
    png_bytep profile = nullptr;
    png_uint_32 profile_bytes = 0;
    if (png_get_iCCP(png, info, &profile_name, &compression, &profile, &profile_bytes) != 0 &&
        profile != nullptr) {
        header_.has_icc = true;
        header_.icc_name = profile_name != nullptr ? profile_name : "";
        header_.icc_profile.assign(profile, profile + profile_bytes);
    }
    png_fixed_point gamma = 0;
    if (png_get_gAMA_fixed(png, info, &gamma) != 0) header_.gamma_fixed = gamma;
    png_uint_32 exif_bytes = 0;
    png_bytep exif = nullptr;
    if (png_get_eXIf_1(png, info, &exif_bytes, &exif) != 0 && exif != nullptr)
        header_.exif.assign(exif, exif + exif_bytes);
    return header_;
}

std::size_t PngDecoder::row_bytes() const {
    return (std::size_t{header_.width} * header_.samples *
                static_cast<std::size_t>(header_.bit_depth) +
            7) /
           8;
}

// Called from read_rows and read_image after their setjmp: libpng's errors land there.
void PngDecoder::start() {
    State& st = *state_;
    if (st.started) return;
    st.started = true;
    if (header_.bit_depth == 16 && std::endian::native == std::endian::little) png_set_swap(st.png);
    if (header_.interlaced) passes_ = png_set_interlace_handling(st.png);
    png_read_update_info(st.png, st.info);
}

void PngDecoder::read_rows(std::uint8_t* out, std::size_t rows) {
    png_structp png = state_->png;
    if (setjmp(png_jmpbuf(png)) != 0) fail();
    start();
    const std::size_t stride = row_bytes();
    for (std::size_t r = 0; r < rows; ++r) png_read_row(png, out + r * stride, nullptr);
}

void PngDecoder::read_image(std::uint8_t* out) {
    png_structp png = state_->png;
    if (setjmp(png_jmpbuf(png)) != 0) fail();
    start();
    const std::size_t stride = row_bytes();
    for (int pass = 0; pass < passes_; ++pass)
        for (std::size_t r = 0; r < header_.height; ++r)
            png_read_row(png, out + r * stride, nullptr);
}

void PngDecoder::read_end() {
    png_structp png = state_->png;
    png_infop info = state_->info;
    if (setjmp(png_jmpbuf(png)) != 0) fail();
    png_read_end(png, info);
    png_uint_32 exif_bytes = 0;
    png_bytep exif = nullptr;
    if (header_.exif.empty() && png_get_eXIf_1(png, info, &exif_bytes, &exif) != 0 &&
        exif != nullptr)
        header_.exif.assign(exif, exif + exif_bytes);
}

ImageBuffer decode_png(Bytes bytes, const std::string& name,
                       const std::function<void(const PngHeader&)>& check) {
    PngDecoder decoder(bytes, name);
    const PngHeader& header = decoder.read_header();
    if (check) check(header);
    if (header.colour_type == PNG_COLOR_TYPE_PALETTE ||
        (header.bit_depth != 8 && header.bit_depth != 16))
        throw DataError(concat(name, ": PNG colour type ", std::to_string(header.colour_type),
                               " with ", std::to_string(header.bit_depth),
                               "-bit samples is not supported; valid: 8- or 16-bit grey, grey + "
                               "alpha, RGB, RGBA"));
    ImageBuffer image(header.width, header.height, header.samples, {header.bit_depth, false});
    decoder.read_image(image.data.data());
    decoder.read_end();
    return image;
}

// ---- encoding ---------------------------------------------------------------------------------

namespace {

struct WriteState {
    png_structp png = nullptr;
    png_infop info = nullptr;
    char message[256] = {};
    ~WriteState() { png_destroy_write_struct(&png, &info); }

    static void append(png_structp png, png_bytep data, png_size_t length) {
        static_cast<std::string*>(png_get_io_ptr(png))
            ->append(reinterpret_cast<const char*>(data), length);
    }
    static void flush(png_structp) {}
};

// The libpng calls of encode_png; false after a libpng error (WriteState::message).
bool write_png(WriteState& st, std::string& out, const ImageView& image,
               const PngEncodeOptions& options) {
    png_structp png = st.png;
    png_infop info = st.info;
    if (setjmp(png_jmpbuf(png)) != 0) return false;
    png_set_write_fn(png, &out, WriteState::append, WriteState::flush);
    if (options.compression_level >= 0) png_set_compression_level(png, options.compression_level);
    if (!options.filter) png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_NONE);
    png_set_IHDR(png, info, static_cast<png_uint_32>(image.width),
                 static_cast<png_uint_32>(image.height), image.type.bits,
                 colour_type_for(image.channels), PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    if (options.significant_bits > 0) {
        png_color_8 significant{};
        const auto bits = static_cast<png_byte>(options.significant_bits);
        significant.gray = significant.red = significant.green = significant.blue = bits;
        significant.alpha = bits;
        png_set_sBIT(png, info, &significant);
    }
    png_write_info(png, info);
    if (image.type.bits == 16 && std::endian::native == std::endian::little) png_set_swap(png);
    // libpng copies each row before transforming it: the caller's samples stay as they are.
    for (std::size_t r = 0; r < image.height; ++r)
        png_write_row(png, const_cast<png_bytep>(image.row(r)));
    png_write_end(png, nullptr);
    return true;
}

}  // namespace

std::string encode_png(const ImageView& image, const PngEncodeOptions& options,
                       const std::string& what) {
    if (image.type.is_float || (image.type.bits != 8 && image.type.bits != 16) ||
        image.channels < 1 || image.channels > 4)
        throw InvalidArgument(concat(what, ": PNG holds 8- or 16-bit samples of 1 to 4 channels"));
    if (image.width == 0 || image.height == 0 || image.width > 0x7fffffffU ||
        image.height > 0x7fffffffU)
        throw InvalidArgument(concat(what, ": each side must be in [1, 2^31 - 1] pixels"));
    std::string out;
    if (!options.filter) out.reserve(image.row_bytes() * image.height * 9 / 8 + 1024);
    WriteState st;
    st.png = png_create_write_struct(PNG_LIBPNG_VER_STRING, st.message, on_error, on_warning);
    if (st.png == nullptr) throw Error(concat(what, ": libpng could not start"));
    st.info = png_create_info_struct(st.png);
    if (st.info == nullptr) throw Error(concat(what, ": libpng could not start"));
    if (!write_png(st, out, image, options)) throw Error(concat(what, ": libpng: ", st.message));
    return out;
}

}  // namespace roughscope::io::codec
