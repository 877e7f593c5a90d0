// TIFF through libtiff, in memory: the one place the library calls libtiff. The photograph
// reader (photo), the height-image reader and writer (surface), the map files (maps) and the
// synthetic captures (simulation) use it and keep only their own meaning of the samples.
// Internal (src/); libtiff is private to the io topic. libtiff's messages go to a handler of the
// open file (the first error is kept for the messages here), never to stderr.
#pragma once

#include <array>
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

// Tag values of the TIFF 6.0 and DNG specifications that the callers test.
namespace tiff {
constexpr std::uint16_t kPhotometricMinIsBlack = 1;
constexpr std::uint16_t kPhotometricRgb = 2;
constexpr std::uint16_t kPhotometricCfa = 32803;
constexpr std::uint16_t kPhotometricLinearRaw = 34892;
constexpr std::uint16_t kSampleFormatUint = 1;
constexpr std::uint16_t kSampleFormatFloat = 3;
constexpr std::uint16_t kSampleFormatVoid = 4;
constexpr std::uint16_t kCompressionNone = 1;
constexpr std::uint16_t kPlanarSeparate = 2;
constexpr std::uint16_t kOrientationTopLeft = 1;
constexpr std::uint32_t kFileTypeReducedImage = 1;
}  // namespace tiff

// What the first image's directory says (absent tags: their TIFF defaults).
struct TiffHeader {
    bool has_size = false;  // ImageWidth and ImageLength present
    std::uint32_t width = 0;
    std::uint32_t height = 0;
    std::uint16_t bits = 1;
    std::uint16_t samples = 1;
    std::uint16_t sample_format = tiff::kSampleFormatUint;
    std::uint16_t planar = 1;
    std::uint16_t compression = tiff::kCompressionNone;
    std::uint16_t orientation = tiff::kOrientationTopLeft;
    std::optional<std::uint16_t> photometric;
    std::uint32_t subfile_type = 0;
    bool dng = false;             // a DNGVersion tag
    bool codec_available = true;  // libtiff can decode the compression
    bool tiled = false;
    bool has_exif = false;  // an EXIF IFD
    std::vector<std::uint8_t> icc_profile;

    std::size_t sample_bytes() const { return bits / 8U; }
    bool separate() const { return planar == tiff::kPlanarSeparate && samples > 1; }
};

// The EXIF IFD's exposure fields (those present and > 0) and ColorSpace.
struct TiffExif {
    std::optional<double> exposure_s;
    std::optional<double> f_number;
    std::optional<double> iso;
    std::optional<int> color_space;
};

// Decodes one TIFF held in memory (the bytes must outlive the decoder). Single allocations of
// libtiff are capped at 1 GiB.
class TiffDecoder {
  public:
    // `map`: hand the bytes to libtiff as a memory map (no copy of uncompressed strips).
    // Never throws for a bad file: ok() says whether libtiff could open it, reason() why not.
    TiffDecoder(Bytes bytes, const std::string& name, bool map = true);
    ~TiffDecoder();
    TiffDecoder(const TiffDecoder&) = delete;
    TiffDecoder& operator=(const TiffDecoder&) = delete;

    bool ok() const;
    // libtiff's first error message ("libtiff reported no detail" when it gave none).
    std::string reason() const;
    const TiffHeader& header() const { return header_; }
    // The EXIF IFD's fields; the first image is current again afterwards (DataError if not).
    TiffExif read_exif();

    // Every row of the first image, in order: row(samples, y, plane). plane < 0: the row holds
    // every sample of each pixel (header().samples apart); with separate planes from strips,
    // plane p ≥ 0 of `planes` planes comes plane by plane, one sample per pixel. Strips or tiles
    // (tiles are put together into rows). DataError naming the file and the row or tile for a
    // truncated or corrupt file, or tiles or scanlines that do not fit the image.
    using RowSink = std::function<void(const std::uint8_t* samples, std::uint32_t y, int plane)>;
    void read_rows(const RowSink& row, std::size_t planes);

  private:
    struct State;
    void read_strips(const RowSink& row, std::size_t planes);
    void read_tiles(const RowSink& row);
    std::unique_ptr<State> state_;
    TiffHeader header_;
    std::string name_;
};

// The whole first image of a TIFF as samples (contiguous; extra samples kept). `check` sees the
// header before any sample is allocated (and throws to refuse the file). DataError for a broken
// file or samples other than 8/16-bit unsigned or 32/64-bit float.
ImageBuffer decode_tiff(Bytes bytes, const std::string& name,
                        const std::function<void(const TiffHeader&)>& check = {});

// DNG 1.4's tags of a LinearRaw image (Adobe DNG specification, "Tags").
struct DngTags {
    std::string make;
    std::string model;
    std::string unique_camera_model;
    std::array<std::uint8_t, 4> version{1, 4, 0, 0};
    std::array<std::uint8_t, 4> backward_version{1, 1, 0, 0};
    std::vector<float> black_level;
    std::vector<std::uint32_t> white_level;
    std::vector<float> color_matrix1;
    std::vector<float> as_shot_neutral;
    std::uint16_t calibration_illuminant1 = 21;  // D65
};

struct TiffEncodeOptions {
    const char* mode = "w";         // as TIFFOpen's: "w", "wl" little-endian, "w8" BigTIFF
    std::uint16_t photometric = 0;  // 0: grey (min-is-black) for 1 channel, else RGB
    bool subfile_type = false;      // write NewSubfileType 0
    bool orientation = false;       // write Orientation top-left
    std::string software;           // a Software tag when not empty
    std::optional<DngTags> dng;
};

// Samples as an uncompressed TIFF in strips of libtiff's default size (float samples with
// SampleFormat 3). Error "<what>: libtiff ...: <libtiff's message>" when libtiff fails.
std::string encode_tiff(const ImageView& image, const TiffEncodeOptions& options = {},
                        const std::string& what = "tiff");

}  // namespace roughscope::io::codec
