// x3p (ISO 25178-72 / ISO 5436-2): a zip archive holding main.xml (axes, grid size, the data or a
// link to bindata/*.bin) and md5checksum.hex (the MD5 of main.xml). The zip is read and written
// with libzip in memory, the XML with tinyxml2, the checksums with OpenSSL's EVP MD5.
// Conventions, units and the checksum policy: docs/height-files.md, section "x3p".
#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include <openssl/evp.h>
#include <tinyxml2.h>
#include <zip.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/memory.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/surface/formats.hpp"
#include "x3p_text.hpp"

namespace roughscope::surface::formats {

namespace {

static_assert(std::endian::native == std::endian::little,
              "the x3p binary data are little-endian; this reader assumes a little-endian host");

[[noreturn]] void fail(const std::string& name, std::string_view what) {
    std::string message = name;
    message.append(": ").append(what);
    throw DataError(message);
}

// ---- MD5 ------------------------------------------------------------------------------------

class Md5 {
  public:
    Md5() : ctx_(EVP_MD_CTX_new()) {
        if (!ctx_ || EVP_DigestInit_ex(ctx_.get(), EVP_md5(), nullptr) != 1) {
            throw Error("x3p: OpenSSL cannot compute MD5 checksums");
        }
    }
    void update(const void* data, std::size_t size) {
        if (size != 0) EVP_DigestUpdate(ctx_.get(), data, size);
    }
    std::string hex() {
        unsigned char digest[EVP_MAX_MD_SIZE];
        unsigned int length = 0;
        EVP_DigestFinal_ex(ctx_.get(), digest, &length);
        static constexpr char kDigits[] = "0123456789abcdef";
        std::string out;
        for (unsigned int i = 0; i < length; ++i) {
            out.push_back(kDigits[digest[i] >> 4]);
            out.push_back(kDigits[digest[i] & 15]);
        }
        return out;
    }

  private:
    struct Free {
        void operator()(EVP_MD_CTX* c) const { EVP_MD_CTX_free(c); }
    };
    std::unique_ptr<EVP_MD_CTX, Free> ctx_;
};

std::string md5_hex(std::string_view data) {
    Md5 md5;
    md5.update(data.data(), data.size());
    return md5.hex();
}

std::string_view trim(std::string_view s) {
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
    return s;
}

bool is_md5_hex(std::string_view s) {
    return s.size() == 32 && std::all_of(s.begin(), s.end(), [](char c) {
               return std::isxdigit(static_cast<unsigned char>(c)) != 0;
           });
}

bool same_md5(std::string_view a, std::string_view b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i) {
        if (std::tolower(static_cast<unsigned char>(a[i])) !=
            std::tolower(static_cast<unsigned char>(b[i]))) {
            return false;
        }
    }
    return true;
}

// ---- numbers in main.xml -----------------------------------------------------------------------

// The decimal number `text` (metres) in micrometres, correctly rounded: the decimal exponent is
// shifted by 6 in the text before the one rounding to double, so "2.58e-06" gives exactly 2.58
// and a length the writer printed from a µm value comes back bit for bit.
double parse_decimal(std::string_view text, int shift, const std::string& name,
                     std::string_view element) {
    const std::string_view t = trim(text);
    auto bad = [&]() -> double {
        std::string what = "<";
        what.append(element).append("> is not a number: ").append(quote_input(t));
        fail(name, what);
    };
    std::size_t i = 0;
    std::string mantissa;
    if (i < t.size() && (t[i] == '+' || t[i] == '-')) {
        if (t[i] == '-') mantissa.push_back('-');
        ++i;
    }
    std::size_t digits = 0;
    while (i < t.size() && std::isdigit(static_cast<unsigned char>(t[i]))) {
        mantissa.push_back(t[i++]);
        ++digits;
    }
    if (i < t.size() && t[i] == '.') {
        mantissa.push_back(t[i++]);
        while (i < t.size() && std::isdigit(static_cast<unsigned char>(t[i]))) {
            mantissa.push_back(t[i++]);
            ++digits;
        }
    }
    if (digits == 0) return bad();
    long long exponent = 0;
    if (i < t.size() && (t[i] == 'e' || t[i] == 'E')) {
        ++i;
        if (i < t.size() && t[i] == '+') ++i;
        const char* first = t.data() + i;
        const char* last = t.data() + t.size();
        const auto [ptr, ec] = std::from_chars(first, last, exponent);
        if (ec != std::errc{} || ptr != last) return bad();
        i = t.size();
        if (exponent < -100000 || exponent > 100000) return bad();
    }
    if (i != t.size()) return bad();
    mantissa.append("e").append(std::to_string(exponent + shift));
    double value = 0.0;
    const auto [ptr, ec] =
        std::from_chars(mantissa.data(), mantissa.data() + mantissa.size(), value);
    if (ec == std::errc::result_out_of_range) {
        // Underflow to zero is harmless for offsets; overflow is not a length.
        if (std::fabs(value) > 1.0) return bad();
    } else if (ec != std::errc{} || ptr != mantissa.data() + mantissa.size()) {
        return bad();
    }
    if (!std::isfinite(value)) return bad();
    return value;
}

double metres_text_to_um(std::string_view text, const std::string& name, std::string_view element) {
    return parse_decimal(text, 6, name, element);
}

// `um` (µm) as decimal metres that metres_text_to_um() reads back exactly: the shortest
// round-trip digits of the µm value with the exponent lowered by 6.
std::string um_to_metres_text(double um) {
    char buffer[64];
    const auto result =
        std::to_chars(buffer, buffer + sizeof buffer, um, std::chars_format::scientific);
    const std::string_view text(buffer, static_cast<std::size_t>(result.ptr - buffer));
    const std::size_t e = text.find('e');
    int exponent = 0;
    std::from_chars(text.data() + e + 1 + (text[e + 1] == '+' ? 1 : 0), text.data() + text.size(),
                    exponent);
    std::string out(text.substr(0, e));
    out.append("e").append(std::to_string(exponent - 6));
    return out;
}

std::size_t parse_count(std::string_view text, const std::string& name, std::string_view element) {
    const std::string_view t = trim(text);
    std::size_t value = 0;
    const auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), value);
    if (t.empty() || ec != std::errc{} || ptr != t.data() + t.size()) {
        std::string what = "<";
        what.append(element).append("> is not a count: ").append(quote_input(t));
        fail(name, what);
    }
    return value;
}

