// JPEG photographs through libjpeg(-turbo) (read.hpp, docs/image.md "JPEG"). Before the decoder
// sees the bytes, the marker segments are walked here: the frame header (SOF) gives the size,
// precision and components, which are checked (so a lying header allocates nothing), an APP1
// "Exif" segment goes to libexif and APP2 "ICC_PROFILE" segments to the ICC reader. The pixels
// stay in their stored orientation.
//
// libjpeg is driven directly rather than through OpenCV's cv::imdecode, whose libjpeg error
// manager prints corrupt-data warnings to stderr: here every message goes to the decoder's own
// handler (nothing printed) and a warning about corrupt data makes the file a DataError.
// libjpeg reports fatal errors by longjmp: as for PNG, everything with a destructor lives in a
// JpegState owned by decode_jpeg, and jpeg_body (the only function libjpeg jumps into) has
// trivial locals.
#include <algorithm>
#include <csetjmp>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <jpeglib.h>

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

namespace {

struct JpegError {
    jpeg_error_mgr manager{};  // first member: libjpeg's cinfo->err points here
    std::jmp_buf jump{};
    char message[JMSG_LENGTH_MAX] = {};
};

[[noreturn]] void jpeg_fail(j_common_ptr cinfo) {
    auto* error = reinterpret_cast<JpegError*>(cinfo->err);
    (*cinfo->err->format_message)(cinfo, error->message);
    std::longjmp(error->jump, 1);
}

// Warnings (level −1: corrupt data) are counted and the first one kept; trace messages dropped.
void jpeg_message(j_common_ptr cinfo, int level) {
    auto* error = reinterpret_cast<JpegError*>(cinfo->err);
    if (level >= 0) return;
    if (error->manager.num_warnings++ == 0) (*cinfo->err->format_message)(cinfo, error->message);
}

void jpeg_no_output(j_common_ptr) {}

struct JpegState {
    const std::string* name = nullptr;
    const ReadOptions* options = nullptr;
    Bytes bytes;
    jpeg_decompress_struct cinfo{};
    JpegError error;
    bool created = false;
    LinearImage image;
    Layout layout;
    Evidence evidence;
    std::optional<Linearizer> linearizer;
    std::vector<std::uint8_t> row;
    JpegState() = default;
    JpegState(const JpegState&) = delete;
    JpegState& operator=(const JpegState&) = delete;
    ~JpegState() {
        if (created) jpeg_destroy_decompress(&cinfo);
    }
};

bool jpeg_body(JpegState& st) {
    if (setjmp(st.error.jump) != 0) return false;
    jpeg_create_decompress(&st.cinfo);
    st.created = true;
    jpeg_mem_src(&st.cinfo, st.bytes.data(), static_cast<unsigned long>(st.bytes.size()));
    jpeg_read_header(&st.cinfo, TRUE);
    st.cinfo.out_color_space = st.layout.channels == 1 ? JCS_GRAYSCALE : JCS_RGB;
    jpeg_start_decompress(&st.cinfo);
    if (st.cinfo.output_width != st.layout.width || st.cinfo.output_height != st.layout.height ||
        static_cast<std::size_t>(st.cinfo.output_components) != st.layout.channels)
        throw DataError(concat(*st.name, ": JPEG decoded to an unexpected layout (corrupt)"));
    st.linearizer.emplace(st.image, st.layout, st.evidence, *st.options);
    st.row.resize(st.layout.width * st.layout.channels);
    while (st.cinfo.output_scanline < st.cinfo.output_height) {
        const std::size_t r = st.cinfo.output_scanline;
        JSAMPROW rows[1] = {st.row.data()};
        if (jpeg_read_scanlines(&st.cinfo, rows, 1) != 1) break;  // suspended: cannot happen
        st.linearizer->put_pixels(st.row.data(), r, st.layout.channels, {0, 1, 2});
    }
    st.linearizer->finish();
    jpeg_finish_decompress(&st.cinfo);
    return true;
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

    JpegState st;
    st.name = &name;
    st.options = &options;
    st.bytes = bytes;
    st.image.info.source = name;
    st.image.info.format = "jpeg";
    const ExifFields exif = header.exif.empty() ? ExifFields{} : parse_exif(header.exif);
    if (!header.icc.empty()) st.evidence = icc_evidence(header.icc, "JPEG ICC profile");
    if (!st.evidence.known()) {
        if (exif.color_space == 0xffff)
            st.evidence.text = "EXIF ColorSpace uncalibrated";
        else if (exif.color_space == 1)
            st.evidence = exif_color_space_evidence(exif);
        else
            st.evidence = {Response::Srgb, 0.0, "JPEG (sRGB unless stated otherwise)"};
    }
    apply_exif_exposure(exif, st.image.info);
    warn_orientation(exif.orientation, "EXIF", st.image.info);
    st.layout.width = header.width;
    st.layout.height = header.height;
    st.layout.channels = static_cast<std::size_t>(header.components);
    st.layout.bits = 8;
    st.layout.full_scale = 255.0;

    st.cinfo.err = jpeg_std_error(&st.error.manager);
    st.error.manager.error_exit = jpeg_fail;
    st.error.manager.emit_message = jpeg_message;
    st.error.manager.output_message = jpeg_no_output;
    if (!jpeg_body(st))
        throw DataError(
            concat(name, ": corrupt or truncated JPEG (libjpeg: ", st.error.message, ")"));
    if (st.error.manager.num_warnings > 0)
        throw DataError(
            concat(name, ": corrupt or truncated JPEG (libjpeg: ", st.error.message, ")"));
    return std::move(st.image);
}

}  // namespace roughscope::image::detail
