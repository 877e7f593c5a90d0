// Internal pieces of the image reader (image/read.hpp): one decoder per format and what they
// share, the conversion of stored codes to linear values (Linearizer) and the metadata parsers
// (EXIF through libexif, ICC profiles). Not installed.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "roughscope/core/response.hpp"
#include "roughscope/photo/image.hpp"
#include "roughscope/photo/read.hpp"

namespace roughscope::image::detail {

using Bytes = std::span<const std::uint8_t>;

// What the file says about its tone response (ImageInfo::file_response and its evidence); gamma
// is γ of Response::Gamma (linear = code^γ).
struct Evidence {
    std::optional<Response> response;
    double gamma = 0.0;
    std::string text;
    bool known() const { return response.has_value(); }
};

// The stored samples of a file, as its decoder found them in the header.
struct Layout {
    std::size_t width = 0;
    std::size_t height = 0;
    std::size_t channels = 0;  // 1 or 3 colour planes kept
    int bits = 0;              // bits per stored sample: 8, 16 or 32 (float)
    bool is_float = false;
    double full_scale = 0.0;            // F: the code of full scale (2^bits − 1, 1 for float)
    std::vector<double> default_black;  // per plane when the file has black levels (RAW)
    double largest_code = 0.0;          // integer codes: the largest stored (0: 2^bits − 1)
};

// Throws DataError unless width, height ≥ 1 and width · height ≤ kMaxImagePixels.
void check_pixel_count(const std::string& name, std::size_t width, std::size_t height);

// Throws DataError unless `decoded_bytes` could come out of a file of `file_bytes` bytes
// compressed at most `max_ratio` : 1 (decompression bombs and lying headers are refused before
// any pixel is allocated).
void check_expansion(const std::string& name, std::uint64_t decoded_bytes, std::size_t file_bytes,
                     std::uint64_t max_ratio, std::string_view what);

// Stored codes to linear values (read.hpp, "The linear scale"). The constructor decides the
// response (options, else the evidence, else the bit depth), the black and white levels, records
// them and any warning in image.info, and allocates the image — the values uninitialised (no
// pass over 100 MB that the decoder overwrites), the flags zero; put() then converts one plane of
// one row at a time, and finish() makes sure every row of every plane came.
class Linearizer {
  public:
    Linearizer(LinearImage& image, const Layout& layout, const Evidence& evidence,
               const ReadOptions& options);

    // Row `row` of plane `plane`: the sample of column x is samples[x · stride + offset]. Flags
    // are OR-ed into the pixel's, so planes may come in any order. T: std::uint8_t, std::uint16_t
    // (codes ≤ full scale) or float (DataError for a non-finite sample).
    template <class T>
    void put(const T* samples, std::size_t row, std::size_t stride, std::size_t offset,
             std::size_t plane);

    // Every plane of row `row`: plane c of column x is samples[x · stride + offsets[c]].
    template <class T>
    void put_pixels(const T* samples, std::size_t row, std::size_t stride,
                    const std::array<std::size_t, 3>& offsets);

    // DataError naming the first row (and plane) that no put() wrote: a decoder that stopped
    // early on a corrupt file never hands out uninitialised values.
    void finish() const;
    // For a decoder that writes image.values and image.flags itself, every pixel of every plane
    // (LibRaw's): the rows count as written.
    void mark_every_row_written() { std::fill(row_written_.begin(), row_written_.end(), 1); }

    // s = F · R⁻¹(q / F) (read.hpp).
    double linear_code(double code) const;
    double black(std::size_t plane) const { return black_[plane]; }
    double white() const { return white_; }

  private:
    void build_tables(int bits);

    LinearImage& image_;
    std::vector<std::uint8_t> row_written_;  // plane · height + row
    Response response_ = Response::Linear;
    double gamma_ = 0.0;
    double full_scale_ = 1.0;
    std::vector<double> black_;
    double white_ = 1.0;
    int bits_ = 0;
    // Non-linear responses of integer samples: value and flags per code, built on first use.
    std::size_t table_size_ = 0;
    std::vector<float> value_table_;        // plane · table_size_ + code
    std::vector<std::uint8_t> flag_table_;  // plane · table_size_ + code
};

// ---- metadata ---------------------------------------------------------------------------------

struct ExifFields {
    std::optional<double> exposure_s;
    std::optional<double> f_number;
    std::optional<double> iso;
    std::optional<int> color_space;  // EXIF ColorSpace: 1 = sRGB, 0xFFFF = uncalibrated
    std::optional<int> orientation;  // 1 = top-left (stored order)
};

// An EXIF block as found in a JPEG APP1 segment: "Exif\0\0" then a TIFF structure. Fields that
// are missing or malformed stay unset; never throws for bad data.
ExifFields parse_exif(Bytes block);

// Copies the exposure fields into `info` (those set only).
void apply_exif_exposure(const ExifFields& exif, ImageInfo& info);

// The evidence of an EXIF ColorSpace tag (sRGB; uncalibrated says nothing).
Evidence exif_color_space_evidence(const ExifFields& exif);

// A warning for an orientation other than top-left (pixels are never rotated).
void warn_orientation(std::optional<int> orientation, std::string_view where, ImageInfo& info);

// The response an ICC profile describes: its grey or green tone curve (identity → linear, a pure
// power → gamma, the sRGB curve → sRGB), else an sRGB description. `where` names the profile's
// place ("PNG iCCP profile"). Unknown or malformed profiles give no evidence.
Evidence icc_evidence(Bytes profile, std::string_view where);

// ---- decoders ----------------------------------------------------------------------------------
// Each fills image.info.format and the metadata and returns the image; DataError for bad files.

LinearImage decode_png(Bytes bytes, const std::string& name, const ReadOptions& options);
LinearImage decode_jpeg(Bytes bytes, const std::string& name, const ReadOptions& options);
// What the TIFF directories of a camera RAW say of its exposure (EXIF 2.3 tags ExposureTime
// 33434 and FNumber 33437, in IFD0 or the EXIF IFD): a tag present with the value 0 says "not
// recorded" (Magic Lantern's DNGs write 0/1000000 s). LibRaw then falls back on the APEX tags,
// whose 0 reads as 1 s and f/1: the reader takes such a value as unknown instead.
struct RawTiffFacts {
    bool exposure_time_zero = false;  // an ExposureTime of 0 and none other than 0
    bool f_number_zero = false;       // an FNumber of 0 and none other than 0
};

// DataError unless the TIFF directories reachable from the header lie inside the file with
// entries of known types (LibRaw's TIFF parser trusts them; decode_tiff.cpp). any_version: also
// when the header's version is not TIFF's 42 (ORF, RW2 and any file starting with II or MM,
// which LibRaw parses as TIFF directories too). Returns the exposure facts above.
RawTiffFacts check_raw_structure(Bytes bytes, const std::string& name, bool any_version);

// nullopt: the file is a TIFF-structured camera RAW (read.hpp), for decode_raw.
std::optional<LinearImage> decode_tiff(Bytes bytes, const std::string& name,
                                       const ReadOptions& options);
// `offered`: true when the file was not recognised as PNG, JPEG or TIFF (the error then says so).
LinearImage decode_raw(Bytes bytes, const std::string& name, const ReadOptions& options,
                       bool offered);

}  // namespace roughscope::image::detail
