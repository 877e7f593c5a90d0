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

    write_output(given(a.o_output) ? std::optional<fs::path>(a.output_path) : std::nullopt,
                 a.json_output ? serialize::dump(serialize::versioned(out))
                               : serialize::paper_tables_text(tables));
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
