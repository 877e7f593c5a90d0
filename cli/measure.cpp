// `roughscope measure CAPTURE.json`: roughness from photographs (image/measure.hpp). The capture
// file names the images, their light and view directions and exposures, and the region; the
// result is σ (specular capture, Eq. 13), σ/T (Eq. 17/19 or the two-geometry solver), T given σ
// (Eq. 15), with standard errors. The JSON document is serialize/measure.hpp's (the same as the
// Python module's dict); --report DIR writes the HTML report through the Python package
// (roughscope.report_measure). Keys and the capture file: docs/measure.md.
#include "roughscope/image/measure.hpp"

#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "commands.hpp"
#include "common.hpp"
#include "python_runner.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/serialize/json.hpp"
#include "roughscope/serialize/measure.hpp"

namespace roughscope::cli {
namespace {

namespace fs = std::filesystem;

struct MeasureCommand {
    std::string capture_file;
    bool json_output = false;
    std::string output_path;
    std::string report_dir;
    CLI::Option *o_output{}, *o_report{};
};

std::string value_with_error(const serialize::Json& doc, const std::string& key,
                             const std::string& unit = "") {
    const auto& v = doc[key];
    if (v.is_null()) return "-";
    // The value with the CLI's 10 significant digits, its standard error with 2 (the digits
    // beyond are noise).
    std::string text = format_result(v.get<double>(), key);
    const auto& e = doc[key + "_stderr"];
    if (!e.is_null() && e.get<double>() > 0.0)
        text = concat(text, " ± ", roughscope::format_significant(e.get<double>(), 2, key));
    return unit.empty() ? text : concat(text, " ", unit);
}

std::string text_report(const serialize::Json& doc) {
    std::vector<std::pair<std::string, std::string>> items;
    items.emplace_back("captures", std::to_string(doc["captures"].size()));
    items.emplace_back(
        "region", concat(doc["region"]["description"].get<std::string>(), " (",
                         std::to_string(doc["region"]["pixels"].get<std::size_t>()), " pixels)"));
    items.emplace_back("E1/E2", value_with_error(doc, "E1_over_E2"));
    items.emplace_back("sigma/T (Gaussian)", value_with_error(doc, "sigma_over_T_gaussian"));
    items.emplace_back("sigma/T (exponential)", value_with_error(doc, "sigma_over_T_exponential"));
    items.emplace_back("sigma", value_with_error(doc, "sigma_um", "um"));
    items.emplace_back("T", value_with_error(doc, "T_um", "um"));
    items.emplace_back("theta_K", value_with_error(doc, "theta_K_deg", "deg"));
    items.emplace_back("xi_K", value_with_error(doc, "xi_K"));
    const auto& cls = doc["roughness_class"];
    items.emplace_back(
        "roughness class",
        cls.is_null() ? std::string("-")
                      : concat(cls.get<std::string>(), doc["roughness_class_assumed"].get<bool>()
                                                           ? " (assumed by the estimator)"
                                                           : ""));
    std::ostringstream out;
    print_key_values(out, items);
    for (const auto& w : doc["warnings"]) out << "warning: " << w.get<std::string>() << '\n';
    return out.str();
}

void run_measure(const MeasureCommand& c) {
    const image::MeasureRequest request = image::read_capture_file(c.capture_file);
    const image::MeasureResult result = image::measure(request);
    const serialize::Json doc = serialize::to_json(result, request);
    if (given(c.o_report)) {
        run_python_module("roughscope.report_measure",
                          {"--out", fs::absolute(c.report_dir).string()}, serialize::dump(doc),
                          "measure --report");
    }
    const std::string text = c.json_output ? serialize::dump(doc) : text_report(doc);
    write_output(given(c.o_output) ? std::optional<fs::path>(c.output_path) : std::nullopt, text);
}

}  // namespace

void register_measure(CLI::App& app) {
    auto args = std::make_shared<MeasureCommand>();
    MeasureCommand& c = *args;
    CLI::App* cmd = app.add_subcommand(
        "measure",
        "Roughness from photographs: sigma (specular capture), sigma/T and T from the captures "
        "named in a capture file (docs/measure.md)");
    cmd->add_option("capture_file", c.capture_file, "The capture file (JSON)")->required();
    cmd->add_flag("--json", c.json_output, "Print JSON (keys in docs/measure.md)");
    c.o_output = cmd->add_option("--output", c.output_path, "Write the result to FILE atomically");
    c.o_report = cmd->add_option("--report", c.report_dir,
                                 "Write an HTML report (photographs with the regions, values, "
                                 "checks) to DIR/index.html");
    cmd->callback([args]() { run_measure(*args); });
}

}  // namespace roughscope::cli
