// Gwyddion files: the native .gwy (a serialized GwyContainer, read only) and the Gwyddion Simple
// Field .gsf (read and write). Units, missing points and quirks: docs/height-files.md, section
// "Gwyddion .gwy and .gsf".
//
// GWY serialization (Gwyddion user guide, "Format of Gwyddion Files"): the magic "GWYP", then one
// object. An object is its type name (NUL-terminated), a little-endian uint32 byte count of its
// components, and the components; a component is its name (NUL-terminated), a one-byte type and
// the value: b/c 1 byte, i int32, q int64, d double, s NUL-terminated string, o a nested object;
// capital C/I/Q/D/S/O are arrays: a uint32 count followed by the items.
#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <tuple>
#include <vector>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/surface/formats.hpp"

namespace roughscope::surface::formats {

namespace {

static_assert(std::endian::native == std::endian::little,
              "gwy and gsf data are little-endian; this reader assumes a little-endian host");

[[noreturn]] void fail(const std::string& name, std::string_view what) {
    std::string message = name;
    message.append(": ").append(what);
    throw DataError(message);
}

[[noreturn]] void fail_at(const std::string& name, std::size_t offset, std::string_view what) {
    std::string message = name;
    message.append(": byte ").append(std::to_string(offset)).append(": ").append(what);
    throw DataError(message);
}

// How many µm one unit of `unit` is, as a multiplier or (for sub-µm units, exact division) a
// divisor. An empty unit is taken as metres (Gwyddion's SI base unit for lengths).
struct UnitScale {
    double multiply = 1.0;
    double divide = 1.0;
    double apply(double v) const {
        if (multiply != 1.0) v *= multiply;
        if (divide != 1.0) v /= divide;
        return v;
    }
};

std::optional<UnitScale> length_unit(std::string_view unit) {
    if (unit.empty() || unit == "m") return UnitScale{1e6, 1.0};
    if (unit == "mm") return UnitScale{1e3, 1.0};
    if (unit == "um" || unit == "\xc2\xb5m" || unit == "\xce\xbcm") return UnitScale{1.0, 1.0};
    if (unit == "nm") return UnitScale{1.0, 1e3};
    if (unit == "pm") return UnitScale{1.0, 1e6};
    // Angstrom (the letter A alone is the ampere).
    if (unit == "\xc3\x85" || unit == "\xe2\x84\xab") return UnitScale{1.0, 1e4};
    return std::nullopt;
}

double missing_if_not_finite(double v) {
    return std::isfinite(v) ? v : std::numeric_limits<double>::quiet_NaN();
}

void finish(HeightMap& map, const std::string& name) {
    try {
        validate(map, name);
    } catch (const InvalidArgument& e) {
        throw DataError(e.what());
    }
}

// ---- GWY ----------------------------------------------------------------------------------------

constexpr int kMaxGwyDepth = 32;

struct GwyObject;

struct GwyValue {
    char type = 0;
    double number = 0.0;                // b c i q d
    std::string text;                   // s
    std::unique_ptr<GwyObject> object;  // o
    std::size_t array_offset = 0;       // D: where the doubles start
    std::uint32_t array_count = 0;
};

struct GwyObject {
    std::string type_name;
    std::size_t offset = 0;
    std::map<std::string, GwyValue> items;  // last one wins on duplicates
    const GwyValue* find(const std::string& key) const {
        const auto it = items.find(key);
        return it == items.end() ? nullptr : &it->second;
    }
};

class GwyParser {
  public:
    GwyParser(std::string_view bytes, const std::string& name) : bytes_(bytes), name_(name) {}

    std::unique_ptr<GwyObject> object(std::size_t& pos, std::size_t end, int depth) {
        if (depth > kMaxGwyDepth) fail_at(name_, pos, "objects nested too deep");
        auto obj = std::make_unique<GwyObject>();
        obj->offset = pos;
        obj->type_name = cstring(pos, end);
        const std::uint32_t size = u32(pos, end);
        if (size > end - pos) {
            fail_at(name_, pos,
                    concat("object ", quote_input(obj->type_name), " claims ", std::to_string(size),
                           " bytes, only ", std::to_string(end - pos), " remain"));
        }
        const std::size_t stop = pos + size;
        while (pos < stop) {
            const std::size_t at = pos;
            std::string key = cstring(pos, stop);
            GwyValue value = component(pos, stop, depth);
            (void)at;
            obj->items.insert_or_assign(std::move(key), std::move(value));
        }
        return obj;
    }

