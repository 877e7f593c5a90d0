// Height-map files: every reader and writer of the surface topic, and the one entry point that
// picks them by extension. Each reader takes the file's bytes (so the fuzz targets drive exactly
// the code a file drives) plus the name used in messages, and throws DataError naming the file
// and the line or byte offset of the first problem; a HeightMap it returns has passed validate().
// Writers return the bytes of the file; write_height_map() puts them on disk through
// io::OutputFile (atomic replace, nothing half-written). Formats and their quirks:
// docs/height-files.md.
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include "roughscope/surface/height_map.hpp"

namespace roughscope::surface {

enum class HeightFormat {
    CsvMatrix,  // CSV/ASCII matrix: one row of heights per line (.csv, .txt, .asc)
    Xyz,        // x y z triples on a regular grid (.xyz)
    Sdf,        // ISO 25178-71 SDF, ASCII (aISO-1.0) or binary (bISO-1.0) (.sdf)
    X3p,        // ISO 25178-72 / ISO 5436-2 XML in a zip (.x3p)
    Gwy,        // Gwyddion native GWYP (.gwy), read only
    Gsf,        // Gwyddion simple field (.gsf)
    Png,        // 16-bit (or 8-bit) grey PNG, heights = z_scale_um × count (.png)
    Tiff,       // 16-bit integer or 32/64-bit float grey TIFF (.tif, .tiff)
    Raw,        // headerless float32/float64, dimensions given (.raw, .bin, .f32, .f64)
};

// "x3p", "gsf", ... (core/names.hpp table; any case).
std::string to_string(HeightFormat format);
HeightFormat parse_height_format(std::string_view name);
// The format a path's extension names; nullopt when the extension is not one of the above.
std::optional<HeightFormat> height_format_from_extension(const std::filesystem::path& path);

enum class RawSampleType { Float32, Float64 };

// What a file does not say itself. A value a format does carry (x3p spacings, SDF scales) wins
// over these unless the option says otherwise in its comment.
struct HeightReadOptions {
    std::optional<HeightFormat> format;  // default: from the extension
    // csv_matrix, png, tiff, raw: spacings in µm (required for raw; default 1 µm otherwise, with
    // the map's title noting it). xyz: ignored (from the coordinates).
    std::optional<double> dx_um;
    std::optional<double> dy_um;
    // csv_matrix, xyz: the length unit of the numbers when no header line names it ("m", "mm",
    // "um", "nm"; default "um").
    std::optional<std::string> length_unit;
    // png, tiff (integer samples): heights in µm per count (required for integer images).
    std::optional<double> z_scale_um;
    // raw: grid size, sample type, byte order.
    std::optional<std::size_t> nx;
    std::optional<std::size_t> ny;
    RawSampleType raw_type = RawSampleType::Float64;
    bool raw_big_endian = false;
    // x3p: verify the MD5 checksums a file states (point data, validity bitmap, main.xml); false
    // reads a file whose checksums are stale. An absent checksum is never an error.
    bool x3p_verify_checksums = true;
};

struct HeightWriteOptions {
    std::optional<HeightFormat> format;  // default: from the extension
    bool sdf_binary = true;              // sdf: bISO-1.0 (true) or aISO-1.0 (false)
    // png/tiff integer output: µm per count (required); tiff_float writes 32-bit float samples.
    std::optional<double> z_scale_um;
    bool tiff_float = true;
    RawSampleType raw_type = RawSampleType::Float64;
};

// Reads `path` (format from options or extension). DataError for unreadable/malformed files,
// InvalidArgument for options out of range (both name the file).
HeightMap read_height_map(const std::filesystem::path& path, const HeightReadOptions& options = {});
// Writes `map` to `path` ("-" = stdout) in the format the options or the extension name.
void write_height_map(const HeightMap& map, const std::filesystem::path& path,
                      const HeightWriteOptions& options = {});

// Per-format decoders and encoders (bytes in, value out; `name` only for messages).
// About how many bytes write_height_map holds in memory to write `points` heights in `format`
// (the encoded file is made in memory, then written): for memory checks (core/memory.hpp).
double encoded_size_estimate(std::size_t points, HeightFormat format,
                             const HeightWriteOptions& options = {});

HeightMap decode_height_map(std::string_view bytes, const std::string& name, HeightFormat format,
                            const HeightReadOptions& options = {});
// Throws InvalidArgument for a format that cannot be written (gwy) or a map it cannot hold.
std::string encode_height_map(const HeightMap& map, HeightFormat format,
                              const HeightWriteOptions& options = {});

namespace formats {
// One pair per format family, implemented in src/surface/format_<family>.cpp.
HeightMap decode_csv_matrix(std::string_view bytes, const std::string& name,
                            const HeightReadOptions&);
std::string encode_csv_matrix(const HeightMap& map, const HeightWriteOptions&);
HeightMap decode_xyz(std::string_view bytes, const std::string& name, const HeightReadOptions&);
std::string encode_xyz(const HeightMap& map, const HeightWriteOptions&);
HeightMap decode_sdf(std::string_view bytes, const std::string& name, const HeightReadOptions&);
std::string encode_sdf(const HeightMap& map, const HeightWriteOptions&);
HeightMap decode_x3p(std::string_view bytes, const std::string& name, const HeightReadOptions&);
std::string encode_x3p(const HeightMap& map, const HeightWriteOptions&);
HeightMap decode_gwy(std::string_view bytes, const std::string& name, const HeightReadOptions&);
HeightMap decode_gsf(std::string_view bytes, const std::string& name, const HeightReadOptions&);
std::string encode_gsf(const HeightMap& map, const HeightWriteOptions&);
HeightMap decode_png(std::string_view bytes, const std::string& name, const HeightReadOptions&);
std::string encode_png(const HeightMap& map, const HeightWriteOptions&);
HeightMap decode_tiff(std::string_view bytes, const std::string& name, const HeightReadOptions&);
std::string encode_tiff(const HeightMap& map, const HeightWriteOptions&);
HeightMap decode_raw(std::string_view bytes, const std::string& name, const HeightReadOptions&);
std::string encode_raw(const HeightMap& map, const HeightWriteOptions&);
}  // namespace formats

}  // namespace roughscope::surface