// ---- zip in memory ---------------------------------------------------------------------------

struct ZipCloser {
    void operator()(zip_t* z) const { zip_discard(z); }
};
using ZipPtr = std::unique_ptr<zip_t, ZipCloser>;
struct ZipFileCloser {
    void operator()(zip_file_t* f) const { zip_fclose(f); }
};
using ZipFilePtr = std::unique_ptr<zip_file_t, ZipFileCloser>;

// Uncompressed bytes a deflate stream can produce per compressed byte (the format's bound is
// 1032:1); a member claiming more is corrupt, and is refused before anything is allocated.
constexpr std::uint64_t kMaxInflateRatio = 1100;

class ZipArchive {
  public:
    ZipArchive(std::string_view bytes, const std::string& name) : name_(name) {
        zip_error_t error;
        zip_error_init(&error);
        zip_source_t* source = zip_source_buffer_create(bytes.data(), bytes.size(), 0, &error);
        if (!source) fail(name, "cannot open the zip archive (out of memory)");
        zip_t* archive = zip_open_from_source(source, ZIP_RDONLY, &error);
        if (!archive) {
            zip_source_free(source);
            std::string what = "not a readable zip archive (";
            what.append(zip_error_strerror(&error)).append(")");
            zip_error_fini(&error);
            fail(name, what);
        }
        zip_error_fini(&error);
        archive_.reset(archive);
        input_size_ = bytes.size();
    }

    zip_t* get() const { return archive_.get(); }

    std::vector<std::string> entry_names() const {
        std::vector<std::string> names;
        const zip_int64_t n = zip_get_num_entries(archive_.get(), 0);
        for (zip_int64_t i = 0; i < n; ++i) {
            const char* entry = zip_get_name(archive_.get(), static_cast<zip_uint64_t>(i), 0);
            if (entry) names.emplace_back(entry);
        }
        return names;
    }

    bool has(const std::string& entry) const {
        return zip_name_locate(archive_.get(), entry.c_str(), 0) >= 0;
    }