  private:
    GwyValue component(std::size_t& pos, std::size_t end, int depth) {
        if (pos >= end) fail_at(name_, pos, "component without a type");
        GwyValue v;
        v.type = bytes_[pos++];
        switch (v.type) {
            case 'b':
            case 'c':
                need(pos, end, 1);
                v.number = static_cast<unsigned char>(bytes_[pos++]);
                break;
            case 'i':
                v.number = static_cast<std::int32_t>(u32(pos, end));
                break;
            case 'q':
                need(pos, end, 8);
                v.number = static_cast<double>(load<std::int64_t>(pos));
                pos += 8;
                break;
            case 'd':
                need(pos, end, 8);
                v.number = load<double>(pos);
                pos += 8;
                break;
            case 's':
                v.text = cstring(pos, end);
                break;
            case 'o':
                v.object = object(pos, end, depth + 1);
                break;
            case 'C':
            case 'I':
            case 'Q':
            case 'D': {
                const std::uint32_t count = u32(pos, end);
                const std::size_t item = v.type == 'C' ? 1 : v.type == 'I' ? 4 : 8;
                if (count > (end - pos) / item) {
                    fail_at(name_, pos,
                            concat("array of ", std::to_string(count),
                                   " items runs past the end of its object"));
                }
                v.array_offset = pos;
                v.array_count = count;
                pos += count * item;
                break;
            }
            case 'S': {
                const std::uint32_t count = u32(pos, end);
                if (count > end - pos) fail_at(name_, pos, "string array runs past its object");
                for (std::uint32_t i = 0; i < count; ++i) (void)cstring(pos, end);
                break;
            }
            case 'O': {
                const std::uint32_t count = u32(pos, end);
                if (count > end - pos) fail_at(name_, pos, "object array runs past its object");
                for (std::uint32_t i = 0; i < count; ++i) (void)object(pos, end, depth + 1);
                break;
            }
            default: {
                std::string what = "unknown component type ";
                what.append(quote_input(std::string_view(&bytes_[pos - 1], 1)));
                fail_at(name_, pos - 1, what);
            }
        }
        return v;
    }

    template <class T>
    T load(std::size_t pos) const {
        T v;
        std::memcpy(&v, bytes_.data() + pos, sizeof v);
        return v;
    }
    void need(std::size_t pos, std::size_t end, std::size_t n) const {
        if (n > end - pos) fail_at(name_, pos, "value runs past the end of its object");
    }
    std::uint32_t u32(std::size_t& pos, std::size_t end) const {
        need(pos, end, 4);
        const auto v = load<std::uint32_t>(pos);
        pos += 4;
        return v;
    }
    std::string cstring(std::size_t& pos, std::size_t end) const {
        const std::size_t nul = bytes_.substr(0, end).find('\0', pos);
        if (nul == std::string_view::npos) fail_at(name_, pos, "string without a terminating NUL");
        std::string s(bytes_.substr(pos, nul - pos));
        pos = nul + 1;
        return s;
    }

