// Output of the model comparison with measured BRDFs (paper §5.3, Tables 3–4, Fig. 10): one JSON
// schema (keys in docs/curet.md), CSV rows, a Markdown table and the text report. Unknown values
// are null in JSON and empty in CSV, never NaN. Used by `roughscope curet` and roughscope.curet.
#pragma once

#include <string>
#include <vector>

#include "roughscope/brdf/comparison.hpp"
#include "roughscope/serialize/json.hpp"

namespace roughscope::serialize {

// The comparison options from named values; the one place a front end's options become a
// ComparisonOptions. Keys (all optional, null = default): theta1_deg and theta2_deg (both or
// neither), pair ([I, J] measurement numbers), on_sigma_rad and on_albedo (both or neither;
// given Oren–Nayar parameters), fits (bool), radiometry ("radiance" | "intensity"),
// max_overflow (fraction in [0, 1]). Validated (validate(ComparisonOptions)); an unknown key or
// a bad value throws InvalidArgument naming it.
ComparisonOptions comparison_options_from(const Json& options);

// One comparison as a JSON object; `series` adds the per-measurement data and model brightness
// (normalised by their maxima, and scaled by each model's optimal gain) used by Fig. 10.
Json to_json(const Comparison& comparison, bool series = false);
// Every comparison as a JSON array.
Json to_json(const std::vector<Comparison>& comparisons, bool series = false);

// The CSV header line and one row per comparison: estimates, the three error measures per
// model, winners, exclusions (each line ends in '\n').
std::string csv_header();
std::string csv_row(const Comparison& comparison);
std::string to_csv(const std::vector<Comparison>& comparisons);  // header + rows

// A Markdown table of the paper's Table 3–4 quantities plus the best fit and the exclusions.
std::string to_markdown(const std::vector<Comparison>& comparisons);

// The text report of `roughscope curet` (--format text): the two-point estimate, the table of
// models (parameters as "name=value ± error", core/uncertainty.hpp), the winners and the data
// issues of one comparison; for several, one aligned row per sample.
std::string to_text(const Comparison& comparison);
std::string to_text(const std::vector<Comparison>& comparisons);

}  // namespace roughscope::serialize
