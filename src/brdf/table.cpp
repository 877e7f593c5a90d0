// Measured BRDF tables: validation, the CSV reader and the paper-frame conversion (§2, §5.3).
#include "roughscope/brdf/table.hpp"

#include <algorithm>
#include <charconv>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>

#include "roughscope/core/errors.hpp"

namespace roughscope {
namespace {

std::string_view trim(std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r'))
        s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
        s.remove_suffix(1);
    return s;
}

std::vector<std::string_view> split_commas(std::string_view line) {
    std::vector<std::string_view> out;
    std::size_t start = 0;
    while (true) {
        const std::size_t comma = line.find(',', start);
        if (comma == std::string_view::npos) {
            out.push_back(trim(line.substr(start)));
            break;
        }
        out.push_back(trim(line.substr(start, comma - start)));
        start = comma + 1;
    }
    return out;
}

// Strict: the whole field must be a finite number.
bool parse_number(std::string_view text, double& value) {
    if (!text.empty() && text.front() == '+') text.remove_prefix(1);
    if (text.empty()) return false;
    const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    return ec == std::errc() && ptr == text.data() + text.size() && std::isfinite(value);
}

[[noreturn]] void fail(std::string_view source, std::size_t line, const std::string& what) {
    throw DataError(std::string(source) + ":" + std::to_string(line) + ": " + what);
}

}  // namespace

std::optional<std::size_t> BrdfTable::find(int index) const {
    for (std::size_t k = 0; k < measurements.size(); ++k)
        if (measurements[k].index == index) return k;
    return std::nullopt;
}

BrdfMeasurement make_brdf_measurement(int index, double theta_i_rad, double phi_i_rad,
                                      double theta_v_rad, double phi_v_rad, double value,
                                      double weight, std::optional<double> overflow_fraction) {
    check::finite("BRDF value", value);
    check::non_negative("weight", weight);
    if (overflow_fraction && !(std::isfinite(*overflow_fraction) && *overflow_fraction >= 0.0 &&
                               *overflow_fraction <= 1.0))
        throw InvalidArgument("overflow fraction = " + check::format_number(*overflow_fraction) +
                              " is outside the valid range [0, 1]");
    BrdfMeasurement m;
    m.index = index;
    m.theta_i_rad = theta_i_rad;
    m.phi_i_rad = phi_i_rad;
    m.theta_v_rad = theta_v_rad;
    m.phi_v_rad = phi_v_rad;
    m.value = value;
    m.weight = weight;
    m.overflow_fraction = overflow_fraction;
    // §2: θs = θv, φs = φv − φi + π (validates the angles).
    m.geometry = geometry_from_two_azimuths(theta_i_rad, phi_i_rad, theta_v_rad, phi_v_rad);
    return m;
}

BrdfTable parse_brdf_csv(std::string_view text, std::string_view source_name,
                         const BrdfCsvOptions& options) {
    static const std::vector<std::string> required = {"theta_i", "phi_i", "theta_s", "phi_s",
                                                      "value"};
    BrdfTable table;
    table.name = std::string(source_name);

    std::map<std::string, std::size_t> column;  // name → position
    std::size_t n_columns = 0;
    bool have_header = false;
    std::set<int> seen_index;
    std::set<std::string> channels_seen;
    std::size_t line_no = 0, data_rows = 0;
    std::size_t pos = 0;
    while (pos < text.size()) {
        std::size_t eol = text.find('\n', pos);
        if (eol == std::string_view::npos) eol = text.size();
        const std::string_view line = trim(text.substr(pos, eol - pos));
        pos = eol + 1;
        ++line_no;
        if (line.empty() || line.front() == '#') {
            continue;
        }
        const std::vector<std::string_view> fields = split_commas(line);
        if (!have_header) {
            for (std::size_t k = 0; k < fields.size(); ++k) {
                const std::string name(fields[k]);
                if (name.empty()) fail(source_name, line_no, "empty column name in the header");
                if (!column.emplace(name, k).second)
                    fail(source_name, line_no, "duplicate column '" + name + "' in the header");
            }
            std::string missing;
            for (const auto& r : required)
                if (!column.count(r)) missing += (missing.empty() ? "" : ", ") + r;
            if (!missing.empty()) {
                std::string found;
                for (std::size_t k = 0; k < fields.size(); ++k)
                    found += (k ? ", " : "") + std::string(fields[k]);
                fail(source_name, line_no,
                     "missing column(s) " + missing + " (found: " + found +
                         "; required: theta_i, phi_i, theta_s, phi_s, value in degrees and 1/sr; "
                         "optional: weight, channel, measurement)");
            }
            n_columns = fields.size();
            have_header = true;
            continue;
        }
        if (fields.size() != n_columns)
            fail(source_name, line_no,
                 "expected " + std::to_string(n_columns) + " fields, found " +
                     std::to_string(fields.size()));
        auto number = [&](const std::string& name) {
            double v = 0.0;
            const std::string_view f = fields[column.at(name)];
            if (!parse_number(f, v))
                fail(source_name, line_no,
                     "column " + name + ": '" + std::string(f) + "' is not a finite number");
            return v;
        };
        ++data_rows;
        if (column.count("channel")) {
            const std::string ch(fields[column.at("channel")]);
            channels_seen.insert(ch);
            if (options.channel && ch != *options.channel) {
                continue;
            }
        }
        const double ti = number("theta_i"), pi = number("phi_i"), ts = number("theta_s"),
                     ps = number("phi_s"), value = number("value");
        double weight = 1.0;
        if (column.count("weight") && !fields[column.at("weight")].empty())
            weight = number("weight");
        int index = static_cast<int>(data_rows);
        if (column.count("measurement")) {
            const double idx = number("measurement");
            if (idx != std::floor(idx) || idx < 1 || idx > 1e9)
                fail(source_name, line_no,
                     "column measurement: '" + std::string(fields[column.at("measurement")]) +
                         "' is not a positive integer");
            index = static_cast<int>(idx);
        }
        if (!seen_index.insert(index).second)
            fail(source_name, line_no, "duplicate measurement " + std::to_string(index));
        try {
            BrdfMeasurement m =
                make_brdf_measurement(index, deg_to_rad(ti), deg_to_rad(pi), deg_to_rad(ts),
                                      deg_to_rad(ps), value, weight);
            table.measurements.push_back(m);
        } catch (const InvalidArgument& e) {
            fail(source_name, line_no, e.what());
        }
    }
    if (!have_header)
        throw DataError(std::string(source_name) +
                        ": no header line (expected theta_i, phi_i, theta_s, phi_s, value)");
    if (column.count("channel")) {
        if (options.channel) {
            if (!channels_seen.count(*options.channel)) {
                std::string list;
                for (const auto& c : channels_seen) list += (list.empty() ? "" : ", ") + c;
                throw DataError(std::string(source_name) + ": no rows of channel '" +
                                *options.channel + "' (channels in the file: " + list + ")");
            }
            table.channel = *options.channel;
        } else if (channels_seen.size() > 1) {
            std::string list;
            for (const auto& c : channels_seen) list += (list.empty() ? "" : ", ") + c;
            throw DataError(std::string(source_name) + ": the file holds several channels (" +
                            list + "); choose one");
        } else if (channels_seen.size() == 1) {
            table.channel = *channels_seen.begin();
        }
    } else if (options.channel) {
        throw DataError(std::string(source_name) + ": channel '" + *options.channel +
                        "' requested but the file has no channel column");
    }
    if (table.measurements.empty()) throw DataError(std::string(source_name) + ": no data rows");
    return table;
}

BrdfTable read_brdf_csv(const std::filesystem::path& path, const BrdfCsvOptions& options) {
    std::ifstream in(path, std::ios::binary);
    if (!in)
        throw DataError("cannot read BRDF table " + path.string() +
                        ": no such file or not readable");
    std::ostringstream buffer;
    buffer << in.rdbuf();
    return parse_brdf_csv(buffer.str(), path.string(), options);
}

}  // namespace roughscope