    std::string_view bytes_;
    const std::string& name_;
};

struct GwyField {
    std::size_t xres = 0;
    std::size_t yres = 0;
    double xreal = 1.0;
    double yreal = 1.0;
    double xoff = 0.0;
    double yoff = 0.0;
    std::string unit_xy;
    std::string unit_z;
    std::size_t data_offset = 0;
};

std::string unit_of(const GwyObject& field, const char* key) {
    const GwyValue* v = field.find(key);
    if (!v || v->type != 'o' || !v->object) return {};
    const GwyValue* s = v->object->find("unitstr");
    return s && s->type == 's' ? s->text : std::string();
}

GwyField read_field(const GwyObject& obj, const std::string& key, const std::string& name) {
    auto where = [&](std::string_view what) {
        std::string out = key;
        out.append(": ").append(what);
        return out;
    };
    if (obj.type_name != "GwyDataField") {
        fail_at(name, obj.offset,
                where(concat("is a ", quote_input(obj.type_name), ", not a GwyDataField")));
    }
    GwyField f;
    auto integer = [&](const char* k) -> std::size_t {
        const GwyValue* v = obj.find(k);
        if (!v || v->type != 'i' || v->number < 1) {
            fail_at(name, obj.offset, where(concat(std::string(k), " must be a positive int32")));
        }
        return static_cast<std::size_t>(v->number);
    };
    auto real = [&](const char* k, double fallback) -> double {
        const GwyValue* v = obj.find(k);
        if (!v) return fallback;
        if (v->type != 'd' || !std::isfinite(v->number)) {
            fail_at(name, obj.offset, where(concat(std::string(k), " must be a finite double")));
        }
        return v->number;
    };
    f.xres = integer("xres");
    f.yres = integer("yres");
    f.xreal = real("xreal", 1.0);
    f.yreal = real("yreal", 1.0);
    f.xoff = real("xoff", 0.0);
    f.yoff = real("yoff", 0.0);
    f.unit_xy = unit_of(obj, "si_unit_xy");
    f.unit_z = unit_of(obj, "si_unit_z");
    const GwyValue* data = obj.find("data");
    if (!data || data->type != 'D') fail_at(name, obj.offset, where("has no double array 'data'"));
    if (f.xres > kMaxHeightMapPoints / f.yres || data->array_count != f.xres * f.yres) {
        fail_at(name, data->array_offset,
                where(concat("data holds ", std::to_string(data->array_count),
                             " values, xres x yres = ", std::to_string(f.xres), " x ",
                             std::to_string(f.yres))));
    }
    f.data_offset = data->array_offset;
    return f;
}

}  // namespace

HeightMap decode_gwy(std::string_view bytes, const std::string& name, const HeightReadOptions&) {
    if (bytes.size() < 4 || bytes.substr(0, 4) != "GWYP") {
        if (bytes.substr(0, std::min<std::size_t>(4, bytes.size())) == "GWYO") {
            fail_at(name, 0, "GWYO (Gwyddion 1.x) files are not supported; resave with Gwyddion 2");
        }
        fail_at(name, 0, "not a Gwyddion file (no GWYP magic)");
    }
    GwyParser parser(bytes, name);
    std::size_t pos = 4;
    const std::unique_ptr<GwyObject> root = parser.object(pos, bytes.size(), 0);
    if (root->type_name != "GwyContainer") {
        fail_at(
            name, 4,
            concat("the top object is a ", quote_input(root->type_name), ", not a GwyContainer"));
    }
    // The channels /N/data, in increasing N; the first whose units are lengths is the height map.
    std::map<long long, const GwyObject*> channels;
    for (const auto& [key, value] : root->items) {
        if (key.size() < 7 || !key.starts_with("/") || !key.ends_with("/data") ||
            value.type != 'o') {
            continue;
        }
        const std::string_view digits(key.data() + 1, key.size() - 6);
        long long n = 0;
        const auto [ptr, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), n);
        if (digits.empty() || ec != std::errc{} || ptr != digits.data() + digits.size()) continue;
        channels.emplace(n, value.object.get());
    }
    if (channels.empty()) fail(name, "the container holds no channel /N/data (no GwyDataField)");
    std::string rejected;
    for (const auto& [n, obj] : channels) {
        const std::string key = concat("/", std::to_string(n), "/data");
        const GwyField f = read_field(*obj, key, name);
        const auto sxy = length_unit(f.unit_xy);
        const auto sz = length_unit(f.unit_z);
        if (!sxy || !sz) {
            if (!rejected.empty()) rejected.append(", ");
            rejected.append(key)
                .append(" (")
                .append(quote_input(f.unit_xy))
                .append(", ")
                .append(quote_input(f.unit_z))
                .append(")");
            continue;
        }
        HeightMap map;
        map.nx = f.xres;
        map.ny = f.yres;
        map.dx_um = sxy->apply(f.xreal) / static_cast<double>(f.xres);
        map.dy_um = sxy->apply(f.yreal) / static_cast<double>(f.yres);
        map.x_offset_um = sxy->apply(f.xoff);
        map.y_offset_um = sxy->apply(f.yoff);
        map.heights_um.resize(map.size());
        for (std::size_t i = 0; i < map.size(); ++i) {
            double v;
            std::memcpy(&v, bytes.data() + f.data_offset + 8 * i, 8);
            map.heights_um[i] = missing_if_not_finite(sz->apply(v));
        }
        // A mask marks the points Gwyddion flags (an import's invalid points): missing here.
        const std::string mask_key = concat("/", std::to_string(n), "/mask");
        if (const GwyValue* m = root->find(mask_key); m && m->type == 'o' && m->object) {
            const GwyField mf = read_field(*m->object, mask_key, name);
            if (mf.xres != f.xres || mf.yres != f.yres) {
                fail_at(name, m->object->offset, mask_key + " is not the size of its channel");
            }
            for (std::size_t i = 0; i < map.size(); ++i) {
                double v;
                std::memcpy(&v, bytes.data() + mf.data_offset + 8 * i, 8);
                if (v > 0.5) map.heights_um[i] = std::numeric_limits<double>::quiet_NaN();
            }
        }
        if (const GwyValue* t = root->find(key + "/title"); t && t->type == 's')
            map.title = t->text;
        finish(map, name);
        return map;
    }
    fail(name, concat("no channel has length units (lateral, height): ", rejected));
}

