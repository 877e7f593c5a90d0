// PNG through libpng, in memory: the one place the library calls libpng. The photograph reader
// (photo), the height-image reader and writer (surface), the map files (maps) and the synthetic
// captures (simulation) use it and keep only their own meaning of the samples. Internal (src/);
// libpng is private to the io topic.
//
// libpng reports errors by longjmp. Every libpng call is made inside a member function of this
// module that calls setjmp first and holds no object with a destructor, so the jump skips none;
// the error then leaves that function as a C++ exception. Warnings are dropped: nothing prints.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "io/image_buffer.hpp"
#include "roughscope/core/errors.hpp"

namespace roughscope::io::codec {

// A libpng error while decoding: the message says "<name>: corrupt or truncated PNG (libpng:
// <detail>)"; detail() is libpng's own text and offset() how many bytes of the file libpng had
// read, for readers that word the error their way.
class PngError : public DataError {
  public:
    PngError(const std::string& name, std::string detail, std::size_t offset);
    const std::string& detail() const { return detail_; }
    std::size_t offset() const { return offset_; }

  private:
    std::string detail_;
    std::size_t offset_ = 0;
};

// PNG colour types (PNG specification, IHDR).
enum class PngColour : int { Grey = 0, Rgb = 2, Palette = 3, GreyAlpha = 4, Rgba = 6 };

// What the header and the chunks before the image data say.
struct PngHeader {
    std::uint32_t width = 0;
    std::uint32_t height = 0;
    int bit_depth = 0;  // as stored: 1, 2, 4, 8 or 16
    int colour_type = 0;
    std::size_t samples = 1;  // samples per pixel: 1 to 4 (alpha included)
    bool interlaced = false;
    int significant_bits = 0;  // sBIT: the most of the colour channels' (bit_depth without sBIT)
    bool srgb = false;         // an sRGB chunk
    std::optional<std::int32_t> gamma_fixed;  // gAMA: the encoding exponent × 100000
    bool has_icc = false;                     // an iCCP chunk
    std::string icc_name;
    std::vector<std::uint8_t> icc_profile;
    std::vector<std::uint8_t> exif;  // an eXIf chunk's payload (the TIFF structure)
};

// Decodes one PNG held in memory (the bytes must outlive the decoder). Ancillary chunks with
// errors (a bad CRC or profile) are dropped, critical ones are errors; libpng's own limit on the
// width and height is lifted (callers check the size against the file, header() first).
class PngDecoder {
  public:
    // `name` names the file in messages. DataError when libpng cannot start.
    PngDecoder(Bytes bytes, std::string name);
    ~PngDecoder();
    PngDecoder(const PngDecoder&) = delete;
    PngDecoder& operator=(const PngDecoder&) = delete;

    // Reads the header and the chunks before the image data; PngError for a broken file.
    // Afterwards rows come with 16-bit samples in the machine's byte order.
    const PngHeader& read_header();
    const PngHeader& header() const { return header_; }
    // The samples of one row: width · samples · bit_depth / 8 bytes.
    std::size_t row_bytes() const;
    // The next `rows` rows into out (row_bytes() apart); not for an interlaced file.
    void read_rows(std::uint8_t* out, std::size_t rows);
    // Every row into out (row_bytes() · height bytes), interlaced or not.
    void read_image(std::uint8_t* out);
    // The chunks after the image data (an eXIf chunk there fills header().exif when empty).
    void read_end();

  private:
    struct State;
    [[noreturn]] void fail() const;
    void start();
    std::unique_ptr<State> state_;
    PngHeader header_;
    std::string name_;
    int passes_ = 1;
};

// The whole image of an 8- or 16-bit PNG (grey, grey + alpha, RGB, RGBA) as samples, alpha kept.
// `check` sees the header before any sample is allocated (and throws to refuse the file).
// DataError for a palette or low-bit-depth image, PngError for a broken file.
ImageBuffer decode_png(Bytes bytes, const std::string& name,
                       const std::function<void(const PngHeader&)>& check = {});

struct PngEncodeOptions {
    int compression_level = -1;  // zlib's 0 to 9; -1: libpng's default
    bool filter = true;          // false: no row filters (fast, for noise)
    int significant_bits = 0;    // an sBIT chunk for every colour channel (0: none)
};

// 8- or 16-bit grey (1 channel), grey + alpha (2), RGB (3) or RGBA (4) samples as PNG. Error
// "<what>: libpng: ..." when libpng fails.
std::string encode_png(const ImageView& image, const PngEncodeOptions& options = {},
                       const std::string& what = "png");

}  // namespace roughscope::io::codec
