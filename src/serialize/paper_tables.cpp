#include "roughscope/serialize/paper_tables.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "io/json_reader.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/estimation/estimation.hpp"
#include "roughscope/scattering/correlation.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/scattering/validity.hpp"
#include "roughscope/serialize/text.hpp"

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

using io::JsonNode;

double num_at(const JsonNode& j, std::string_view key) { return j.at(key).number(); }

std::string text_at(const JsonNode& j, std::string_view key) { return j.at(key).string(); }

std::vector<JsonNode> rows_of(const JsonNode& table) {
    return table.at("rows").array(0, SIZE_MAX, "rows");
}

// σ/T by Eq. 17 and Eq. 19 from the printed E1/E2 (given to ratio_decimals decimals).
void add_slope_checks(Json& out, const JsonNode& row, double ratio, int ratio_decimals,
                      double theta1_rad, double theta2_rad) {
    for (const Correlation c : kCorrelations) {
        const std::string key = "sigma_over_T_" + std::string(info(c).letter);  // the paper's σ/T_G
        out[key] = check(num_at(row, key), 4, {ratio}, {ratio_decimals}, [&](const Inputs& x) {
            return sigma_over_T_from_ratio(c, x[0], theta1_rad, theta2_rad);
        });
    }
}

// What every printed table has: its conditions and the incidence angles θ1, θ2 of its ratio.
struct PrintedTable {
    JsonNode table;
    JsonNode conditions;
    double theta1_rad;
    double theta2_rad;
};

PrintedTable open_table(const JsonNode& reference, std::string_view key) {
    const JsonNode t = reference.at(key);
    const JsonNode cond = t.at("conditions");
    const double theta1_rad = deg_to_rad(num_at(cond, "theta1_deg"));
    const double theta2_rad = deg_to_rad(num_at(cond, "theta2_deg"));
    return {t, cond, theta1_rad, theta2_rad};
}

Json table1(const JsonNode& reference) {
    const PrintedTable t = open_table(reference, "table1_slightly_rough");
    const double theta_rad = deg_to_rad(num_at(t.conditions, "specular_theta_deg"));
    const double theta1_rad = t.theta1_rad, theta2_rad = t.theta2_rad;
    const double wavelength_um = num_at(t.conditions, "lambda_um");
    const auto T_of = [&](const Inputs& x) {  // x = {σ, E1/E2}: Eq. 15
        return correlation_length_from_ratio(x[1], x[0], theta1_rad, theta2_rad, wavelength_um);
    };
    Json rows = Json::array();
    for (const JsonNode& row : rows_of(t.table)) {
        const double R_spec = num_at(row, "R_spec");
        const double sigma_um = num_at(row, "sigma_um");
        const double ratio = num_at(row, "E1_over_E2");
        Json r = {{"surface", text_at(row, "surface")},
                  {"R_spec", number(R_spec)},
                  {"E1_over_E2", number(ratio)}};
        r["sigma_um"] = check(sigma_um, 3, {R_spec}, {3}, [&](const Inputs& x) {
            return sigma_from_specular(x[0], theta_rad, wavelength_um);  // Eq. 13
        });
        r["T_um"] = check(num_at(row, "T_um"), 3, {sigma_um, ratio}, {3, 3}, T_of);
        r["sigma_over_T"] = check(num_at(row, "sigma_over_T"), 3, {sigma_um, ratio}, {3, 3},
                                  [&](const Inputs& x) { return x[0] / T_of(x); });
        rows.push_back(std::move(r));
    }
    return {{"conditions", t.conditions.json()}, {"rows", rows}};
}

Json table2(const JsonNode& reference) {
    const PrintedTable t = open_table(reference, "table2_very_rough");
    const double theta1_rad = t.theta1_rad, theta2_rad = t.theta2_rad;
    Json rows = Json::array();
    for (const JsonNode& row : rows_of(t.table)) {
        const double ratio = num_at(row, "E1_over_E2");
        Json r = {{"surface", text_at(row, "surface")}, {"E1_over_E2", number(ratio)}};
        add_slope_checks(r, row, ratio, 3, theta1_rad, theta2_rad);
        // θK and ξK (§3.5) from the printed Gaussian σ/T.
        const double printed_sigma_over_T = num_at(row, "sigma_over_T_G");
        r["theta_K_deg"] =
            check(num_at(row, "theta_K_deg"), 0, {printed_sigma_over_T}, {4},
                  [](const Inputs& x) { return rad_to_deg(caron_theta_K_rad(x[0])); });
        r["xi_K_percent"] = check(num_at(row, "xi_K_percent"), 1, {printed_sigma_over_T}, {4},
                                  [](const Inputs& x) { return 100.0 * caron_xi_K(x[0]); });
        rows.push_back(std::move(r));
    }
    return {{"conditions", t.conditions.json()}, {"rows", rows}};
}

Json table3(const JsonNode& reference) {
    const PrintedTable t = open_table(reference, "table3_curet_parameters");
    const double theta1_rad = t.theta1_rad, theta2_rad = t.theta2_rad;
    Json rows = Json::array();
    for (const JsonNode& row : rows_of(t.table)) {
        const double ratio = num_at(row, "E1_over_E2");
        std::string name = text_at(row, "name");
        if (row.has("sample")) {
            const JsonNode sample = row.at("sample");
            if (!sample.json().is_number_integer())
                sample.fail("must be an integer (the CUReT sample number), not " +
                            sample.json().dump());
            name += " (" + sample.json().dump() + ")";
        }
        Json r = {{"sample", name}, {"E1_over_E2", number(ratio)}};
        add_slope_checks(r, row, ratio, 6, theta1_rad, theta2_rad);
        rows.push_back(std::move(r));
    }
    return {{"conditions", t.conditions.json()}, {"rows", rows}};
}