// ---- GSF ----------------------------------------------------------------------------------------

namespace {

constexpr std::string_view kGsfMagic = "Gwyddion Simple Field 1.0\n";

std::string_view trim(std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r')) {
        s.remove_prefix(1);
    }
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) {
        s.remove_suffix(1);
    }
    return s;
}

double gsf_number(const std::map<std::string, std::pair<std::string, std::size_t>>& header,
                  const char* key, double fallback, const std::string& name) {
    const auto it = header.find(key);
    if (it == header.end()) return fallback;
    const std::string& text = it->second.first;
    double v = 0.0;
    const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (text.empty() || ec != std::errc{} || ptr != text.data() + text.size() ||
        !std::isfinite(v)) {
        fail_at(name, it->second.second,
                concat(key, " is not a finite number: ", quote_input(text)));
    }
    return v;
}

}  // namespace

HeightMap decode_gsf(std::string_view bytes, const std::string& name, const HeightReadOptions&) {
    std::size_t pos = 0;
    if (bytes.starts_with(kGsfMagic)) {
        pos = kGsfMagic.size();
    } else if (bytes.starts_with("Gwyddion Simple Field 1.0\r\n")) {
        pos = kGsfMagic.size() + 1;
    } else {
        fail_at(name, 0, "not a GSF file (no \"Gwyddion Simple Field 1.0\" line)");
    }
    const std::size_t header_end = bytes.find('\0', pos);
    if (header_end == std::string_view::npos)
        fail_at(name, bytes.size(), "the header has no NUL terminator");
    // key -> (value, byte offset of its line)
    std::map<std::string, std::pair<std::string, std::size_t>> header;
    while (pos < header_end) {
        std::size_t eol = bytes.find('\n', pos);
        if (eol == std::string_view::npos || eol > header_end) eol = header_end;
        const std::string_view line = trim(bytes.substr(pos, eol - pos));
        if (!line.empty()) {
            const std::size_t eq = line.find('=');
            if (eq == std::string_view::npos) {
                fail_at(name, pos, concat("header line without '=': ", quote_input(line)));
            }
            header.insert_or_assign(std::string(trim(line.substr(0, eq))),
                                    std::make_pair(std::string(trim(line.substr(eq + 1))), pos));
        }
        pos = eol + 1;
    }
    // One to four NUL bytes align the data to a multiple of 4.
    const std::size_t data_start = (header_end + 4) / 4 * 4;
    if (data_start > bytes.size()) fail_at(name, header_end, "the file ends in the header padding");
    for (std::size_t i = header_end; i < data_start; ++i) {
        if (bytes[i] != '\0') fail_at(name, i, "header padding must be NUL bytes");
    }
    auto count = [&](const char* key) -> std::size_t {
        const auto it = header.find(key);
        if (it == header.end()) fail(name, concat("the header has no ", key));
        const std::string& text = it->second.first;
        std::size_t v = 0;
        const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
        if (text.empty() || ec != std::errc{} || ptr != text.data() + text.size() || v < 1) {
            fail_at(name, it->second.second,
                    concat(key, " must be a positive integer, not ", quote_input(text)));
        }
        return v;
    };
    const std::size_t nx = count("XRes");
    const std::size_t ny = count("YRes");
    if (nx > kMaxHeightMapPoints / ny) {
        fail(name, concat("XRes x YRes = ", std::to_string(nx), " x ", std::to_string(ny),
                          " is more than ", std::to_string(kMaxHeightMapPoints), " points"));
    }
    const std::size_t need = nx * ny * 4;
    if (bytes.size() - data_start != need) {
        fail_at(name, data_start,
                concat("the data hold ", std::to_string(bytes.size() - data_start),
                       " bytes; XRes x YRes float32 values need ", std::to_string(need)));
    }
    auto unit = [&](const char* key) -> UnitScale {
        const auto it = header.find(key);
        const std::string text = it == header.end() ? std::string() : it->second.first;
        const auto s = length_unit(text);
        if (!s) {
            fail_at(name, it->second.second,
                    concat(key, " is not a length unit (m, mm, um, nm, pm): ", quote_input(text)));
        }
        return *s;
    };
    const UnitScale sxy = unit("XYUnits");
    const UnitScale sz = unit("ZUnits");
    HeightMap map;
    map.nx = nx;
    map.ny = ny;
    const double xreal = gsf_number(header, "XReal", 1.0, name);
    const double yreal = gsf_number(header, "YReal", 1.0, name);
    map.dx_um = sxy.apply(xreal) / static_cast<double>(nx);
    map.dy_um = sxy.apply(yreal) / static_cast<double>(ny);
    // roughscope's exact spacings (written when XReal / XRes cannot give the spacing bit for
    // bit); used only when they agree with XReal.
    for (auto [key, real, res, spacing] : {std::tuple{"XSpacing", xreal, nx, &map.dx_um},
                                           std::tuple{"YSpacing", yreal, ny, &map.dy_um}}) {
        if (!header.contains(key)) continue;
        const double s = sxy.apply(gsf_number(header, key, 0.0, name));
        const double total = sxy.apply(real);
        if (s > 0.0 && std::fabs(s * static_cast<double>(res) - total) <= 1e-9 * std::fabs(total)) {
            *spacing = s;
        }
    }
    map.x_offset_um = sxy.apply(gsf_number(header, "XOffset", 0.0, name));
    map.y_offset_um = sxy.apply(gsf_number(header, "YOffset", 0.0, name));
    if (const auto it = header.find("Title"); it != header.end()) map.title = it->second.first;
    map.heights_um.resize(nx * ny);
    for (std::size_t i = 0; i < nx * ny; ++i) {
        float v;
        std::memcpy(&v, bytes.data() + data_start + 4 * i, 4);
        map.heights_um[i] = missing_if_not_finite(sz.apply(static_cast<double>(v)));
    }
    finish(map, name);
    return map;
}

