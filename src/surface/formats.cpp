// Dispatch of the height-map readers and writers (formats.hpp); the formats themselves live in
// src/surface/format_<family>.cpp.
#include "roughscope/surface/formats.hpp"

#include <array>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <system_error>
#include <vector>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/memory.hpp"
#include "roughscope/core/names.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/io/input_file.hpp"
#include "roughscope/io/output_file.hpp"

namespace roughscope::surface {

namespace {

constexpr std::array<NameEntry<HeightFormat>, 9> kFormatNames{{
    {"csv_matrix", HeightFormat::CsvMatrix},
    {"xyz", HeightFormat::Xyz},
    {"sdf", HeightFormat::Sdf},
    {"x3p", HeightFormat::X3p},
    {"gwy", HeightFormat::Gwy},
    {"gsf", HeightFormat::Gsf},
    {"png", HeightFormat::Png},
    {"tiff", HeightFormat::Tiff},
    {"raw", HeightFormat::Raw},
}};

struct ExtensionEntry {
    std::string_view extension;  // lower case, with the dot
    HeightFormat format;
};

constexpr std::array<ExtensionEntry, 16> kExtensions{{
    {".csv", HeightFormat::CsvMatrix},
    {".txt", HeightFormat::CsvMatrix},
    {".asc", HeightFormat::CsvMatrix},
    {".xyz", HeightFormat::Xyz},
    {".sdf", HeightFormat::Sdf},
    {".x3p", HeightFormat::X3p},
    {".gwy", HeightFormat::Gwy},
    {".gsf", HeightFormat::Gsf},
    {".png", HeightFormat::Png},
    {".tif", HeightFormat::Tiff},
    {".tiff", HeightFormat::Tiff},
    {".raw", HeightFormat::Raw},
    {".bin", HeightFormat::Raw},
    {".f32", HeightFormat::Raw},
    {".f64", HeightFormat::Raw},
    {".dat", HeightFormat::Raw},
}};

std::string extension_list() {
    std::string out;
    for (const auto& entry : kExtensions) {
        if (!out.empty()) out += ", ";
        out += entry.extension;
    }
    return out;
}

HeightFormat format_for(const std::filesystem::path& path,
                        const std::optional<HeightFormat>& given) {
    if (given) return *given;
    if (auto found = height_format_from_extension(path)) return *found;
    std::string message = "cannot tell the height-map format of ";
    message.append(quote_input(path.string()))
        .append(" from its extension; use one of ")
        .append(extension_list())
        .append(" or name the format");
    throw InvalidArgument(message);
}

std::string read_whole_file(const std::filesystem::path& path) {
    std::error_code ec;
    const auto status = std::filesystem::status(path, ec);
    if (ec || !std::filesystem::exists(status)) {
        throw DataError("cannot read " + quote_input(path.string()) + ": no such file");
    }
    if (std::filesystem::is_directory(status)) {
        throw DataError("cannot read " + quote_input(path.string()) + ": it is a directory");
    }
    // A FIFO is read (docs/height-files.md, "Pipes"), up to the memory budget; a device is not.
    io::check_input_file(path, "cannot read " + quote_input(path.string()), true);
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        std::string message = "cannot read " + quote_input(path.string());
        message.append(": ").append(std::strerror(errno));
        throw DataError(message);
    }
    // A regular file: read in one call into storage of its size (huge pages asked for when it is
    // large); then whatever else the stream holds (a file that grew, or no known size: a pipe).
    std::string bytes;
    const bool regular = std::filesystem::is_regular_file(status);
    const std::uintmax_t size = regular ? std::filesystem::file_size(path, ec) : 0;
    if (regular && !ec && size > 0 && size <= bytes.max_size()) {
        bytes.reserve(static_cast<std::size_t>(size));
        advise_huge_pages(bytes.data(), static_cast<std::size_t>(size));
        bytes.resize(static_cast<std::size_t>(size));
        in.read(bytes.data(), static_cast<std::streamsize>(size));
        bytes.resize(static_cast<std::size_t>(in.gcount()));
        if (in.bad()) throw DataError("cannot read " + quote_input(path.string()) + ": read error");
        in.clear(in.rdstate() & ~std::ios::failbit & ~std::ios::eofbit);
    }
    // The rest (a pipe: all of it) in chunks, never more than the memory budget.
    const MemoryBudget budget = memory_budget();
    std::vector<char> chunk(std::size_t{1} << 20);
    while (in) {
        in.read(chunk.data(), static_cast<std::streamsize>(chunk.size()));
        const auto got = static_cast<std::size_t>(in.gcount());
        if (static_cast<double>(bytes.size() + got) > budget.bytes)
            throw DataError(concat("cannot read ", quote_input(path.string()),
                                   ": it delivers more than the memory limit of ",
                                   format_gigabytes(budget.bytes), " (", budget.source,
                                   "; ROUGHSCOPE_MEMORY_LIMIT_GB sets it)"));
        bytes.append(chunk.data(), got);
    }
    if (in.bad()) throw DataError("cannot read " + quote_input(path.string()) + ": read error");
    return bytes;
}

}  // namespace

