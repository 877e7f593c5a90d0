// The image reader's entry points (image/read.hpp): options, the choice of decoder by the file's
// first bytes, and the conversion of stored codes to linear values that every decoder shares.
#include "roughscope/photo/read.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include "decode.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/memory.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/io/input_file.hpp"

namespace roughscope::image {

namespace {

std::string number(double value) { return check::format_number(value); }

bool starts_with(detail::Bytes bytes, std::string_view magic) {
    return bytes.size() >= magic.size() &&
           std::equal(magic.begin(), magic.end(), bytes.begin(),
                      [](char a, std::uint8_t b) { return static_cast<std::uint8_t>(a) == b; });
}

std::string response_name(Response response, double gamma) {
    if (response == Response::Gamma) return concat("gamma ", number(gamma));
    return std::string(to_string(response));
}

// A whole file's bytes: a read-only memory map of a regular file (no copy: the page cache's pages
// are the bytes), else (a file system that cannot map) the bytes read into memory. DataError
// naming the file when it cannot be read or is not a regular file (io/input_file.hpp: a device
// or a FIFO is refused before it is opened). (As with any memory-mapped reader, a
// file truncated by another process while it is being decoded ends the process with SIGBUS.)
class FileBytes {
  public:
    explicit FileBytes(const std::string& path) {
        namespace fs = std::filesystem;
        std::error_code ec;
        const fs::file_status status = fs::status(path, ec);
        if (ec || !fs::exists(status))
            throw DataError(concat("cannot read ", quote_input(path), ": no such file"));
        if (fs::is_directory(status))
            throw DataError(concat("cannot read ", quote_input(path), ": it is a directory"));
        io::check_input_file(path, concat("cannot read ", quote_input(path)));
        const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
        if (fd < 0)
            throw DataError(concat("cannot read ", quote_input(path), ": ", std::strerror(errno)));
        struct stat info {};
        if (::fstat(fd, &info) != 0 || !S_ISREG(info.st_mode)) {  // replaced since the check
            ::close(fd);
            throw DataError(concat("cannot read ", quote_input(path), ": not a regular file"));
        }
        if (info.st_size > 0) {
            void* map = ::mmap(nullptr, static_cast<std::size_t>(info.st_size), PROT_READ,
                               MAP_PRIVATE | MAP_POPULATE, fd, 0);
            if (map != MAP_FAILED) {
                map_ = map;
                size_ = static_cast<std::size_t>(info.st_size);
                ::close(fd);
                return;
            }
        }
        read_all(fd, path);
        ::close(fd);
    }
    ~FileBytes() {
        if (map_ != nullptr) ::munmap(map_, size_);
    }
    FileBytes(const FileBytes&) = delete;
    FileBytes& operator=(const FileBytes&) = delete;
    std::span<const std::uint8_t> bytes() const {
        return map_ != nullptr
                   ? std::span<const std::uint8_t>(static_cast<const std::uint8_t*>(map_), size_)
                   : std::span<const std::uint8_t>(buffer_);
    }

  private:
    void read_all(int fd, const std::string& path) {
        std::uint8_t chunk[65536];
        for (;;) {
            const ssize_t n = ::read(fd, chunk, sizeof chunk);
            if (n == 0) break;
            if (n < 0) {
                if (errno == EINTR) continue;
                const int error = errno;
                ::close(fd);
                throw DataError(
                    concat("cannot read ", quote_input(path), ": ", std::strerror(error)));
            }
            buffer_.insert(buffer_.end(), chunk, chunk + n);
        }
    }