    // The uncompressed size of `entry`, checked against the bytes present.
    std::uint64_t size_of(const std::string& entry) const {
        zip_stat_t st;
        zip_stat_init(&st);
        if (zip_stat(archive_.get(), entry.c_str(), 0, &st) != 0 || !(st.valid & ZIP_STAT_SIZE) ||
            !(st.valid & ZIP_STAT_COMP_SIZE)) {
            fail(name_, concat("cannot read the zip entry ", quote_input(entry)));
        }
        if (st.comp_size > input_size_ || st.size > (st.comp_size + 64) * kMaxInflateRatio) {
            std::string what = "the zip entry ";
            what.append(quote_input(entry))
                .append(" claims ")
                .append(std::to_string(st.size))
                .append(" bytes, more than its ")
                .append(std::to_string(st.comp_size))
                .append(" compressed bytes can hold (truncated or corrupt archive)");
            fail(name_, what);
        }
        return st.size;
    }

    ZipFilePtr open(const std::string& entry) const {
        zip_file_t* file = zip_fopen(archive_.get(), entry.c_str(), 0);
        if (!file) {
            std::string what = "cannot open the zip entry ";
            what.append(quote_input(entry))
                .append(" (")
                .append(zip_strerror(archive_.get()))
                .append(")");
            fail(name_, what);
        }
        return ZipFilePtr(file);
    }

    // Reads up to `size` bytes; DataError when the entry ends early or is corrupt.
    void read_exact(zip_file_t* file, const std::string& entry, void* out, std::size_t size) const {
        auto* p = static_cast<char*>(out);
        while (size > 0) {
            const zip_int64_t got = zip_fread(file, p, size);
            if (got <= 0) {
                std::string what = "cannot read the zip entry ";
                what.append(quote_input(entry)).append(" (");
                what.append(got < 0 ? zip_file_strerror(file) : "it ends early").append(")");
                fail(name_, what);
            }
            p += got;
            size -= static_cast<std::size_t>(got);
        }
    }

    // Whether `entry` is stored (not compressed, not encrypted): its bytes can be read in windows.
    bool is_stored(const std::string& entry) const {
        zip_stat_t st;
        zip_stat_init(&st);
        return zip_stat(archive_.get(), entry.c_str(), 0, &st) == 0 &&
               (st.valid & ZIP_STAT_COMP_METHOD) && st.comp_method == ZIP_CM_STORE &&
               (!(st.valid & ZIP_STAT_ENCRYPTION_METHOD) || st.encryption_method == ZIP_EM_NONE);
    }

    // Bytes [start, start + size) of the stored `entry`, through a window of the archive. libzip
    // checks a member's CRC-32 only when the whole member is read, so a read in windows skips that
    // checksum (a read that does not verify checksums).
    void read_window(const std::string& entry, std::uint64_t start, void* out,
                     std::size_t size) const {
        const zip_int64_t index = zip_name_locate(archive_.get(), entry.c_str(), 0);
        zip_source_t* window = index < 0 ? nullptr
                                         : zip_source_zip(archive_.get(), archive_.get(),
                                                          static_cast<zip_uint64_t>(index), 0,
                                                          start, static_cast<zip_int64_t>(size));
        if (!window || zip_source_open(window) != 0) {
            if (window) zip_source_free(window);
            fail(name_, concat("cannot open the zip entry ", quote_input(entry), " (",
                               zip_strerror(archive_.get()), ")"));
        }
        auto* p = static_cast<char*>(out);
        std::size_t left = size;
        while (left > 0) {
            const zip_int64_t got = zip_source_read(window, p, left);
            if (got <= 0) break;
            p += got;
            left -= static_cast<std::size_t>(got);
        }
        zip_source_close(window);
        zip_source_free(window);
        if (left > 0)
            fail(name_,
                 concat("cannot read the zip entry ", quote_input(entry), " (it ends early)"));
    }

    std::string read_all(const std::string& entry) const {
        const std::uint64_t size = size_of(entry);
        ZipFilePtr file = open(entry);
        std::string out(static_cast<std::size_t>(size), '\0');
        read_exact(file.get(), entry, out.data(), out.size());
        expect_end(file.get(), entry);
        return out;
    }

    // After the entry's bytes: its end (libzip then compares the CRC-32 of what was read with the
    // archive's), else a DataError.
    void expect_end(zip_file_t* file, const std::string& entry) const {
        char extra = 0;
        const zip_int64_t got = zip_fread(file, &extra, 1);
        if (got < 0)
            fail(name_, concat("cannot read the zip entry ", quote_input(entry), " (",
                               zip_file_strerror(file), ")"));
        if (got != 0)
            fail(name_, concat("the zip entry ", quote_input(entry), " is longer than it claims"));
    }