std::string to_string(HeightFormat format) { return std::string(name_of(kFormatNames, format)); }

HeightFormat parse_height_format(std::string_view name) {
    return parse_name(kFormatNames, "height-map format", name);
}

std::optional<HeightFormat> height_format_from_extension(const std::filesystem::path& path) {
    const std::string extension = normalize_name(path.extension().string());
    for (const auto& entry : kExtensions) {
        if (entry.extension == extension) return entry.format;
    }
    return std::nullopt;
}

HeightMap decode_height_map(std::string_view bytes, const std::string& name, HeightFormat format,
                            const HeightReadOptions& options) {
    switch (format) {
        case HeightFormat::CsvMatrix:
            return formats::decode_csv_matrix(bytes, name, options);
        case HeightFormat::Xyz:
            return formats::decode_xyz(bytes, name, options);
        case HeightFormat::Sdf:
            return formats::decode_sdf(bytes, name, options);
        case HeightFormat::X3p:
            return formats::decode_x3p(bytes, name, options);
        case HeightFormat::Gwy:
            return formats::decode_gwy(bytes, name, options);
        case HeightFormat::Gsf:
            return formats::decode_gsf(bytes, name, options);
        case HeightFormat::Png:
            return formats::decode_png(bytes, name, options);
        case HeightFormat::Tiff:
            return formats::decode_tiff(bytes, name, options);
        case HeightFormat::Raw:
            return formats::decode_raw(bytes, name, options);
    }
    throw InvalidArgument("unknown height-map format");
}

std::string encode_height_map(const HeightMap& map, HeightFormat format,
                              const HeightWriteOptions& options) {
    validate(map, "height map");
    switch (format) {
        case HeightFormat::CsvMatrix:
            return formats::encode_csv_matrix(map, options);
        case HeightFormat::Xyz:
            return formats::encode_xyz(map, options);
        case HeightFormat::Sdf:
            return formats::encode_sdf(map, options);
        case HeightFormat::X3p:
            return formats::encode_x3p(map, options);
        case HeightFormat::Gwy:
            throw InvalidArgument(
                "height-map format 'gwy' can be read but not written; "
                "write .gsf or .x3p for Gwyddion");
        case HeightFormat::Gsf:
            return formats::encode_gsf(map, options);
        case HeightFormat::Png:
            return formats::encode_png(map, options);
        case HeightFormat::Tiff:
            return formats::encode_tiff(map, options);
        case HeightFormat::Raw:
            return formats::encode_raw(map, options);
    }
    throw InvalidArgument("unknown height-map format");
}

HeightMap read_height_map(const std::filesystem::path& path, const HeightReadOptions& options) {
    const HeightFormat format = format_for(path, options.format);
    const std::string bytes = read_whole_file(path);
    return decode_height_map(bytes, path.string(), format, options);
}

double encoded_size_estimate(std::size_t points, HeightFormat format,
                             const HeightWriteOptions& options) {
    // Bytes a point: the encoders' own reservations (text: up to 20 characters a number), one
    // copy of the samples for the binary formats that convert them first.
    double per_point = 8.0;
    switch (format) {
        case HeightFormat::CsvMatrix:
            per_point = 20.0;
            break;
        case HeightFormat::Xyz:
            per_point = 40.0;
            break;
        case HeightFormat::Sdf:
            per_point = options.sdf_binary ? 8.0 : 20.0;
            break;
        case HeightFormat::X3p:
            per_point = 24.0;  // the samples, the point data's copy and the zip archive
            break;
        case HeightFormat::Png:
            per_point = 4.0;
            break;
        case HeightFormat::Tiff:
            per_point = 8.0;
            break;
        case HeightFormat::Raw:
            per_point = options.raw_type == RawSampleType::Float32 ? 4.0 : 8.0;
            break;
        case HeightFormat::Gwy:
        case HeightFormat::Gsf:
            per_point = 8.0;
            break;
    }
    return per_point * static_cast<double>(points);
}

void write_height_map(const HeightMap& map, const std::filesystem::path& path,
                      const HeightWriteOptions& options) {
    const HeightFormat format = format_for(path, options.format);
    const std::string bytes = encode_height_map(map, format, options);
    io::write_file_atomic(path, bytes);
}

}  // namespace roughscope::surface
