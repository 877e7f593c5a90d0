// The text report of a measurement (measure.hpp): the CLI's default output of `roughscope
// measure`, from the same document as --json.
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "roughscope/core/numbers.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/core/uncertainty.hpp"
#include "roughscope/serialize/measure.hpp"
#include "roughscope/serialize/text.hpp"

namespace roughscope::serialize {
namespace {

// Significant digits of the text report's numbers (the CLI's precision, docs/cli.md).
constexpr int kTextDigits = 10;

std::string significant(double value, std::string_view name) {
    return format_significant(value, kTextDigits, name);
}

std::string value_with_error(const Json& doc, const std::string& key,
                             const std::string& unit = "") {
    const auto& v = doc[key];
    if (v.is_null()) return "-";
    // The standard error with 2 significant digits and the value to the same place (the digits
    // beyond are noise); without one, the value with the CLI's 10 significant digits.
    const auto& e = doc[key + "_stderr"];
    const std::string text = format_uncertain(
        v.get<double>(), e.is_null() ? std::nullopt : std::optional<double>(e.get<double>()),
        kTextDigits, key);
    return unit.empty() ? text : concat(text, " ", unit);
}

// The value to the decimal place that "value ± error" gives it (core/uncertainty.hpp).
std::string at_place_of(double value, double error, const std::string& name) {
    const std::string text = format_uncertain(value, error, kTextDigits, name);
    return text.substr(0, text.find(" ± "));
}

// With a budget (measure/budget.hpp): "0.300 ± 0.012 (k=1, 95 % [0.277, 0.324]); largest:
// theta_i of capture 2 (71 %)"; without one, the value and its statistical standard error.
std::string value_with_uncertainty(const Json& doc, const std::string& key,
                                   const std::string& unit = "") {
    const auto& u = doc[key + "_uncertainty"];
    if (doc[key].is_null() || u.is_null()) return value_with_error(doc, key, unit);
    const double value = doc[key].get<double>();
    const double uncertainty = u.get<double>();
    const auto& interval = doc[key + "_interval95"];
    std::string text = format_uncertain(value, uncertainty, kTextDigits, key);
    if (!unit.empty()) text = concat(text, " ", unit);
    text = concat(text, " (k=1, 95 % [", at_place_of(interval[0].get<double>(), uncertainty, key),
                  ", ", at_place_of(interval[1].get<double>(), uncertainty, key), "])");
    const auto& lines = doc["uncertainty_budget"][key];
    if (!lines.empty())
        text = concat(text, "; largest: ", printable_text(lines[0]["source"].get<std::string>()),
                      " (", format_fixed(100.0 * lines[0]["fraction"].get<double>(), 0), " %)");
    return text;
}

}  // namespace

std::string measure_text(const Json& doc) {
    std::vector<std::pair<std::string, std::string>> items;
    items.emplace_back("captures", std::to_string(doc["captures"].size()));
    items.emplace_back("object", doc["object"]["shape"].get<std::string>());
    if (doc["region"].contains("description"))
        items.emplace_back(
            "region",
            concat(printable_text(doc["region"]["description"].get<std::string>()), " (",
                   std::to_string(doc["region"]["pixels"].get<std::size_t>()), " pixels)"));
    items.emplace_back("E1/E2", value_with_uncertainty(doc, "E1_over_E2"));
    items.emplace_back("sigma/T (Gaussian)", value_with_uncertainty(doc, "sigma_over_T_gaussian"));
    items.emplace_back("sigma/T (exponential)",
                       value_with_uncertainty(doc, "sigma_over_T_exponential"));
    items.emplace_back("sigma", value_with_uncertainty(doc, "sigma_um", "um"));
    items.emplace_back("T", value_with_uncertainty(doc, "T_um", "um"));
    // The exact series (measure/exact_series.hpp): "0.412 ± 0.012 (T given σ; closed form
    // +38 %)" per correlation.
    if (const auto& es = doc["exact_series"]; !es.is_null())
        for (const char* c : {"gaussian", "exponential"}) {
            const auto& e = es[c];
            std::string text = value_with_error(e, "sigma_over_T");
            text = concat(text, " (", es["method_description"].get<std::string>());
            if (const auto& d = e["closed_form_deviation_rel"]; !d.is_null())
                text = concat(text, "; closed form ", d.get<double>() >= 0.0 ? "+" : "",
                              format_fixed(100.0 * d.get<double>(), 0), " %");
            items.emplace_back(concat("sigma/T exact series (", c, ")"), concat(text, ")"));
        }
    items.emplace_back("theta_K", value_with_error(doc, "theta_K_deg", "deg"));
    items.emplace_back("xi_K", value_with_error(doc, "xi_K"));
    const auto& cls = doc["roughness_class"];
    items.emplace_back(
        "roughness class",
        cls.is_null() ? std::string("-")
                      : concat(cls.get<std::string>(), doc["roughness_class_assumed"].get<bool>()
                                                           ? " (assumed by the estimator)"
                                                           : ""));
    if (const auto& cyl = doc["cylinder"]; !cyl.is_null()) {
        items.emplace_back("profile bins", std::to_string(cyl["profile"].size()));
        for (const auto& m : cyl["models"]) {
            const auto& d = m["departure_angle_deg"];
            items.emplace_back(concat("departure ", m["model"].get<std::string>()),
                               d.is_null()
                                   ? std::string("none (follows the data)")
                                   : concat(significant(d.get<double>(), "departure"), " deg"));
        }
    }
    if (const auto& sph = doc["sphere"]; !sph.is_null()) {
        items.emplace_back("sphere table rows", std::to_string(sph["rows"].get<std::size_t>()));
        const auto& winner = sph["comparison"]["winner"];
        items.emplace_back("best model",
                           winner.is_null() ? std::string("-") : winner.get<std::string>());
    }
    if (const auto& map = doc["map"]; !map.is_null()) {
        items.emplace_back("map",
                           concat(std::to_string(map["width"].get<std::size_t>()), " x ",
                                  std::to_string(map["height"].get<std::size_t>()), " (window ",
                                  std::to_string(map["window_px"].get<std::size_t>()), " px), ",
                                  std::to_string(map["valid"].get<std::size_t>()), " valid"));
        for (const auto& c : map["classes"])
            items.emplace_back(concat("map ", c["roughness_class"].get<std::string>()),
                               concat(format_fixed(100.0 * c["fraction"].get<double>(), 1), " %"));
        for (const auto& r : map["regions"])
            items.emplace_back(
                concat("region ", printable_text(r["name"].get<std::string>())),
                concat("sigma/T (G) ", value_with_error(r, "sigma_over_T_gaussian")));
    }
    std::ostringstream out;
    out << key_value_lines(items);
    // Names and paths from the capture file: control characters escaped (core/text.hpp).
    if (const auto& m = doc["uncertainty_method"]; !m.is_null())
        out << concat(
            "uncertainty: ",
            m.get<std::string>() == "monte_carlo"
                ? concat("Monte Carlo (",
                         std::to_string(doc["uncertainty_trials"].get<std::size_t>()), " trials)")
                : std::string("first order"),
            "; ± is the combined standard uncertainty (setup and pixel noise), "
            "--json gives each quantity's budget\n");
    for (const auto& w : doc["warnings"])
        out << "warning: " << printable_text(w.get<std::string>()) << '\n';
    return out.str();
}

std::string to_text(const image::MeasureResult& result, const image::MeasureRequest& request) {
    return measure_text(to_json(result, request));
}

}  // namespace roughscope::serialize