  private:
    std::string name_;
    ZipPtr archive_;
    std::size_t input_size_ = 0;
};

bool is_os_metadata(std::string_view entry) {
    if (entry.starts_with("__MACOSX/")) return true;
    const std::size_t slash = entry.rfind('/');
    const std::string_view leaf = slash == std::string_view::npos ? entry : entry.substr(slash + 1);
    return leaf == ".DS_Store" || leaf.starts_with("._");
}

// The folder main.xml sits in ("" or "top/"): files nested under one top folder are accepted.
std::string find_main_xml(const ZipArchive& zip, const std::string& name) {
    std::optional<std::string> nested;
    for (const std::string& entry : zip.entry_names()) {
        if (is_os_metadata(entry)) continue;
        if (entry == "main.xml") return "";
        if (entry.ends_with("/main.xml") && std::count(entry.begin(), entry.end(), '/') == 1) {
            if (nested) fail(name, "the zip holds more than one top folder with a main.xml");
            nested = entry.substr(0, entry.size() - std::string_view("main.xml").size());
        }
    }
    if (!nested) fail(name, "the zip holds no main.xml (not an x3p file)");
    return *nested;
}

// ---- main.xml ---------------------------------------------------------------------------------

const tinyxml2::XMLElement* child(const tinyxml2::XMLElement* parent, const char* tag) {
    return parent ? parent->FirstChildElement(tag) : nullptr;
}

std::string_view text_of(const tinyxml2::XMLElement* e) {
    if (!e) return {};
    const char* t = e->GetText();
    return t ? std::string_view(t) : std::string_view();
}

const tinyxml2::XMLElement* require(const tinyxml2::XMLElement* parent, const char* tag,
                                    const std::string& name, std::string_view path) {
    const tinyxml2::XMLElement* e = child(parent, tag);
    if (!e) {
        std::string what = "main.xml has no <";
        what.append(path).append(">");
        fail(name, what);
    }
    return e;
}

enum class SampleType { Int16, Int32, Float32, Float64 };

std::size_t sample_bytes(SampleType t) {
    switch (t) {
        case SampleType::Int16:
            return 2;
        case SampleType::Int32:
        case SampleType::Float32:
            return 4;
        case SampleType::Float64:
            return 8;
    }
    return 8;
}

struct Axis {
    bool incremental = false;
    SampleType type = SampleType::Float64;
    bool has_increment = false;
    double increment_um = 1e6;  // 1 m: the default of an axis without <Increment>
    double offset_um = 0.0;
};

Axis read_axis(const tinyxml2::XMLElement* axes, const char* tag, const std::string& name) {
    std::string path = "Record1/Axes/";
    path.append(tag);
    const tinyxml2::XMLElement* e = require(axes, tag, name, path);
    Axis axis;
    const std::string_view type = trim(text_of(require(e, "AxisType", name, path + "/AxisType")));
    if (type == "I") {
        axis.incremental = true;
    } else if (type != "A") {
        fail(name, path + "/AxisType must be I or A, not " + quote_input(type));
    }
    if (const auto* dt = child(e, "DataType")) {
        const std::string_view d = trim(text_of(dt));
        if (d == "I") {
            axis.type = SampleType::Int16;
        } else if (d == "L") {
            axis.type = SampleType::Int32;
        } else if (d == "F") {
            axis.type = SampleType::Float32;
        } else if (d == "D") {
            axis.type = SampleType::Float64;
        } else {
            fail(name, path + "/DataType must be I, L, F or D, not " + quote_input(d));
        }
    } else if (!axis.incremental) {
        fail(name, concat("main.xml has no <", path, "/DataType>"));
    }
    if (const auto* inc = child(e, "Increment"); inc && !trim(text_of(inc)).empty()) {
        axis.has_increment = true;
        axis.increment_um = metres_text_to_um(text_of(inc), name, path + "/Increment");
    }
    if (const auto* off = child(e, "Offset"); off && !trim(text_of(off)).empty()) {
        axis.offset_um = metres_text_to_um(text_of(off), name, path + "/Offset");
    }
    return axis;
}

