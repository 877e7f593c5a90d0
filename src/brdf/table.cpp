// Measured BRDF tables: validation, the CSV reader and the paper-frame conversion (§2, §5.3).
#include "roughscope/brdf/table.hpp"

#include <algorithm>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <system_error>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/io/csv.hpp"
#include "roughscope/io/input_file.hpp"

namespace roughscope {
namespace {

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

BrdfTable parse_brdf_csv(std::istream& in, std::string_view source_name,
                         const BrdfCsvOptions& options) {
    // The one CSV reader (io/csv.hpp): header, comments, CRLF, BOM, strict numbers, and errors
    // "<source>:<line>: ..." naming the column.
    io::CsvReader reader(in, std::string(source_name),
                         {"theta_i", "phi_i", "theta_s", "phi_s", "value"},
                         {"weight", "measurement"});
    BrdfTable table;
    table.name = std::string(source_name);
    const bool has_channel = reader.has_column("channel");
    // Without a measurement column the indices are the row numbers, distinct by construction.
    const bool has_index = reader.has_column("measurement");
    std::set<int> seen_index;
    std::set<std::string> channels_seen;
    std::size_t data_rows = 0;
    io::CsvRow row;
    while (reader.next(row)) {
        ++data_rows;
        if (has_channel) {
            const std::string& ch = row.text("channel");
            channels_seen.insert(ch);
            if (options.channel && ch != *options.channel) continue;
        }
        const double weight = row.find("weight").value_or(1.0);
        int index = static_cast<int>(data_rows);
        if (row.find("measurement")) {  // an integer: decimal digits only (core/numbers.hpp)
            std::string reason;
            const auto idx = try_parse_integer(row.text("measurement"), 1, 1000000000, reason);
            if (!idx)
                fail(source_name, row.line,
                     "column measurement: " + quote_input(row.text("measurement")) + " is " +
                         reason);
            index = static_cast<int>(*idx);
        }
        if (has_index && !seen_index.insert(index).second)
            fail(source_name, row.line, "duplicate measurement " + std::to_string(index));
        try {
            table.measurements.push_back(
                make_brdf_measurement(index, deg_to_rad(row.at("theta_i")),
                                      deg_to_rad(row.at("phi_i")), deg_to_rad(row.at("theta_s")),
                                      deg_to_rad(row.at("phi_s")), row.at("value"), weight));
        } catch (const InvalidArgument& e) {
            fail(source_name, row.line, e.what());
        }
    }
    if (has_channel) {
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

BrdfTable parse_brdf_csv(std::string_view text, std::string_view source_name,
                         const BrdfCsvOptions& options) {
    std::istringstream in{std::string(text)};
    return parse_brdf_csv(in, source_name, options);
}

BrdfTable read_brdf_csv(const std::filesystem::path& path, const BrdfCsvOptions& options) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec))
        throw DataError("cannot read BRDF table " + path.string() + ": is a directory");
    io::check_input_file(path, "cannot read BRDF table " + path.string());
    std::ifstream in(path, std::ios::binary);
    if (!in)
        throw DataError("cannot read BRDF table " + path.string() +
                        ": no such file or not readable");
    return parse_brdf_csv(in, path.string(), options);
}

}  // namespace roughscope