namespace {

// A length `real` with real / n == spacing exactly (Gwyddion's spacing is XReal / XRes), searched
// among the doubles next to n × spacing; nullopt when none divides back exactly.
std::optional<double> exact_total(double spacing, std::size_t n) {
    const double count = static_cast<double>(n);
    double up = spacing * count;
    double down = up;
    for (int i = 0; i < 16; ++i) {
        if (up / count == spacing) return up;
        if (down / count == spacing) return down;
        up = std::nextafter(up, std::numeric_limits<double>::infinity());
        down = std::nextafter(down, -std::numeric_limits<double>::infinity());
    }
    return std::nullopt;
}

std::string shortest(double v) {
    char buffer[64];
    const auto r = std::to_chars(buffer, buffer + sizeof buffer, v);
    return std::string(buffer, r.ptr);
}

}  // namespace

std::string encode_gsf(const HeightMap& map, const HeightWriteOptions&) {
    validate(map, "gsf output");
    const double float_max = std::numeric_limits<float>::max();
    for (std::size_t i = 0; i < map.size(); ++i) {
        const double z = map.heights_um[i];
        if (std::fabs(z) > float_max) {
            std::string what = "gsf output: height ";
            what.append(shortest(z))
                .append(" um at point ")
                .append(std::to_string(i))
                .append(" is outside the float32 range the format holds (|z| <= ")
                .append(shortest(float_max))
                .append(" um)");
            throw InvalidArgument(what);
        }
    }
    std::string title = map.title;
    std::replace_if(
        title.begin(), title.end(), [](char c) { return c == '\n' || c == '\r' || c == '\0'; },
        ' ');
    std::string out(kGsfMagic);
    auto line = [&](std::string_view key, const std::string& value) {
        out.append(key).append(" = ").append(value).append("\n");
    };
    line("XRes", std::to_string(map.nx));
    line("YRes", std::to_string(map.ny));
    const std::optional<double> xreal = exact_total(map.dx_um, map.nx);
    const std::optional<double> yreal = exact_total(map.dy_um, map.ny);
    line("XReal", shortest(xreal.value_or(map.dx_um * static_cast<double>(map.nx))));
    line("YReal", shortest(yreal.value_or(map.dy_um * static_cast<double>(map.ny))));
    if (!xreal) line("XSpacing", shortest(map.dx_um));
    if (!yreal) line("YSpacing", shortest(map.dy_um));
    line("XOffset", shortest(map.x_offset_um));
    line("YOffset", shortest(map.y_offset_um));
    line("XYUnits", "um");
    line("ZUnits", "um");
    if (!title.empty()) line("Title", title);
    out.append(4 - out.size() % 4, '\0');
    const std::size_t start = out.size();
    out.resize(start + 4 * map.size());
    for (std::size_t i = 0; i < map.size(); ++i) {
        const auto v = static_cast<float>(map.heights_um[i]);  // nearest float32; NaN stays NaN
        std::memcpy(out.data() + start + 4 * i, &v, 4);
    }
    return out;
}

}  // namespace roughscope::surface::formats