// physical = offset + increment × value, with the multiplication and the addition skipped when
// they are the identity (so a value stored in µm with Increment 1e-6 m is kept bit for bit).
struct Scale {
    double factor_um = 1.0;
    double offset_um = 0.0;
    double apply(double value) const {
        if (factor_um != 1.0) value *= factor_um;
        if (offset_um != 0.0) value += offset_um;
        return value;
    }
};

template <class T>
T load(const char* p) {
    T v;
    std::memcpy(&v, p, sizeof v);
    return v;
}

double sample_value(SampleType type, const char* p) {
    switch (type) {
        case SampleType::Int16:
            return load<std::int16_t>(p);
        case SampleType::Int32:
            return load<std::int32_t>(p);
        case SampleType::Float32:
            return static_cast<double>(load<float>(p));
        case SampleType::Float64:
            return load<double>(p);
    }
    return 0.0;
}

void check_md5(const std::string& name, const std::string& file, std::string_view expected,
               const std::string& actual, const char* which) {
    const std::string_view want = trim(expected);
    if (!is_md5_hex(want)) {
        std::string what = which;
        what.append(" for ")
            .append(file)
            .append(" is not 32 hex digits: ")
            .append(quote_input(want));
        fail(name, what);
    }
    if (!same_md5(want, actual)) {
        std::string what = "checksum mismatch: ";
        what.append(file)
            .append(" has MD5 ")
            .append(actual)
            .append(" but ")
            .append(which)
            .append(" says ")
            .append(want)
            .append(
                " (changed after the checksum was written, or corrupt; a read that does not "
                "verify checksums takes it as it is)");
        fail(name, what);
    }
}

// The binary point data (only Z per point: incremental CX and CY), converted chunk by chunk while
// its MD5 is computed, so no second copy of the data is held.
void read_binary_heights(const ZipArchive& zip, const std::string& name, const std::string& entry,
                         SampleType type, const Scale& scale, std::size_t points,
                         std::optional<std::string_view> expected_md5, bool verify,
                         std::vector<double>& heights, HeightsScan& scan) {
    if (!zip.has(entry))
        fail(name, concat("main.xml links ", quote_input(entry), ", absent from the zip"));
    const std::size_t bytes_per_point = sample_bytes(type);
    const std::uint64_t size = zip.size_of(entry);
    if (size != static_cast<std::uint64_t>(points) * bytes_per_point) {
        std::string what = entry;
        what.append(" holds ")
            .append(std::to_string(size))
            .append(" bytes; main.xml's MatrixDimension and CZ/DataType need ")
            .append(std::to_string(points))
            .append(" x ")
            .append(std::to_string(bytes_per_point))
            .append(" bytes");
        fail(name, what);
    }
    assign_large(heights, points, 0.0);
    // Without verification a stored entry is read in windows, which skips libzip's CRC-32 pass.
    const bool windows = !verify && zip.is_stored(entry);
    ZipFilePtr file = windows ? nullptr : zip.open(entry);
    const auto read = [&](void* to, std::size_t offset_points, std::size_t bytes) {
        if (windows)
            zip.read_window(entry, offset_points * bytes_per_point, to, bytes);
        else
            zip.read_exact(file.get(), entry, to, bytes);
    };
    Md5 md5;
    constexpr std::size_t kChunkPoints = 1 << 16;
    // Doubles already in µm are read straight into the heights (checksummed there, before
    // non-finite values become NaN); other samples through a chunk buffer.
    const bool direct =
        type == SampleType::Float64 && scale.factor_um == 1.0 && scale.offset_um == 0.0;
    std::vector<char> buffer(direct ? 0 : kChunkPoints * bytes_per_point);
    for (std::size_t done = 0; done < points;) {
        const std::size_t n = std::min(kChunkPoints, points - done);
        double* out = heights.data() + done;
        if (direct) {
            read(out, done, n * sizeof(double));
            if (verify) md5.update(reinterpret_cast<const char*>(out), n * sizeof(double));
            // ±inf and NaN become the quiet NaN (a compare and a blend: vectorised).
            constexpr double kLargest = std::numeric_limits<double>::max();
            constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
            for (std::size_t i = 0; i < n; ++i)
                out[i] = std::abs(out[i]) <= kLargest ? out[i] : kNaN;
        } else {
            read(buffer.data(), done, n * bytes_per_point);
            if (verify) md5.update(buffer.data(), n * bytes_per_point);
            for (std::size_t i = 0; i < n; ++i) {
                const double v = sample_value(type, buffer.data() + i * bytes_per_point);
                out[i] =
                    std::isfinite(v) ? scale.apply(v) : std::numeric_limits<double>::quiet_NaN();
            }
        }
        // validate's height rule on the chunk while it is in cache.
        const HeightsScan chunk = scan_heights(out, n);
        if (chunk.first_out_of_range < n && scan.first_out_of_range == points)
            scan.first_out_of_range = done + chunk.first_out_of_range;
        scan.any_valid = scan.any_valid || chunk.any_valid;
        done += n;
    }
    // libzip compares a member's CRC-32 when a read reaches its end: one more read (verifying).
    if (verify) zip.expect_end(file.get(), entry);
    if (verify && expected_md5)
        check_md5(name, entry, *expected_md5, md5.hex(), "MD5ChecksumPointData");
}

