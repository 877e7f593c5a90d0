// JPEG photographs through OpenCV's decoder (cv::imdecode; read.hpp, docs/image.md "JPEG").
// Before OpenCV sees the bytes, the marker segments are walked here: the frame header (SOF) gives
// the size, precision and components, which are checked (so a lying header allocates nothing), an
// APP1 "Exif" segment goes to libexif and APP2 "ICC_PROFILE" segments to the ICC reader. The
// pixels are kept in their stored orientation (IMREAD_IGNORE_ORIENTATION).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "decode.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"

namespace roughscope::image::detail {

namespace {

// A JPEG claiming more than this many pixels per byte of file is refused (baseline JPEG at its
// most compressible, a flat image, holds about 100 to 250 pixels per byte).
constexpr std::uint64_t kJpegMaxPixelsPerByte = 2048;

struct JpegHeader {
    std::size_t width = 0;
    std::size_t height = 0;
    int precision = 0;
    int components = 0;
    Bytes exif;
    std::vector<std::uint8_t> icc;  // the ICC_PROFILE chunks joined in sequence order
};

bool segment_is(Bytes payload, std::string_view tag) {
    return payload.size() >= tag.size() && std::memcmp(payload.data(), tag.data(), tag.size()) == 0;
}

JpegHeader read_header(Bytes bytes, const std::string& name) {
    JpegHeader header;
    std::vector<std::pair<int, Bytes>> icc_chunks;
    std::size_t pos = 2;  // after SOI
    for (;;) {
        while (pos < bytes.size() && bytes[pos] == 0xff && pos + 1 < bytes.size() &&
               bytes[pos + 1] == 0xff)
            ++pos;  // fill bytes
        if (pos + 4 > bytes.size())
            throw DataError(concat(name, ": JPEG ends before its frame header (truncated)"));
        if (bytes[pos] != 0xff)
            throw DataError(
                concat(name, ": corrupt JPEG (no marker at byte ", std::to_string(pos), ")"));
        const std::uint8_t marker = bytes[pos + 1];
        if (marker == 0xd8 || (marker >= 0xd0 && marker <= 0xd7) || marker == 0x01) {
            pos += 2;  // markers without a length
            continue;
        }
        if (marker == 0xd9 || marker == 0xda)
            throw DataError(concat(name, ": corrupt JPEG (no frame header before the scan)"));
        const std::size_t length = (std::size_t{bytes[pos + 2]} << 8) | bytes[pos + 3];
        if (length < 2 || pos + 2 + length > bytes.size())
            throw DataError(concat(name, ": JPEG segment at byte ", std::to_string(pos),
                                   " runs past the end of the file (truncated or corrupt)"));
        const Bytes payload = bytes.subspan(pos + 4, length - 2);
        const bool frame =
            marker >= 0xc0 && marker <= 0xcf && marker != 0xc4 && marker != 0xc8 && marker != 0xcc;
        if (marker == 0xe1 && header.exif.empty() &&
            segment_is(payload, std::string_view("Exif\0\0", 6))) {
            header.exif = payload;
        } else if (marker == 0xe2 && payload.size() > 14 &&
                   segment_is(payload, std::string_view("ICC_PROFILE\0", 12))) {
            icc_chunks.emplace_back(payload[12], payload.subspan(14));
        } else if (frame) {
            if (payload.size() < 6) throw DataError(concat(name, ": corrupt JPEG frame header"));
            header.precision = payload[0];
            header.height = (std::size_t{payload[1]} << 8) | payload[2];
            header.width = (std::size_t{payload[3]} << 8) | payload[4];
            header.components = payload[5];
            if (marker == 0xc3 || marker == 0xc7 || marker == 0xcb || marker == 0xcf)
                throw DataError(concat(name, ": lossless JPEG is not supported"));
            break;
        }
        pos += 2 + length;
    }
    std::sort(icc_chunks.begin(), icc_chunks.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    for (const auto& [sequence, chunk] : icc_chunks)
        header.icc.insert(header.icc.end(), chunk.begin(), chunk.end());
    return header;
}

}  // namespace

LinearImage decode_jpeg(Bytes bytes, const std::string& name, const ReadOptions& options) {
    const JpegHeader header = read_header(bytes, name);
    if (header.precision != 8)
        throw DataError(concat(name, ": JPEG of ", std::to_string(header.precision),
                               "-bit samples is not supported; valid: 8 bits"));
    if (header.components != 1 && header.components != 3)
        throw DataError(concat(name, ": JPEG with ", std::to_string(header.components),
                               " components is not supported; valid: 1 (grey) or 3 (colour)"));
    if (header.height == 0)
        throw DataError(concat(name,
                               ": JPEG whose height is given after the scan (DNL) is not "
                               "supported"));
    check_pixel_count(name, header.width, header.height);
    check_expansion(name, std::uint64_t{header.width} * header.height, bytes.size(),
                    kJpegMaxPixelsPerByte, "JPEG frame header");

    LinearImage image;
    image.info.source = name;
    image.info.format = "jpeg";
    const ExifFields exif = header.exif.empty() ? ExifFields{} : parse_exif(header.exif);
    Evidence evidence;
    if (!header.icc.empty()) evidence = icc_evidence(header.icc, "JPEG ICC profile");
    if (!evidence.known()) {
        if (exif.color_space == 0xffff)
            evidence.text = "EXIF ColorSpace uncalibrated";
        else if (exif.color_space == 1)
            evidence = exif_color_space_evidence(exif);
        else
            evidence = {Response::Srgb, 0.0, "JPEG (sRGB unless stated otherwise)"};
    }
    apply_exif_exposure(exif, image.info);
    warn_orientation(exif.orientation, "EXIF", image.info);

    cv::Mat decoded;
    try {
        const cv::Mat buffer(1, static_cast<int>(std::min<std::size_t>(bytes.size(), 0x7fffffff)),
                             CV_8UC1, const_cast<std::uint8_t*>(bytes.data()));
        decoded = cv::imdecode(buffer, cv::IMREAD_ANYCOLOR | cv::IMREAD_IGNORE_ORIENTATION);
    } catch (const cv::Exception& e) {
        throw DataError(concat(name, ": corrupt JPEG (OpenCV: ", e.what(), ")"));
    }
    if (decoded.empty())
        throw DataError(concat(name, ": corrupt or truncated JPEG (OpenCV could not decode it)"));
    const std::size_t channels = static_cast<std::size_t>(decoded.channels());
    if (decoded.depth() != CV_8U || (channels != 1 && channels != 3) ||
        static_cast<std::size_t>(decoded.cols) != header.width ||
        static_cast<std::size_t>(decoded.rows) != header.height)
        throw DataError(concat(name, ": JPEG decoded to an unexpected layout (corrupt)"));

    Layout layout;
    layout.width = header.width;
    layout.height = header.height;
    layout.channels = channels;
    layout.bits = 8;
    layout.full_scale = 255.0;
    Linearizer lin(image, layout, evidence, options);
    for (std::size_t r = 0; r < header.height; ++r) {
        const std::uint8_t* row = decoded.ptr<std::uint8_t>(static_cast<int>(r));
        if (channels == 1)
            lin.put_pixels(row, r, 1, {0, 0, 0});
        else
            lin.put_pixels(row, r, 3, {2, 1, 0});  // BGR → RGB
    }
    return image;
}

}  // namespace roughscope::image::detail
