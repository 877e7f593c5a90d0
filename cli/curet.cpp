// `roughscope curet`: models against measured BRDFs (paper §5.3, Tables 3–4, Fig. 10) for one
// CUReT sample, every sample, or any BRDF table in CSV. See docs/curet.md.
//
// The options become a ComparisonOptions and the results JSON/CSV/Markdown in the library
// (roughscope/serialize/comparison.hpp), as for the Python module. Figures (--plot) are drawn by
// the Python package: the comparison document is piped into `python3 -m roughscope.plot curet
// --out FILE` (python_runner.hpp); its error message, if any, becomes this command's error.
#include "roughscope/brdf/curet.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "commands.hpp"
#include "common.hpp"
#include "python_runner.hpp"
#include "roughscope/brdf/comparison.hpp"
#include "roughscope/brdf/table.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/serialize/comparison.hpp"

namespace roughscope::cli {
namespace {

namespace fs = std::filesystem;

enum class Format { Text, Json, Csv, Markdown };

// --format names, in the library's enum-name scheme (roughscope/core/names.hpp).
constexpr std::array<NameEntry<Format>, 5> kFormatNames{{
    {"text", Format::Text},
    {"json", Format::Json},
    {"csv", Format::Csv},
    {"markdown", Format::Markdown},
    {"md", Format::Markdown},  // alias
}};

Format parse_format(std::string_view name) { return parse_name(kFormatNames, "format", name); }

struct Args {
    int sample = 0;
    bool all = false;
    std::string table_path;
    std::string table_channel;
    std::string data_dir;
    CuretChannel channel = CuretChannel::Mean;
    Format format = Format::Text;
    bool json_flag = false;
    bool series = false;
    std::string plot_path;
    std::string output_path;
    double theta1_deg = 45.0, theta2_deg = 67.5;
    std::vector<int> pair;
    double on_sigma_rad = 0.0, on_albedo = 0.0;
    bool no_fits = false;
    Radiometry radiometry = Radiometry::Radiance;
    double max_overflow = 1.0;
    int threads = 0;