// One table; an estimator's refusal of a printed input (InvalidArgument, NoSolution) becomes a
// DataError naming the file and the table.
Json one_table(Json (*compute)(const JsonNode&), const char* key, const JsonNode& reference) {
    try {
        return compute(reference);
    } catch (const DataError&) {
        throw;
    } catch (const Error& e) {
        throw DataError(reference.where() + ": " + key + ": " + e.what());
    }
}

// The text mark of one checked quantity (serialize/paper_tables.hpp).
std::string mark(const Json& c) {
    const std::string a = c.at("agreement").get<std::string>();
    return a == "exact" ? "=" : a == "within_rounding" ? "~" : "DIFFERS";
}

double value(const Json& j, const char* key) { return j.at(key).get<double>(); }

// "printed  recomputed  mark" cells of one checked quantity.
void add_cells(std::vector<std::string>& cells, const Json& c, int printed_decimals,
               int recomputed_decimals) {
    cells.push_back(format_fixed(value(c, "printed"), printed_decimals));
    cells.push_back(format_fixed(value(c, "recomputed"), recomputed_decimals));
    cells.push_back(mark(c));
}

}  // namespace

Json recompute_paper_tables(const Json& reference, const std::string& where) {
    const JsonNode root(reference, where);
    if (!reference.is_object()) root.fail("not a JSON object");
    return {{"table1", one_table(table1, "table1_slightly_rough", root)},
            {"table2", one_table(table2, "table2_very_rough", root)},
            {"table3", one_table(table3, "table3_curet_parameters", root)}};
}

Json read_paper_tables_reference(const std::filesystem::path& path) {
    return io::read_json_file(path, "a file");
}

std::string paper_tables_text(const Json& tables) {
    std::ostringstream text;

    {
        const Json& t = tables["table1"];
        const Json& cond = t["conditions"];
        std::vector<std::vector<std::string>> cells;
        for (const Json& row : t["rows"]) {
            std::vector<std::string> c = {row["surface"].get<std::string>(),
                                          format_fixed(value(row, "R_spec"), 3)};
            add_cells(c, row["sigma_um"], 3, 4);
            c.push_back(format_fixed(value(row, "E1_over_E2"), 3));
            add_cells(c, row["T_um"], 3, 4);
            add_cells(c, row["sigma_over_T"], 3, 4);
            cells.push_back(std::move(c));
        }
        text << "Table 1 (slightly rough; sigma from R_spec by Eq. 13 at theta = "
             << format_fixed(value(cond, "specular_theta_deg"), 0)
             << " deg, T from the printed sigma and E1/E2 by Eq. 15 at "
             << format_fixed(value(cond, "theta1_deg"), 0) << "/"
             << format_fixed(value(cond, "theta2_deg"), 0)
             << " deg, lambda = " << value(cond, "lambda_um") << " um, R0 = 1, F_VH)\n";
        text << text_table({"surface", "R_spec", "sigma", "sigma*", "", "E1/E2", "T", "T*", "",
                            "sigma/T", "sigma/T*", ""},
                           cells);
    }
    {
        const Json& t = tables["table2"];
        const Json& cond = t["conditions"];
        std::vector<std::vector<std::string>> cells;
        for (const Json& row : t["rows"]) {
            std::vector<std::string> c = {row["surface"].get<std::string>(),
                                          format_fixed(value(row, "E1_over_E2"), 3)};
            add_cells(c, row["sigma_over_T_G"], 4, 4);
            add_cells(c, row["sigma_over_T_E"], 4, 4);
            add_cells(c, row["theta_K_deg"], 0, 2);
            add_cells(c, row["xi_K_percent"], 1, 2);
            cells.push_back(std::move(c));
        }
        text << "\nTable 2 (very rough; sigma/T from E1/E2 by Eq. 17 and 19 at "
             << format_fixed(value(cond, "theta1_deg"), 0) << "/"
             << format_fixed(value(cond, "theta2_deg"), 0)
             << " deg, F_VH; theta_K and xi_K from the printed sigma/T_G)\n";
        text << text_table({"surface", "E1/E2", "s/T_G", "s/T_G*", "", "s/T_E", "s/T_E*", "",
                            "theta_K", "theta_K*", "", "xi_K%", "xi_K%*", ""},
                           cells);
    }
    {
        const Json& t = tables["table3"];
        const Json& cond = t["conditions"];
        std::vector<std::vector<std::string>> cells;
        for (const Json& row : t["rows"]) {
            std::vector<std::string> c = {row["sample"].get<std::string>(),
                                          format_fixed(value(row, "E1_over_E2"), 6)};
            add_cells(c, row["sigma_over_T_G"], 4, 4);
            add_cells(c, row["sigma_over_T_E"], 4, 4);
            cells.push_back(std::move(c));
        }
        text << "\nTable 3 (CUReT; sigma/T from E1/E2 by Eq. 17 and 19 at "
             << format_fixed(value(cond, "theta1_deg"), 1) << "/"
             << format_fixed(value(cond, "theta2_deg"), 1) << " deg, F_VH)\n";
        text << text_table({"sample", "E1/E2", "s/T_G", "s/T_G*", "", "s/T_E", "s/T_E*", ""},
                           cells);
    }
    text << "\n* recomputed from the printed inputs.  = same at the printed digits;  ~ within the "
            "rounding of the printed inputs;  DIFFERS otherwise.\n";

    return text.str();
}

}  // namespace roughscope::serialize
