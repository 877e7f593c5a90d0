// What files say about themselves (docs/image.md, "Metadata" and "Response"): EXIF through
// libexif (exposure time, f-number, ISO, colour space, orientation) and the tone curve of an ICC
// profile (read here from the ICC.1 tag table: 'kTRC'/'gTRC'/'rTRC' curves, 'desc').
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include <libexif/exif-data.h>

#include "decode.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"

namespace roughscope::image::detail {

namespace {

// ---- EXIF
// ----------------------------------------------------------------------------------------

struct ExifDataRef {
    ExifData* data = nullptr;
    ~ExifDataRef() {
        if (data != nullptr) exif_data_unref(data);
    }
};

std::optional<double> rational(ExifData* data, ExifTag tag) {
    ExifEntry* entry = exif_data_get_entry(data, tag);
    if (entry == nullptr || entry->data == nullptr || entry->components < 1) return std::nullopt;
    const ExifByteOrder order = exif_data_get_byte_order(data);
    double value = 0.0;
    if (entry->format == EXIF_FORMAT_RATIONAL && entry->size >= 8) {
        const ExifRational r = exif_get_rational(entry->data, order);
        if (r.denominator == 0) return std::nullopt;
        value = static_cast<double>(r.numerator) / r.denominator;
    } else if (entry->format == EXIF_FORMAT_SRATIONAL && entry->size >= 8) {
        const ExifSRational r = exif_get_srational(entry->data, order);
        if (r.denominator == 0) return std::nullopt;
        value = static_cast<double>(r.numerator) / r.denominator;
    } else {
        return std::nullopt;
    }
    if (!(std::isfinite(value) && value > 0.0)) return std::nullopt;
    return value;
}

std::optional<int> integer(ExifData* data, ExifTag tag) {
    ExifEntry* entry = exif_data_get_entry(data, tag);
    if (entry == nullptr || entry->data == nullptr || entry->components < 1) return std::nullopt;
    const ExifByteOrder order = exif_data_get_byte_order(data);
    if (entry->format == EXIF_FORMAT_SHORT && entry->size >= 2)
        return static_cast<int>(exif_get_short(entry->data, order));
    if (entry->format == EXIF_FORMAT_LONG && entry->size >= 4) {
        const ExifLong value = exif_get_long(entry->data, order);
        if (value <= 0x7fffffffU) return static_cast<int>(value);
    }
    return std::nullopt;
}

// ---- ICC ---------------------------------------------------------------------------------------

std::uint32_t be32(Bytes b, std::size_t at) {
    return (std::uint32_t{b[at]} << 24) | (std::uint32_t{b[at + 1]} << 16) |
           (std::uint32_t{b[at + 2]} << 8) | std::uint32_t{b[at + 3]};
}
std::uint16_t be16(Bytes b, std::size_t at) {
    return static_cast<std::uint16_t>((b[at] << 8) | b[at + 1]);
}
double s15fixed16(Bytes b, std::size_t at) {
    return static_cast<double>(static_cast<std::int32_t>(be32(b, at))) / 65536.0;
}

bool has_type(Bytes element, std::string_view type) {
    return element.size() >= 4 &&
           std::equal(type.begin(), type.end(), element.begin(),
                      [](char a, std::uint8_t b) { return static_cast<std::uint8_t>(a) == b; });
}

// The element of the tag `signature`, or an empty span.
Bytes icc_tag(Bytes profile, std::string_view signature) {
    if (profile.size() < 132) return {};
    const std::uint32_t count = be32(profile, 128);
    for (std::uint32_t k = 0; k < count && 132 + 12 * std::size_t{k} + 12 <= profile.size(); ++k) {
        const std::size_t entry = 132 + 12 * std::size_t{k};
        if (!has_type(profile.subspan(entry, 4), signature)) continue;
        const std::uint64_t offset = be32(profile, entry + 4);
        const std::uint64_t size = be32(profile, entry + 8);
        if (offset + size > profile.size() || size < 12) return {};
        return profile.subspan(offset, size);
    }
    return {};
}

// The profile's description (ASCII part), lower case.
std::string icc_description(Bytes profile) {
    const Bytes desc = icc_tag(profile, "desc");
    std::string text;
    if (has_type(desc, "desc") && desc.size() >= 12) {
        const std::uint64_t n = be32(desc, 8);
        for (std::size_t i = 0; i < n && 12 + i < desc.size(); ++i)
            if (desc[12 + i] != 0) text.push_back(static_cast<char>(desc[12 + i]));
    } else if (has_type(desc, "mluc") && desc.size() >= 28) {
        const std::uint64_t length = be32(desc, 20);
        const std::uint64_t offset = be32(desc, 24);
        for (std::uint64_t i = 0; i + 1 < length && offset + i + 1 < desc.size(); i += 2)
            if (desc[offset + i] == 0 && desc[offset + i + 1] != 0)
                text.push_back(static_cast<char>(desc[offset + i + 1]));
    }
    std::string lower;
    for (const char c : text)
        lower.push_back(static_cast<char>(std::tolower(static_cast<unsigned char>(c))));
    return lower;
}

// ICC.1 parametric curve of function type 0..4 at x ∈ [0, 1].
double parametric(int type, const double* p, double x) {
    const double g = p[0];
    switch (type) {
        case 0:
            return std::pow(x, g);
        case 1:
            return x >= -p[2] / p[1] ? std::pow(p[1] * x + p[2], g) : 0.0;
        case 2:
            return x >= -p[2] / p[1] ? std::pow(p[1] * x + p[2], g) + p[3] : p[3];
        case 3:
            return x >= p[4] ? std::pow(p[1] * x + p[2], g) : p[3] * x;
        case 4:
            return x >= p[4] ? std::pow(p[1] * x + p[2], g) + p[5] : p[3] * x + p[6];
        default:
            return std::nan("");
    }
}

// Which of identity, sRGB or x^γ (γ given; 0 = none) a curve y(x) on [0, 1] follows within
// 0.5 % of full scale (64 points).
template <class Curve>
Evidence classify_curve(Curve&& y, double gamma, const std::string& text) {
    double linear = 0.0;
    double srgb = 0.0;
    double power = 0.0;
    for (int i = 0; i <= 64; ++i) {
        const double x = i / 64.0;
        const double v = y(x);
        if (!std::isfinite(v)) return {};
        linear = std::max(linear, std::abs(v - x));
        srgb = std::max(srgb, std::abs(v - srgb_decode(x)));
        if (gamma > 0.0) power = std::max(power, std::abs(v - std::pow(x, gamma)));
    }
    constexpr double kTolerance = 0.005;
    if (linear <= kTolerance) return {Response::Linear, 0.0, concat(text, ", linear curve")};
    if (srgb <= kTolerance) return {Response::Srgb, 0.0, concat(text, ", sRGB curve")};
    if (gamma > 0.0 && power <= kTolerance)
        return {Response::Gamma, gamma,
                concat(text, ", gamma ", check::format_number(gamma), " curve")};
    return {};
}

Evidence trc_evidence(Bytes trc, const std::string& text) {
    if (has_type(trc, "curv")) {
        const std::uint64_t n = be32(trc, 8);
        if (12 + 2 * n > trc.size()) return {};
        if (n == 0) return {Response::Linear, 0.0, concat(text, ", linear curve")};
        if (n == 1) {
            const double gamma = be16(trc, 12) / 256.0;
            if (!(gamma > 0.0)) return {};
            if (std::abs(gamma - 1.0) <= 0.01)
                return {Response::Linear, 0.0, concat(text, ", linear curve")};
            return {Response::Gamma, gamma,
                    concat(text, ", gamma ", check::format_number(gamma), " curve")};
        }
        auto sampled = [&](double x) {
            const double at = x * static_cast<double>(n - 1);
            const auto i =
                static_cast<std::size_t>(std::min<double>(at, static_cast<double>(n - 2)));
            const double t = at - static_cast<double>(i);
            const double a = be16(trc, 12 + 2 * i) / 65535.0;
            const double b = be16(trc, 12 + 2 * (i + 1)) / 65535.0;
            return a + t * (b - a);
        };
        return classify_curve(sampled, 0.0, text);
    }
    if (has_type(trc, "para")) {
        static constexpr int kParams[5] = {1, 3, 4, 5, 7};
        const int type = be16(trc, 8);
        if (type < 0 || type > 4) return {};
        const auto count = static_cast<std::size_t>(kParams[type]);
        if (12 + 4 * count > trc.size()) return {};
        double p[7] = {};
        for (std::size_t k = 0; k < count; ++k) p[k] = s15fixed16(trc, 12 + 4 * k);
        if ((type == 1 || type == 2) && p[1] == 0.0) return {};
        return classify_curve([&](double x) { return parametric(type, p, x); },
                              type == 0 ? p[0] : 0.0, text);
    }
    return {};
}

}  // namespace

ExifFields parse_exif(Bytes block) {
    ExifFields fields;
    if (block.size() < 14) return fields;
    ExifDataRef ref;
    ref.data = exif_data_new();
    if (ref.data == nullptr) return fields;
    // No "fixing" of the data: libexif would otherwise add the mandatory tags it finds missing,
    // with default values (a ColorSpace the file never stated, say).
    exif_data_unset_option(ref.data, EXIF_DATA_OPTION_FOLLOW_SPECIFICATION);
    const auto size = static_cast<unsigned>(std::min<std::size_t>(block.size(), 0xffffffU));
    exif_data_load_data(ref.data, block.data(), size);
    fields.exposure_s = rational(ref.data, EXIF_TAG_EXPOSURE_TIME);
    fields.f_number = rational(ref.data, EXIF_TAG_FNUMBER);
    if (const auto iso = integer(ref.data, EXIF_TAG_ISO_SPEED_RATINGS); iso && *iso > 0)
        fields.iso = *iso;
    fields.color_space = integer(ref.data, EXIF_TAG_COLOR_SPACE);
    fields.orientation = integer(ref.data, EXIF_TAG_ORIENTATION);
    return fields;
}

void apply_exif_exposure(const ExifFields& exif, ImageInfo& info) {
    if (exif.exposure_s) info.exposure_s = exif.exposure_s;
    if (exif.f_number) info.f_number = exif.f_number;
    if (exif.iso) info.iso = exif.iso;
}

Evidence exif_color_space_evidence(const ExifFields& exif) {
    if (exif.color_space == 1) return {Response::Srgb, 0.0, "EXIF ColorSpace sRGB"};
    return {};
}

void warn_orientation(std::optional<int> orientation, std::string_view where, ImageInfo& info) {
    if (!orientation || *orientation == 1) return;
    info.warnings.push_back(concat(where, " orientation ", std::to_string(*orientation),
                                   " not applied: the pixels are in stored order (row 0 as "
                                   "stored at the top)"));
}

Evidence icc_evidence(Bytes profile, std::string_view where) {
    // ICC.1 header: profile size (bytes 0-3), 'acsp' at 36, the tag table at 128.
    if (profile.size() < 132 || !has_type(profile.subspan(36), "acsp")) return {};
    const std::string description = icc_description(profile);
    const std::string text =
        description.empty() ? std::string(where) : concat(where, " ", quote_input(description));
    for (const std::string_view signature : {"kTRC", "gTRC", "rTRC"}) {
        const Bytes trc = icc_tag(profile, signature);
        if (trc.empty()) continue;
        Evidence evidence = trc_evidence(trc, text);
        if (evidence.known()) return evidence;
        break;
    }
    if (description.find("srgb") != std::string::npos &&
        description.find("linear") == std::string::npos)
        return {Response::Srgb, 0.0, concat(text, ", sRGB by its name")};
    return {};
}

}  // namespace roughscope::image::detail
