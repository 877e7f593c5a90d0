#include "roughscope/serialize/paper_tables.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>
#include <string_view>
#include <vector>

#include "roughscope/core/errors.hpp"
#include "roughscope/estimation/estimation.hpp"
#include "roughscope/io/input_file.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/scattering/validity.hpp"

namespace roughscope::serialize {
namespace {

using Inputs = std::vector<double>;
using Function = std::function<double(const Inputs&)>;

double half_unit(int decimals) { return 0.5 * std::pow(10.0, -decimals); }

// f at the printed inputs and over the corners of their rounding box, against the printed value.
Json check(double printed, int decimals, const Inputs& inputs,
           const std::vector<int>& input_decimals, const Function& f) {
    const double recomputed = f(inputs);
    double lo = recomputed, hi = recomputed;
    const std::size_t n = inputs.size();
    for (std::size_t mask = 0; mask < (std::size_t{1} << n); ++mask) {
        Inputs x = inputs;
        for (std::size_t k = 0; k < n; ++k)
            x[k] += ((mask >> k) & 1 ? 1.0 : -1.0) * half_unit(input_decimals[k]);
        try {
            const double v = f(x);
            if (std::isfinite(v)) {
                lo = std::min(lo, v);
                hi = std::max(hi, v);
            }
        } catch (const roughscope::Error&) {
            // A corner outside the estimator's domain does not widen the interval.
        }
    }
    const double scale = std::pow(10.0, decimals);
    const double h = half_unit(decimals);
    const char* agreement = std::llround(recomputed * scale) == std::llround(printed * scale)
                                ? "exact"
                            : (printed >= lo - h && printed <= hi + h) ? "within_rounding"
                                                                       : "differs";
    return {{"printed", number(printed)},
            {"recomputed", number(recomputed)},
            {"rounding_interval", Json::array({number(lo), number(hi)})},
            {"agreement", agreement}};
}

const Json& need(const Json& j, const char* key, const std::string& where) {
    if (!j.is_object() || !j.contains(key)) throw DataError(where + ": missing key '" + key + "'");
    return j.at(key);
}

double num_at(const Json& j, const char* key, const std::string& where) {
    const Json& v = need(j, key, where);
    if (!v.is_number()) throw DataError(where + ": key '" + key + "' is not a number");
    return v.get<double>();
}

std::string text_at(const Json& j, const char* key, const std::string& where) {
    const Json& v = need(j, key, where);
    if (!v.is_string()) throw DataError(where + ": key '" + key + "' is not a string");
    return v.get<std::string>();
}

const Json& rows_of(const Json& table, const std::string& where) {
    const Json& rows = need(table, "rows", where);
    if (!rows.is_array()) throw DataError(where + ": key 'rows' is not a list");
    return rows;
}

// σ/T by Eq. 17 and Eq. 19 from the printed E1/E2 (given to ratio_decimals decimals).
void add_slope_checks(Json& out, const Json& row, const std::string& where, double ratio,
                      int ratio_decimals, double theta1_rad, double theta2_rad) {
    for (const Correlation c : kCorrelations) {
        const std::string key = "sigma_over_T_" + std::string(info(c).letter);  // the paper's σ/T_G
        out[key] = check(num_at(row, key.c_str(), where), 4, {ratio}, {ratio_decimals},
                         [&](const Inputs& x) {
                             return sigma_over_T_from_ratio(c, x[0], theta1_rad, theta2_rad);
                         });
    }
}

// What every printed table has: its conditions and the incidence angles θ1, θ2 of its ratio.
struct PrintedTable {
    std::string where;  // "<file>: <key>", for messages
    const Json& table;
    const Json& conditions;
    double theta1_rad;
    double theta2_rad;
};

PrintedTable open_table(const Json& reference, const char* key, const std::string& where) {
    std::string w = where + ": " + key;
    const Json& t = need(reference, key, where);
    const Json& cond = need(t, "conditions", w);
    const std::string wc = w + ".conditions";
    const double theta1_rad = deg_to_rad(num_at(cond, "theta1_deg", wc));
    const double theta2_rad = deg_to_rad(num_at(cond, "theta2_deg", wc));
    return {std::move(w), t, cond, theta1_rad, theta2_rad};
}

Json table1(const Json& reference, const std::string& where) {
    const PrintedTable t = open_table(reference, "table1_slightly_rough", where);
    const std::string& w = t.where;
    const double theta_rad =
        deg_to_rad(num_at(t.conditions, "specular_theta_deg", w + ".conditions"));
    const double theta1_rad = t.theta1_rad, theta2_rad = t.theta2_rad;
    const double wavelength_um = num_at(t.conditions, "lambda_um", w + ".conditions");
    const auto T_of = [&](const Inputs& x) {  // x = {σ, E1/E2}: Eq. 15
        return correlation_length_from_ratio(x[1], x[0], theta1_rad, theta2_rad, wavelength_um);
    };
    Json rows = Json::array();
    const Json& printed_rows = rows_of(t.table, w);
    for (std::size_t i = 0; i < printed_rows.size(); ++i) {
        const Json& row = printed_rows[i];
        const std::string wr = w + ".rows[" + std::to_string(i) + "]";
        const double R_spec = num_at(row, "R_spec", wr);
        const double sigma_um = num_at(row, "sigma_um", wr);
        const double ratio = num_at(row, "E1_over_E2", wr);
        Json r = {{"surface", text_at(row, "surface", wr)},
                  {"R_spec", number(R_spec)},
                  {"E1_over_E2", number(ratio)}};
        r["sigma_um"] = check(sigma_um, 3, {R_spec}, {3}, [&](const Inputs& x) {
            return sigma_from_specular(x[0], theta_rad, wavelength_um);  // Eq. 13
        });
        r["T_um"] = check(num_at(row, "T_um", wr), 3, {sigma_um, ratio}, {3, 3}, T_of);
        r["sigma_over_T"] = check(num_at(row, "sigma_over_T", wr), 3, {sigma_um, ratio}, {3, 3},
                                  [&](const Inputs& x) { return x[0] / T_of(x); });
        rows.push_back(std::move(r));
    }
    return {{"conditions", t.conditions}, {"rows", rows}};
}

Json table2(const Json& reference, const std::string& where) {
    const PrintedTable t = open_table(reference, "table2_very_rough", where);
    const std::string& w = t.where;
    const double theta1_rad = t.theta1_rad, theta2_rad = t.theta2_rad;
    Json rows = Json::array();
    const Json& printed_rows = rows_of(t.table, w);
    for (std::size_t i = 0; i < printed_rows.size(); ++i) {
        const Json& row = printed_rows[i];
        const std::string wr = w + ".rows[" + std::to_string(i) + "]";
        const double ratio = num_at(row, "E1_over_E2", wr);
        Json r = {{"surface", text_at(row, "surface", wr)}, {"E1_over_E2", number(ratio)}};
        add_slope_checks(r, row, wr, ratio, 3, theta1_rad, theta2_rad);
        // θK and ξK (§3.5) from the printed Gaussian σ/T.
        const double printed_sigma_over_T = num_at(row, "sigma_over_T_G", wr);
        r["theta_K_deg"] =
            check(num_at(row, "theta_K_deg", wr), 0, {printed_sigma_over_T}, {4},
                  [](const Inputs& x) { return rad_to_deg(caron_theta_K_rad(x[0])); });
        r["xi_K_percent"] = check(num_at(row, "xi_K_percent", wr), 1, {printed_sigma_over_T}, {4},
                                  [](const Inputs& x) { return 100.0 * caron_xi_K(x[0]); });
        rows.push_back(std::move(r));
    }
    return {{"conditions", t.conditions}, {"rows", rows}};
}

Json table3(const Json& reference, const std::string& where) {
    const PrintedTable t = open_table(reference, "table3_curet_parameters", where);
    const std::string& w = t.where;
    const double theta1_rad = t.theta1_rad, theta2_rad = t.theta2_rad;
    Json rows = Json::array();
    const Json& printed_rows = rows_of(t.table, w);
    for (std::size_t i = 0; i < printed_rows.size(); ++i) {
        const Json& row = printed_rows[i];
        const std::string wr = w + ".rows[" + std::to_string(i) + "]";
        const double ratio = num_at(row, "E1_over_E2", wr);
        std::string name = text_at(row, "name", wr);
        if (row.contains("sample")) {
            if (!row["sample"].is_number_integer())
                throw DataError(wr + ": key 'sample' is not an integer");
            name += " (" + row["sample"].dump() + ")";
        }
        Json r = {{"sample", name}, {"E1_over_E2", number(ratio)}};
        add_slope_checks(r, row, wr, ratio, 6, theta1_rad, theta2_rad);
        rows.push_back(std::move(r));
    }
    return {{"conditions", t.conditions}, {"rows", rows}};
}

// One table; an estimator's refusal of a printed input (InvalidArgument, NoSolution) becomes a
// DataError naming the file and the table.
Json one_table(Json (*compute)(const Json&, const std::string&), const char* key,
               const Json& reference, const std::string& where) {
    try {
        return compute(reference, where);
    } catch (const DataError&) {
        throw;
    } catch (const Error& e) {
        throw DataError(where + ": " + key + ": " + e.what());
    }
}

// "line L, column C" of byte `offset` (0-based) of `text`.
std::string line_and_column(std::string_view text, std::size_t offset) {
    offset = std::min(offset, text.size());
    const std::string_view before = text.substr(0, offset);
    const std::size_t line =
        1 + static_cast<std::size_t>(std::count(before.begin(), before.end(), '\n'));
    const std::size_t last_newline = before.rfind('\n');
    const std::size_t column =
        last_newline == std::string_view::npos ? offset + 1 : offset - last_newline;
    return "line " + std::to_string(line) + ", column " + std::to_string(column);
}

}  // namespace

Json recompute_paper_tables(const Json& reference, const std::string& where) {
    if (!reference.is_object()) throw DataError(where + ": not a JSON object");
    return {{"table1", one_table(table1, "table1_slightly_rough", reference, where)},
            {"table2", one_table(table2, "table2_very_rough", reference, where)},
            {"table3", one_table(table3, "table3_curet_parameters", reference, where)}};
}

Json read_paper_tables_reference(const std::filesystem::path& path) {
    const std::string name = path.string();
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw DataError(name + ": does not exist");
    if (std::filesystem::is_directory(path, ec))
        throw DataError(name + ": is a directory, not a file");
    io::check_input_file(path, name);
    std::ifstream in(path, std::ios::binary);
    if (!in) throw DataError(name + ": cannot open: " + std::strerror(errno));
    std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    if (in.bad()) throw DataError(name + ": read error");
    if (const auto nul = text.find('\0'); nul != std::string::npos)
        throw DataError(name + ": " + line_and_column(text, nul) + ": not a text file: NUL byte");
    try {
        return Json::parse(text);
    } catch (const Json::parse_error& e) {
        // nlohmann's text: "[json.exception.parse_error.101] parse error at line L, column C:
        // syntax error while parsing value - <what>; last read: '<text>'": keep <what>.
        std::string what = e.what();
        if (const auto colon = what.find(": ", what.find("column")); colon != std::string::npos)
            what = what.substr(colon + 2);
        if (const auto last = what.find("; last read"); last != std::string::npos)
            what.resize(last);
        const std::size_t offset = e.byte > 0 ? e.byte - 1 : 0;
        throw DataError(name + ": " + line_and_column(text, offset) + ": not valid JSON: " + what);
    }
}

}  // namespace roughscope::serialize