    void* map_ = nullptr;
    std::size_t size_ = 0;
    std::vector<std::uint8_t> buffer_;
};

}  // namespace

void check_read_options(const ReadOptions& options) {
    if (options.response == Response::Gamma) {
        if (!(std::isfinite(options.gamma) && options.gamma > 0.0))
            throw InvalidArgument(concat("gamma = ", number(options.gamma),
                                         " with response gamma; valid: a finite value > 0"));
    } else if (options.gamma != 0.0) {
        throw InvalidArgument(concat("gamma = ", number(options.gamma),
                                     " is used with response gamma only (response ",
                                     options.response ? to_string(*options.response) : "unset",
                                     "); leave gamma at 0 or set response gamma"));
    }
    if (options.black_level_dn) {
        const auto& black = *options.black_level_dn;
        if (black.empty() || black.size() == 2 || black.size() > 3)
            throw InvalidArgument(concat("black_level_dn has ", std::to_string(black.size()),
                                         " values; valid: 1 (every plane) or 1 per plane (3 for "
                                         "R, G, B)"));
        for (std::size_t k = 0; k < black.size(); ++k)
            if (!(std::isfinite(black[k]) && black[k] >= 0.0))
                throw InvalidArgument(concat("black_level_dn[", std::to_string(k), "] = ",
                                             number(black[k]), " DN; valid: a finite value >= 0"));
    }
    if (options.white_level_dn) {
        const double white = *options.white_level_dn;
        if (!(std::isfinite(white) && white > 0.0))
            throw InvalidArgument(
                concat("white_level_dn = ", number(white), " DN; valid: a finite value > 0"));
        if (options.black_level_dn)
            for (std::size_t k = 0; k < options.black_level_dn->size(); ++k)
                if ((*options.black_level_dn)[k] >= white)
                    throw InvalidArgument(
                        concat("black_level_dn[", std::to_string(k),
                               "] = ", number((*options.black_level_dn)[k]),
                               " DN is not below white_level_dn = ", number(white), " DN"));
    }
}

LinearImage read_image(const std::string& path, const ReadOptions& options) {
    check_read_options(options);
    const FileBytes file(path);
    return decode_image(file.bytes(), path, options);
}

LinearImage decode_image(std::span<const std::uint8_t> bytes, const std::string& name,
                         const ReadOptions& options) {
    check_read_options(options);
    if (bytes.empty()) throw DataError(concat(name, ": empty file"));
    LinearImage image;
    if (starts_with(bytes, "\x89PNG\r\n\x1a\n")) {
        image = detail::decode_png(bytes, name, options);
    } else if (starts_with(bytes, "\xff\xd8\xff")) {
        image = detail::decode_jpeg(bytes, name, options);
    } else if (starts_with(bytes, std::string_view("II*\0", 4)) ||
               starts_with(bytes, std::string_view("MM\0*", 4)) ||
               starts_with(bytes, std::string_view("II+\0", 4)) ||
               starts_with(bytes, std::string_view("MM\0+", 4))) {
        std::optional<LinearImage> tiff = detail::decode_tiff(bytes, name, options);
        image = tiff ? std::move(*tiff) : detail::decode_raw(bytes, name, options, false);
    } else {
        // LibRaw reads any file that starts with II or MM as TIFF directories (ORF, RW2, ...),
        // except Canon's CRW (HEAPCCDR at 6): checked first, as a TIFF-structured RAW is.
        const bool tiff_like = starts_with(bytes, "II") || starts_with(bytes, "MM");
        const bool crw = bytes.size() >= 6 && starts_with(bytes.subspan(6), "HEAPCCDR");
        if (tiff_like && !crw) detail::check_raw_structure(bytes, name, true);
        image = detail::decode_raw(bytes, name, options, true);
    }
    if (options.white_balance && image.info.format != "raw")
        image.info.warnings.push_back(concat("white_balance applies to camera RAW files only; ",
                                             image.info.format, " values are left as stored"));
    return image;
}

namespace detail {

void check_pixel_count(const std::string& name, std::size_t width, std::size_t height) {
    if (width == 0 || height == 0)
        throw DataError(concat(name, ": image of ", std::to_string(width), " x ",
                               std::to_string(height), " pixels; it needs at least 1 x 1"));
    if (width > kMaxImagePixels / height)
        throw DataError(concat(name, ": image of ", std::to_string(width), " x ",
                               std::to_string(height), " pixels, more than the ",
                               std::to_string(kMaxImagePixels), " pixels read at most"));
}

void check_expansion(const std::string& name, std::uint64_t decoded_bytes, std::size_t file_bytes,
                     std::uint64_t max_ratio, std::string_view what) {
    if (decoded_bytes / max_ratio > file_bytes)
        throw DataError(concat(name, ": ", what, " claims ", std::to_string(decoded_bytes),
                               " bytes of samples, more than a file of ",
                               std::to_string(file_bytes),
                               " bytes can hold (truncated or corrupt)"));
}

// ---- Linearizer --------------------------------------------------------------------------------

Linearizer::Linearizer(LinearImage& image, const Layout& layout, const Evidence& evidence,
                       const ReadOptions& options)
    : image_(image), full_scale_(layout.full_scale) {
    ImageInfo& info = image.info;
    const std::string& name = info.source;
    check_pixel_count(name, layout.width, layout.height);
    assert(layout.channels == 1 || layout.channels == 3);
    assert(full_scale_ > 0.0);

    info.file_response = evidence.response;
    info.file_response_evidence = evidence.text;
    if (options.response) {
        response_ = *options.response;
        gamma_ = options.gamma;
        if (evidence.known()) {
            const bool same = *evidence.response == response_ &&
                              (response_ != Response::Gamma ||
                               std::abs(evidence.gamma - gamma_) <= 0.01 * gamma_);
            if (!same)
                info.warnings.push_back(concat(
                    "response ", response_name(response_, gamma_), " requested, but the file says ",
                    response_name(*evidence.response, evidence.gamma), " (", evidence.text, ")"));
        }
    } else if (evidence.known()) {
        response_ = *evidence.response;
        gamma_ = response_ == Response::Gamma ? evidence.gamma : 0.0;
    } else {
        response_ = layout.bits == 8 && !layout.is_float ? Response::Srgb : Response::Linear;
    }

    const std::size_t planes = layout.channels;
    black_.assign(planes, 0.0);
    if (options.black_level_dn) {
        const auto& given = *options.black_level_dn;
        if (given.size() != 1 && given.size() != planes)
            throw InvalidArgument(concat("black_level_dn has ", std::to_string(given.size()),
                                         " values, but ", name, " has ", std::to_string(planes),
                                         planes == 1 ? " plane" : " planes", "; give 1 or ",
                                         std::to_string(planes)));
        for (std::size_t c = 0; c < planes; ++c)
            black_[c] = given.size() == 1 ? given[0] : given[c];
    } else if (!layout.default_black.empty()) {
        assert(layout.default_black.size() == planes);
        black_ = layout.default_black;
    }
    white_ = options.white_level_dn ? *options.white_level_dn : full_scale_;
    for (std::size_t c = 0; c < planes; ++c) {
        if (black_[c] < white_) continue;
        const std::string text =
            concat("black level ", number(black_[c]), " DN of plane ", std::to_string(c),
                   " is not below the white level ", number(white_), " DN");
        if (options.black_level_dn || options.white_level_dn)
            throw InvalidArgument(concat(name, ": ", text));
        throw DataError(concat(name, ": ", text, " (corrupt levels)"));
    }
    if (!layout.is_float) {
        // The extreme codes (the response is monotonic) must give values a float holds.
        const double largest =
            layout.largest_code > 0.0 ? layout.largest_code : std::ldexp(1.0, layout.bits) - 1.0;
        for (std::size_t c = 0; c < planes; ++c) {
            const double range = white_ - black_[c];
            const double extreme = std::max(std::abs(linear_code(largest) - black_[c]),
                                            std::abs(linear_code(0.0) - black_[c])) /
                                   range;
            if (extreme <= std::numeric_limits<float>::max()) continue;
            throw InvalidArgument(concat(name, ": black level ", number(black_[c]),
                                         " DN and white level ", number(white_),
                                         " DN give linear values beyond the float range"));
        }
    }

    info.bits_per_sample = layout.bits;
    info.is_float = layout.is_float;
    info.white_level_dn = white_;
    info.black_level_dn = black_;
    info.response = response_;
    info.gamma = gamma_;

    image.width = layout.width;
    image.height = layout.height;
    image.channels = planes;
    resize_large_uninitialised(image.values, planes * layout.width * layout.height);
    assign_large(image.flags, layout.width * layout.height, std::uint8_t{0});
    row_written_.assign(planes * layout.height, 0);
    bits_ = layout.bits;
}

void Linearizer::finish() const {
    const auto missing = std::find(row_written_.begin(), row_written_.end(), 0);
    if (missing == row_written_.end()) return;
    const auto k = static_cast<std::size_t>(missing - row_written_.begin());
    const std::size_t row = k % image_.height, plane = k / image_.height;
    throw DataError(concat(image_.info.source, ": row ", std::to_string(row),
                           image_.channels > 1 ? concat(" of plane ", std::to_string(plane)) : "",
                           " was not decoded (truncated or corrupt)"));
}

double Linearizer::linear_code(double code) const {
    switch (response_) {
        case Response::Linear:
            return code;
        case Response::Srgb:
            return code < 0.0 ? -full_scale_ * srgb_decode(-code / full_scale_)
                              : full_scale_ * srgb_decode(code / full_scale_);
        case Response::Gamma:
            return code < 0.0 ? -full_scale_ * std::pow(-code / full_scale_, gamma_)
                              : full_scale_ * std::pow(code / full_scale_, gamma_);
    }
    return code;
}

void Linearizer::build_tables(int bits) {
    assert(bits >= 1 && bits <= 16);
    table_size_ = std::size_t{1} << bits;
    const std::size_t planes = black_.size();
    value_table_.resize(planes * table_size_);
    flag_table_.resize(planes * table_size_);
    std::vector<double> linear(table_size_);
    for (std::size_t q = 0; q < table_size_; ++q) linear[q] = linear_code(static_cast<double>(q));
    for (std::size_t c = 0; c < planes; ++c) {
        const double range = white_ - black_[c];
        for (std::size_t q = 0; q < table_size_; ++q) {
            const double s = linear[q];
            value_table_[c * table_size_ + q] = static_cast<float>((s - black_[c]) / range);
            std::uint8_t f = 0;
            if (s >= white_) f |= kPixelSaturated;
            if (s <= black_[c]) f |= kPixelClippedLow;
            flag_table_[c * table_size_ + q] = f;
        }
    }
}

template <class T>
void Linearizer::put(const T* samples, std::size_t row, std::size_t stride, std::size_t offset,
                     std::size_t plane) {
    const std::size_t width = image_.width;
    row_written_[plane * image_.height + row] = 1;
    float* out = image_.values.data() + (plane * image_.height + row) * width;
    std::uint8_t* flags = image_.flags.data() + row * width;
    const T* in = samples + offset;
    if constexpr (std::is_same_v<T, float>) {
        const double black = black_[plane];
        const double inverse_range = 1.0 / (white_ - black);
        for (std::size_t x = 0; x < width; ++x) {
            const float q = in[x * stride];
            if (std::isnan(q)) {
                // A missing value (NaN: the usual marker of float rasters, roughscope's maps
                // too): flagged, stored as 0, never averaged.
                out[x] = 0.0F;
                flags[x] |= kPixelMissing;
                continue;
            }
            if (!std::isfinite(q))
                throw DataError(concat(image_.info.source, ": sample ", number(q), " at row ",
                                       std::to_string(row), ", column ", std::to_string(x),
                                       " of plane ", std::to_string(plane),
                                       " is infinite; valid: a finite value, or NaN for a "
                                       "missing one"));
            const double s = response_ == Response::Linear ? q : linear_code(q);
            const double value = (s - black) * inverse_range;
            if (!(std::abs(value) <= std::numeric_limits<float>::max()))
                throw DataError(concat(
                    image_.info.source, ": sample ", number(q), " at row ", std::to_string(row),
                    ", column ", std::to_string(x), " of plane ", std::to_string(plane),
                    " gives the linear value ", number(value), ", beyond the float range"));
            out[x] = static_cast<float>(value);
            std::uint8_t f = 0;
            if (s >= white_) f |= kPixelSaturated;
            if (s <= black) f |= kPixelClippedLow;
            flags[x] |= f;
        }
    } else if (response_ == Response::Linear) {
        static_assert(std::is_same_v<T, std::uint8_t> || std::is_same_v<T, std::uint16_t>);
        const double black = black_[plane];
        const double inverse_range = 1.0 / (white_ - black);
        for (std::size_t x = 0; x < width; ++x) {
            const double q = in[x * stride];
            out[x] = static_cast<float>((q - black) * inverse_range);
            flags[x] |= static_cast<std::uint8_t>((q >= white_ ? kPixelSaturated : 0) |
                                                  (q <= black ? kPixelClippedLow : 0));
        }
    } else {
        if (value_table_.empty()) build_tables(bits_);
        const float* values = value_table_.data() + plane * table_size_;
        const std::uint8_t* table_flags = flag_table_.data() + plane * table_size_;
        for (std::size_t x = 0; x < width; ++x) {
            const std::size_t q = in[x * stride];
            assert(q < table_size_);
            out[x] = values[q];
            flags[x] |= table_flags[q];
        }
    }
}

// The common case (integer codes, linear response) with every plane of a pixel in one pass: the
// flags come from integer thresholds (q ≥ white ⇔ q ≥ ⌈white⌉, q ≤ black ⇔ q ≤ ⌊black⌋).
template <std::size_t Planes, class T>
void put_linear_pixels(LinearImage& image, const T* samples, std::size_t row, std::size_t stride,
                       const std::array<std::size_t, 3>& offsets, const std::vector<double>& black,
                       double white) {
    const std::size_t width = image.width;
    const std::size_t plane_size = width * image.height;
    float* out[Planes];
    float black_f[Planes];
    float scale_f[Planes];
    std::uint64_t low_q[Planes];
    for (std::size_t c = 0; c < Planes; ++c) {
        out[c] = image.values.data() + c * plane_size + row * width;
        black_f[c] = static_cast<float>(black[c]);
        scale_f[c] = static_cast<float>(1.0 / (white - black[c]));
        low_q[c] = static_cast<std::uint64_t>(std::floor(black[c]));
    }
    const std::uint64_t high_q = static_cast<std::uint64_t>(std::min(std::ceil(white), 1e18));
    std::uint8_t* flags = image.flags.data() + row * width;
    if constexpr (Planes == 1) {
        if (stride == 1) {
            // Contiguous grey samples (the usual 16-bit TIFF/PNG): a loop the compiler vectorises,
            // with the thresholds as 32-bit integers (codes are at most 16 bits, so clamping them
            // to [−1, 2¹⁷] changes no comparison).
            const T* in = samples + offsets[0];
            float* o = out[0];
            const float b = black_f[0];
            const float scale = scale_f[0];
            constexpr std::uint64_t kClamp = std::uint64_t{1} << 17;
            const auto high = static_cast<std::int32_t>(std::min(high_q, kClamp));
            const auto low = static_cast<std::int32_t>(std::min(low_q[0], kClamp));
            for (std::size_t x = 0; x < width; ++x) {
                const std::int32_t q = in[x];
                o[x] = (static_cast<float>(q) - b) * scale;
                flags[x] |= static_cast<std::uint8_t>((q >= high ? kPixelSaturated : 0) |
                                                      (q <= low ? kPixelClippedLow : 0));
            }
            return;
        }
    }
    for (std::size_t x = 0; x < width; ++x) {
        const T* pixel = samples + x * stride;
        std::uint8_t f = 0;
        for (std::size_t c = 0; c < Planes; ++c) {
            const std::uint64_t q = pixel[offsets[c]];
            out[c][x] = (static_cast<float>(q) - black_f[c]) * scale_f[c];
            f |= static_cast<std::uint8_t>((q >= high_q ? kPixelSaturated : 0) |
                                           (q <= low_q[c] ? kPixelClippedLow : 0));
        }
        flags[x] |= f;
    }
}

template <class T>
void Linearizer::put_pixels(const T* samples, std::size_t row, std::size_t stride,
                            const std::array<std::size_t, 3>& offsets) {
    for (std::size_t c = 0; c < black_.size(); ++c) row_written_[c * image_.height + row] = 1;
    if constexpr (!std::is_same_v<T, float>) {
        if (response_ == Response::Linear) {
            if (black_.size() == 1)
                put_linear_pixels<1>(image_, samples, row, stride, offsets, black_, white_);
            else
                put_linear_pixels<3>(image_, samples, row, stride, offsets, black_, white_);
            return;
        }
    }
    for (std::size_t c = 0; c < black_.size(); ++c) put(samples, row, stride, offsets[c], c);
}

template void Linearizer::put_pixels<std::uint8_t>(const std::uint8_t*, std::size_t, std::size_t,
                                                   const std::array<std::size_t, 3>&);
template void Linearizer::put_pixels<std::uint16_t>(const std::uint16_t*, std::size_t, std::size_t,
                                                    const std::array<std::size_t, 3>&);
template void Linearizer::put_pixels<float>(const float*, std::size_t, std::size_t,
                                            const std::array<std::size_t, 3>&);
template void Linearizer::put<std::uint8_t>(const std::uint8_t*, std::size_t, std::size_t,
                                            std::size_t, std::size_t);
template void Linearizer::put<std::uint16_t>(const std::uint16_t*, std::size_t, std::size_t,
                                             std::size_t, std::size_t);
template void Linearizer::put<float>(const float*, std::size_t, std::size_t, std::size_t,
                                     std::size_t);

}  // namespace detail

}  // namespace roughscope::image