    CLI::Option *o_sample{}, *o_all{}, *o_table{}, *o_format{}, *o_theta1{}, *o_theta2{},
        *o_on_sigma{}, *o_on_albedo{}, *o_max_overflow{}, *o_data{}, *o_channel{},
        *o_table_channel{}, *o_threads{}, *o_pair{};
};

// A comparison in which no model is determined by the data (e.g. a one-row table, or every row
// at one geometry) has no result: NoSolution (exit 3) saying why, instead of arbitrary numbers.
void require_identified_model(const Comparison& c) {
    if (std::any_of(c.models.begin(), c.models.end(),
                    [](const ModelResult& r) { return r.identified(); }))
        return;
    std::string why;
    for (const ModelResult& r : c.models)
        if (r.available && !r.fit_message.empty()) {
            why = std::string(to_string(r.model)) + ": " + r.fit_message;
            break;
        }
    if (why.empty() && !c.models.empty()) why = c.models.front().reason;
    throw roughscope::NoSolution(
        (c.sample ? "CUReT sample " + std::to_string(c.sample) : "'" + c.name + "'") +
        ": no model is identifiable from these data (" + why + "; two-point estimate: " +
        (c.two_point.available ? "available" : c.two_point.reason) + ")");
}

void draw_plot(const json& document, const fs::path& out_png) {
    if (out_png.extension() != ".png")
        throw roughscope::InvalidArgument("--plot: '" + out_png.string() +
                                          "' must end in .png (the figure is a PNG)");
    run_python_module("roughscope.plot", {"curet", "--out", fs::absolute(out_png).string()},
                      serialize::dump(document, -1), "--plot");
}

void run(Args& a) {
    const int modes = (given(a.o_sample) ? 1 : 0) + (a.all ? 1 : 0) + (given(a.o_table) ? 1 : 0);
    if (modes != 1) throw UsageError("give exactly one of --sample N, --all or --table FILE.csv");
    if (a.json_flag) {
        if (given(a.o_format) && a.format != Format::Json)
            throw UsageError("--json conflicts with --format");
        a.format = Format::Json;
    }
    if (!given(a.o_format) && !a.json_flag && a.all) a.format = Format::Markdown;
    if (given(a.o_theta1) != given(a.o_theta2))
        throw UsageError("give both --theta1 and --theta2 (degrees) or neither");
    if (given(a.o_on_sigma) != given(a.o_on_albedo))
        throw UsageError("give both --on-sigma RAD and --on-albedo RHO or neither");
    if (given(a.o_on_sigma) && a.all)
        throw UsageError("--on-sigma/--on-albedo apply to one sample or table, not to --all");
    if (given(a.o_table) && (given(a.o_data) || given(a.o_channel)))
        throw UsageError("--data and --channel apply to CUReT; with --table use --table-channel");
    if (given(a.o_table_channel) && !given(a.o_table))
        throw UsageError("--table-channel applies to --table only");
    if (given(a.o_threads) && !a.all) throw UsageError("--threads applies to --all only");
    if (a.series && a.format != Format::Json) throw UsageError("--series needs --json");

    // Named options → ComparisonOptions by the library (the Python module does the same).
    json options = {{"fits", !a.no_fits}, {"radiometry", std::string(to_string(a.radiometry))}};
    if (given(a.o_theta1)) {
        options["theta1_deg"] = a.theta1_deg;
        options["theta2_deg"] = a.theta2_deg;
    }
    if (given(a.o_pair)) {
        if (a.pair.size() != 2)
            throw roughscope::InvalidArgument("--pair: expected two measurement numbers I,J >= 1");
        options["pair"] = a.pair;
    }
    if (given(a.o_on_sigma)) {
        options["on_sigma_rad"] = a.on_sigma_rad;
        options["on_albedo"] = a.on_albedo;
    }
    if (given(a.o_max_overflow)) options["max_overflow"] = a.max_overflow;
    ComparisonOptions o = serialize::comparison_options_from(options);
    // The predictions (N values per model) are output only in the series and the figure.
    o.keep_predictions = a.series || !a.plot_path.empty();

    std::string text;
    json plot_document;  // one comparison with its series (Fig. 10), or the list (summary)
    if (a.all) {
        const fs::path dir = find_curet_directory(
            given(a.o_data) ? std::optional<fs::path>(a.data_dir) : std::nullopt);
        const CuretDatabase db = load_curet(dir, a.channel);
        const std::vector<Comparison> all = compare_curet_all(db, o, a.threads);
        switch (a.format) {
            case Format::Json:
                text = serialize::dump(serialize::versioned(serialize::to_json(all, a.series)));
                break;
            case Format::Csv:
                text = serialize::to_csv(all);
                break;
            case Format::Markdown:
                text = serialize::to_markdown(all);
                break;
            case Format::Text:
                text = serialize::to_text(all);
                break;
        }
        if (!a.plot_path.empty()) plot_document = serialize::to_json(all, false);
    } else {
        Comparison c;
        if (given(a.o_table)) {
            BrdfCsvOptions co;
            if (given(a.o_table_channel)) co.channel = a.table_channel;
            c = compare_brdf(read_brdf_csv(a.table_path, co), o);
        } else {
            const fs::path dir = find_curet_directory(
                given(a.o_data) ? std::optional<fs::path>(a.data_dir) : std::nullopt);
            const CuretDatabase db = load_curet(dir, a.channel);
            c = compare_curet_sample(db, a.sample, o);
        }
        require_identified_model(c);
        switch (a.format) {
            case Format::Json:
                text = serialize::dump(serialize::versioned(serialize::to_json(c, a.series)));
                break;
            case Format::Csv:
                text = serialize::to_csv({c});
                break;
            case Format::Markdown:
                text = serialize::to_markdown({c});
                break;
            case Format::Text:
                text = serialize::to_text(c);
                break;
        }
        if (!a.plot_path.empty()) plot_document = serialize::to_json(c, true);
    }
    // The figure first: if it fails, nothing has been written.
    if (!a.plot_path.empty()) draw_plot(plot_document, a.plot_path);
    write_output(a.output_path.empty() ? std::nullopt : std::optional<fs::path>(a.output_path),
                 text);
}

}  // namespace

void register_curet(CLI::App& app) {
    auto args = std::make_shared<Args>();
    Args& a = *args;
    CLI::App* cmd = app.add_subcommand(
        "curet",
        "Compare reflectance models with measured BRDFs (paper 5.3, Tables 3-4, Fig. 10): one "
        "CUReT sample (--sample N), the whole database (--all), or any BRDF table (--table "
        "FILE.csv). See docs/curet.md.");
    const std::string what = "What to compare";
    cmd->add_option("--sample", a.sample, "CUReT sample number (1..61)")
        ->transform(
            integer_validator(std::numeric_limits<int>::min(), std::numeric_limits<int>::max()))
        ->group(what);
    cmd->add_flag("--all", a.all, "Every sample of the database")->group(what);
    cmd->add_option("--table", a.table_path,
                    "A BRDF table in CSV: theta_i,phi_i,theta_s,phi_s,value (degrees, 1/sr; "
                    "theta_s/phi_s = viewing direction, azimuths in one sample frame); optional "
                    "weight, channel, measurement")
        ->group(what);
    cmd->add_option("--table-channel", a.table_channel,
                    "Channel to use when the CSV has a channel column with several values")
        ->group(what);

    const std::string data = "CUReT data";
    cmd->add_option("--data", a.data_dir,
                    "Directory with table.txt and abrdf.dat (default: $ROUGHSCOPE_SHARED_DIR/"
                    "data/curet, else ../shared/data/curet searched upward from the current "
                    "directory, else $ROUGHSCOPE_CURET)")
        ->group(data);
    add_enum_option(*cmd, "--channel", a.channel, parse_curet_channel,
                    "mean (abrdf.dat, default), red, green or blue")
        ->group(data);
    add_range_option(*cmd, "--max-overflow", a.max_overflow, 0.0, 1.0,
                     "Exclude measurements whose published overflow (saturation) fraction "
                     "exceeds this (needs rover.dat etc.; default: keep all)")
        ->group(data);

    const std::string models = "Models";
    add_angle_option(*cmd, "--theta1", a.theta1_deg,
                     "Incidence angle of the first two-point measurement (deg; default: from "
                     "the angle table, 45 for CUReT)")
        ->group(models);
    add_angle_option(*cmd, "--theta2", a.theta2_deg,
                     "Incidence angle of the second two-point measurement (deg; default: from "
                     "the angle table, 67.5 for CUReT)")
        ->group(models);
    cmd->add_option("--pair", a.pair,
                    "Two-point measurement numbers I,J (default 81,112; both with the viewer "
                    "on the normal)")
        ->delimiter(',')
        ->expected(2)
        ->transform(integer_validator(1, std::numeric_limits<int>::max()))
        ->group(models);
    add_non_negative_option(*cmd, "--on-sigma", a.on_sigma_rad,
                            "Given Oren-Nayar facet slope sigma (rad; default for samples 25, "
                            "34, 41: the paper's Table 3)",
                            "rad")
        ->group(models);
    add_range_option(*cmd, "--on-albedo", a.on_albedo, 0.0, 1.0,
                     "Given Oren-Nayar albedo rho in [0, 1]")
        ->group(models);
    add_enum_option(*cmd, "--radiometry", a.radiometry, parse_radiometry,
                    "B-K interpretation: radiance (default, reproduces Table 4) or intensity")
        ->group(models);
    cmd->add_flag("--no-fits", a.no_fits, "Only the paper's methods (no least-squares fits)")
        ->group(models);
    cmd->add_option("--threads", a.threads, "Threads for --all (default: all cores)")
        ->transform(integer_validator(1, 1024))
        ->group(models);

    const std::string outg = "Output";
    add_enum_option(*cmd, "--format", a.format, parse_format,
                    "text (default for one sample), json, csv, markdown (default for --all)")
        ->group(outg);
    cmd->add_flag("--json", a.json_flag, "Same as --format json")->group(outg);
    cmd->add_flag("--series", a.series,
                  "With --json: add per-measurement data and model brightness (normalised)")
        ->group(outg);
    cmd->add_option("--plot", a.plot_path,
                    "Write a PNG: Fig. 10 for one sample, the database summary for --all")
        ->group(outg);
    cmd->add_option("--output", a.output_path, "Write the results to FILE atomically")->group(outg);

    a.o_sample = cmd->get_option("--sample");
    a.o_all = cmd->get_option("--all");
    a.o_table = cmd->get_option("--table");
    a.o_table_channel = cmd->get_option("--table-channel");
    a.o_data = cmd->get_option("--data");
    a.o_channel = cmd->get_option("--channel");
    a.o_max_overflow = cmd->get_option("--max-overflow");
    a.o_theta1 = cmd->get_option("--theta1");
    a.o_theta2 = cmd->get_option("--theta2");
    a.o_pair = cmd->get_option("--pair");
    a.o_on_sigma = cmd->get_option("--on-sigma");
    a.o_on_albedo = cmd->get_option("--on-albedo");
    a.o_format = cmd->get_option("--format");
    a.o_threads = cmd->get_option("--threads");

    cmd->callback([args]() { run(*args); });
}

}  // namespace roughscope::cli