void apply_validity(const ZipArchive& zip, const std::string& name, const std::string& entry,
                    std::optional<std::string_view> expected_md5, bool verify,
                    std::vector<double>& heights) {
    if (!zip.has(entry))
        fail(name, concat("main.xml links ", quote_input(entry), ", absent from the zip"));
    const std::size_t need = (heights.size() + 7) / 8;
    if (zip.size_of(entry) != need) {
        std::string what = entry;
        what.append(" must hold ")
            .append(std::to_string(need))
            .append(" bytes (one bit per point)");
        fail(name, what);
    }
    const std::string bits = zip.read_all(entry);
    if (verify && expected_md5) {
        check_md5(name, entry, *expected_md5, md5_hex(bits), "MD5ChecksumValidPoints");
    }
    for (std::size_t i = 0; i < heights.size(); ++i) {
        // Bit i % 8 (least significant first) of byte i / 8: 1 = valid (ISO 5436-2).
        if (((static_cast<unsigned char>(bits[i / 8]) >> (i % 8)) & 1U) == 0) {
            heights[i] = std::numeric_limits<double>::quiet_NaN();
        }
    }
}

// One <Datum>: ';'-separated values of the absolute axes, in the order X, Y, Z present.
void read_data_list(const tinyxml2::XMLElement* list, const std::string& name, const Axis& cx,
                    const Axis& cy, const Axis& cz, std::size_t nx, std::size_t ny,
                    HeightMap& map) {
    std::size_t count = 0;
    for (const auto* d = list->FirstChildElement("Datum"); d; d = d->NextSiblingElement("Datum")) {
        ++count;
    }
    if (count != nx * ny) {
        std::string what = "Record3/DataList holds ";
        what.append(std::to_string(count))
            .append(" <Datum> elements; MatrixDimension needs ")
            .append(std::to_string(nx * ny));
        fail(name, what);
    }
    const std::size_t columns = (cx.incremental ? 0 : 1) + (cy.incremental ? 0 : 1) + 1;
    // An absolute integer-coded X or Y column must step by one count per column or row.
    std::optional<double> y_first;
    std::optional<double> x_first;
    assign_large(map.heights_um, nx * ny, std::numeric_limits<double>::quiet_NaN());
    std::size_t k = 0;
    for (const auto* d = list->FirstChildElement("Datum"); d;
         d = d->NextSiblingElement("Datum"), ++k) {
        const std::string_view text = trim(text_of(d));
        if (text.empty()) continue;  // an empty Datum is a missing point
        std::vector<std::string_view> fields;
        std::size_t start = 0;
        while (true) {
            const std::size_t semi = text.find(';', start);
            fields.push_back(trim(text.substr(start, semi - start)));
            if (semi == std::string_view::npos) break;
            start = semi + 1;
        }
        std::string where = "Record3/DataList/Datum ";
        where.append(std::to_string(k + 1));
        if (fields.size() != columns) {
            std::string what = where;
            what.append(" has ")
                .append(std::to_string(fields.size()))
                .append(" values, expected ")
                .append(std::to_string(columns));
            fail(name, what);
        }
        std::size_t f = 0;
        auto check_grid = [&](std::optional<double>& first, std::size_t index, const char* label) {
            const double v = parse_decimal(fields[f++], 0, name, where);
            if (!first) first = v - static_cast<double>(index);
            if (v != *first + static_cast<double>(index)) {
                std::string what = where;
                what.append(": the absolute ")
                    .append(label)
                    .append(" values are not a regular grid (point clouds are not supported)");
                fail(name, what);
            }
        };
        if (!cx.incremental) check_grid(x_first, k % nx, "X");
        if (!cy.incremental) check_grid(y_first, k / nx, "Y");
        const std::string_view z_text = fields[f];
        if (z_text.empty()) continue;
        // physical = offset + increment × value; without an increment the value is metres and
        // is converted to µm by shifting its decimal exponent (exact up to one rounding).
        double z_um = cz.increment_um == 1e6 ? metres_text_to_um(z_text, name, where)
                                             : parse_decimal(z_text, 0, name, where);
        if (cz.increment_um != 1e6 && cz.increment_um != 1.0) z_um *= cz.increment_um;
        if (cz.offset_um != 0.0) z_um += cz.offset_um;
        map.heights_um[k] = std::isfinite(z_um) ? z_um : std::numeric_limits<double>::quiet_NaN();
    }
    if (!cx.incremental) {
        if (!cx.has_increment) fail(name, "an absolute integer CX axis needs an <Increment>");
        map.dx_um = cx.increment_um;
        map.x_offset_um = cx.offset_um + cx.increment_um * x_first.value_or(0.0);
    }
    if (!cy.incremental) {
        if (!cy.has_increment) fail(name, "an absolute integer CY axis needs an <Increment>");
        map.dy_um = cy.increment_um;
        map.y_offset_um = cy.offset_um + cy.increment_um * y_first.value_or(0.0);
    }
}

}  // namespace

