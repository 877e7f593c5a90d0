// `roughscope paper tables`: the paper's Tables 1, 2 and 3 recomputed from their printed inputs
// with the §4 estimators, next to the printed values.
//
// The printed values are read from ../shared/reference/paper-tables.json (io/data_locator.hpp:
// $ROUGHSCOPE_SHARED_DIR, else searched upward from the current directory) or --reference FILE;
// they are not part of the repository. The library recomputes them (serialize/paper_tables.hpp,
// where the agreement marks are defined); this file only prints the document as text or JSON.
#include <cmath>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include "commands.hpp"
#include "common.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/estimation/estimation.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/scattering/validity.hpp"
#include "roughscope/serialize/json.hpp"
#include "roughscope/serialize/paper_tables.hpp"

namespace roughscope::cli {
namespace {

namespace fs = std::filesystem;

constexpr const char* kDefaultReference = "../shared/reference/paper-tables.json";

struct Args {
    std::string reference;  // empty: found by io::paper_tables_path (io/data_locator.hpp)
    bool json_output = false;
    std::string output_path;
    CLI::Option* o_output{};
};

// The text mark of one checked quantity (serialize/paper_tables.hpp).
std::string mark(const json& c) {
    const std::string a = c.at("agreement").get<std::string>();
    return a == "exact" ? "=" : a == "within_rounding" ? "~" : "DIFFERS";
}

double value(const json& j, const char* key) { return j.at(key).get<double>(); }

// "printed  recomputed  mark" cells of one checked quantity.
void add_cells(std::vector<std::string>& cells, const json& c, int printed_decimals,
               int recomputed_decimals) {
    cells.push_back(format_fixed(value(c, "printed"), printed_decimals));
    cells.push_back(format_fixed(value(c, "recomputed"), recomputed_decimals));
    cells.push_back(mark(c));
}

// The reference document (serialize/paper_tables.hpp; DataError naming the file and the place).
json load_reference(const fs::path& path, bool given) {
    std::error_code ec;
    if (!fs::exists(path, ec))
        throw roughscope::DataError(
            "paper tables not found at " +
            (given ? path.string()
                   : roughscope::io::shared_search_description(
                         roughscope::io::kPaperTablesRelative)) +
            " (the printed values live beside the project in ../shared/reference/; run from the "
            "project root or give --reference FILE)");
    return serialize::read_paper_tables_reference(path);
}

void run_tables(const Args& a) {
    const fs::path path = a.reference.empty()
                              ? roughscope::io::paper_tables_path().value_or(kDefaultReference)
                              : fs::path(a.reference);
    const json ref = load_reference(path, !a.reference.empty());
    json out;
    out["reference"] = path.string();
    const json tables = serialize::recompute_paper_tables(ref, path.string());
    for (const auto& [key, table] : tables.items()) out[key] = table;
    std::ostringstream text;

    {
        const json& t = out["table1"];
        const json& cond = t["conditions"];
        std::vector<std::vector<std::string>> cells;
        for (const json& row : t["rows"]) {
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
        print_table(text,
                    {"surface", "R_spec", "sigma", "sigma*", "", "E1/E2", "T", "T*", "", "sigma/T",
                     "sigma/T*", ""},
                    cells);
    }
    {
        const json& t = out["table2"];
        const json& cond = t["conditions"];
        std::vector<std::vector<std::string>> cells;
        for (const json& row : t["rows"]) {
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
        print_table(text,
                    {"surface", "E1/E2", "s/T_G", "s/T_G*", "", "s/T_E", "s/T_E*", "", "theta_K",
                     "theta_K*", "", "xi_K%", "xi_K%*", ""},
                    cells);
    }
    {
        const json& t = out["table3"];
        const json& cond = t["conditions"];
        std::vector<std::vector<std::string>> cells;
        for (const json& row : t["rows"]) {
            std::vector<std::string> c = {row["sample"].get<std::string>(),
                                          format_fixed(value(row, "E1_over_E2"), 6)};
            add_cells(c, row["sigma_over_T_G"], 4, 4);
            add_cells(c, row["sigma_over_T_E"], 4, 4);
            cells.push_back(std::move(c));
        }
        text << "\nTable 3 (CUReT; sigma/T from E1/E2 by Eq. 17 and 19 at "
             << format_fixed(value(cond, "theta1_deg"), 1) << "/"
             << format_fixed(value(cond, "theta2_deg"), 1) << " deg, F_VH)\n";
        print_table(text, {"sample", "E1/E2", "s/T_G", "s/T_G*", "", "s/T_E", "s/T_E*", ""}, cells);
    }
    text << "\n* recomputed from the printed inputs.  = same at the printed digits;  ~ within the "
            "rounding of the printed inputs;  DIFFERS otherwise.\n";

    write_output(given(a.o_output) ? std::optional<fs::path>(a.output_path) : std::nullopt,
                 a.json_output ? serialize::dump(serialize::versioned(out)) : text.str());
}

}  // namespace

void register_paper(CLI::App& app) {
    CLI::App* paper = app.add_subcommand(
        "paper", "Reproduce results of the paper (Ragheb & Hancock 2007) from its printed inputs");
    paper->require_subcommand(1);
    auto args = std::make_shared<Args>();
    Args& a = *args;
    CLI::App* cmd = paper->add_subcommand(
        "tables",
        "Tables 1, 2 and 3 recomputed from the printed inputs with the section-4 estimators, next "
        "to the printed values");
    cmd->add_option("--reference", a.reference,
                    std::string("JSON of the printed tables (default ") + kDefaultReference + ")");
    cmd->add_flag("--json", a.json_output, "Print JSON");
    a.o_output = cmd->add_option("--output", a.output_path, "Write to FILE atomically");
    cmd->callback([args]() { run_tables(*args); });
}

}  // namespace roughscope::cli