HeightMap decode_x3p(std::string_view bytes, const std::string& name,
                     const HeightReadOptions& options) {
    const bool verify = options.x3p_verify_checksums;
    const ZipArchive zip(bytes, name);
    const std::string folder = find_main_xml(zip, name);
    const std::string xml_entry = folder + "main.xml";
    const std::string xml_text = zip.read_all(xml_entry);

    tinyxml2::XMLDocument doc;
    if (doc.Parse(xml_text.data(), xml_text.size()) != tinyxml2::XML_SUCCESS) {
        std::string what = "main.xml is not well-formed XML (line ";
        what.append(std::to_string(doc.ErrorLineNum()))
            .append(": ")
            .append(doc.ErrorStr())
            .append(")");
        fail(name, what);
    }
    const tinyxml2::XMLElement* root = doc.RootElement();
    const auto* record1 = require(root, "Record1", name, "Record1");
    const std::string_view feature =
        trim(text_of(require(record1, "FeatureType", name, "Record1/FeatureType")));
    if (feature == "PCL") {
        fail(name,
             "FeatureType PCL: point clouds are not supported (a height map needs a regular "
             "grid, FeatureType SUR or PRF)");
    }
    if (feature != "SUR" && feature != "PRF") {
        fail(name,
             concat("Record1/FeatureType must be SUR, PRF or PCL, not ", quote_input(feature)));
    }
    const auto* axes = require(record1, "Axes", name, "Record1/Axes");
    const Axis cx = read_axis(axes, "CX", name);
    const Axis cy = read_axis(axes, "CY", name);
    const Axis cz = read_axis(axes, "CZ", name);
    if (cz.incremental) fail(name, "Record1/Axes/CZ must be an absolute axis (AxisType A)");
    if (cx.incremental && !cx.has_increment)
        fail(name, "main.xml has no <Record1/Axes/CX/Increment>");
    if (cy.incremental && !cy.has_increment)
        fail(name, "main.xml has no <Record1/Axes/CY/Increment>");
    for (const Axis* a : {&cx, &cy}) {
        if (!a->incremental && (a->type == SampleType::Float32 || a->type == SampleType::Float64)) {
            fail(name,
                 "absolute floating-point CX/CY coordinates make a point cloud, which is not "
                 "supported (a height map needs incremental or integer-coded axes)");
        }
    }

    const auto* record3 = require(root, "Record3", name, "Record3");
    const auto* dims = require(record3, "MatrixDimension", name, "Record3/MatrixDimension");
    const std::size_t nx =
        parse_count(text_of(require(dims, "SizeX", name, "MatrixDimension/SizeX")), name,
                    "MatrixDimension/SizeX");
    const std::size_t ny =
        parse_count(text_of(require(dims, "SizeY", name, "MatrixDimension/SizeY")), name,
                    "MatrixDimension/SizeY");
    const std::size_t nz = child(dims, "SizeZ") ? parse_count(text_of(child(dims, "SizeZ")), name,
                                                              "MatrixDimension/SizeZ")
                                                : 1;
    if (nx < 1 || ny < 1 || nx > kMaxHeightMapPoints / ny) {
        fail(name,
             concat("MatrixDimension ", std::to_string(nx), " x ", std::to_string(ny),
                    " is not a grid of 1 to ", std::to_string(kMaxHeightMapPoints), " points"));
    }
    if (nz != 1)
        fail(name, concat("MatrixDimension/SizeZ = ", std::to_string(nz),
                          ": only one layer (1) is supported"));
    if (feature == "PRF" && ny != 1) fail(name, "FeatureType PRF needs MatrixDimension/SizeY = 1");

    HeightMap map;
    map.nx = nx;
    map.ny = ny;
    if (cx.incremental) {
        map.dx_um = cx.increment_um;
        map.x_offset_um = cx.offset_um;
    }
    if (cy.incremental) {
        map.dy_um = cy.increment_um;
        map.y_offset_um = cy.offset_um;
    }

    std::optional<HeightsScan> scanned;  // the heights as read, when nothing changed them after
    if (const auto* link = child(record3, "DataLink")) {
        if (!cx.incremental || !cy.incremental) {
            fail(name, "binary data with absolute CX/CY axes are not supported");
        }
        const std::string_view data_link =
            trim(text_of(require(link, "PointDataLink", name, "DataLink/PointDataLink")));
        std::optional<std::string_view> data_md5;
        if (const auto* m = child(link, "MD5ChecksumPointData"); m && !trim(text_of(m)).empty()) {
            data_md5 = text_of(m);
        }
        // Z in the file's units: physical = offset + increment × value (metres), so µm =
        // offset_um + increment_um × value; a float axis without <Increment> is in metres.
        const Scale scale{cz.increment_um, cz.offset_um};
        HeightsScan scan{nx * ny, false};
        read_binary_heights(zip, name, folder + std::string(data_link), cz.type, scale, nx * ny,
                            data_md5, verify, map.heights_um, scan);
        scanned = scan;
        if (const auto* valid = child(link, "ValidPointsLink");
            valid && !trim(text_of(valid)).empty()) {
            std::optional<std::string_view> valid_md5;
            if (const auto* m = child(link, "MD5ChecksumValidPoints");
                m && !trim(text_of(m)).empty()) {
                valid_md5 = text_of(m);
            }
            apply_validity(zip, name, folder + std::string(trim(text_of(valid))), valid_md5, verify,
                           map.heights_um);
            scanned.reset();  // points marked invalid are missing, whatever their value
        }
    } else if (const auto* list = child(record3, "DataList")) {
        read_data_list(list, name, cx, cy, cz, nx, ny, map);
    } else {
        fail(name, "Record3 has neither a DataLink nor a DataList");
    }

    // main.xml against md5checksum.hex (or the file Record4 names).
    std::string checksum_file = "md5checksum.hex";
    if (const auto* r4 = child(root, "Record4")) {
        if (const auto* cf = child(r4, "ChecksumFile"); cf && !trim(text_of(cf)).empty()) {
            checksum_file = std::string(trim(text_of(cf)));
        }
    }
    if (verify && zip.has(folder + checksum_file)) {
        const std::string hex = zip.read_all(folder + checksum_file);
        const std::string_view stated = std::string_view(hex).substr(0, 32);
        check_md5(name, "main.xml", stated, md5_hex(xml_text), checksum_file.c_str());
    }

    if (const auto* r2 = child(root, "Record2"))
        map.title = std::string(trim(text_of(child(r2, "Comment"))));
    try {
        if (scanned)
            validate(map, name, *scanned);
        else
            validate(map, name);
    } catch (const InvalidArgument& e) {
        throw DataError(e.what());
    }
    return map;
}

namespace x3p {

std::string md5_hex(std::string_view data) { return formats::md5_hex(data); }
std::string um_to_metres_text(double um) { return formats::um_to_metres_text(um); }

}  // namespace x3p

}  // namespace roughscope::surface::formats
