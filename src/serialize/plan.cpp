// Output of capture planning (serialize/plan.hpp).
#include "roughscope/serialize/plan.hpp"

#include <string>
#include <utility>
#include <vector>

#include "roughscope/core/numbers.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/core/uncertainty.hpp"
#include "roughscope/scattering/correlation.hpp"
#include "roughscope/scattering/factors.hpp"
#include "roughscope/serialize/estimation.hpp"
#include "roughscope/serialize/text.hpp"

namespace roughscope::serialize {
namespace {

constexpr int kTextDigits = 6;

Json pair_json(const image::PlannedPair& p) {
    Json j;
    j["theta1_deg"] = number(p.theta1_deg);
    j["theta2_deg"] = number(p.theta2_deg);
    j["has_value"] = p.has_value;
    j["reason"] = text_or_null(p.reason);
    if (!p.has_value) {
        for (const char* key :
             {"sigma_over_T", "E1_over_E2", "sigma_over_T_uncertainty",
              "sigma_over_T_relative_uncertainty", "sigma_over_T_interval95", "method", "budget"})
            j[key] = Json();
        return j;
    }
    j["sigma_over_T"] = number(p.sigma_over_T);
    j["E1_over_E2"] = number(p.E1_over_E2);
    j["sigma_over_T_uncertainty"] = number(p.result.uncertainty);
    j["sigma_over_T_relative_uncertainty"] = number(p.relative_uncertainty);
    j["sigma_over_T_interval95"] =
        Json::array({number(p.result.interval95_low), number(p.result.interval95_high)});
    j["method"] = std::string(to_string(p.method));
    j["budget"] = budget_json(p.result.budget);
    return j;
}

std::string angles(const image::PlannedPair& p) {
    return concat(format_significant(p.theta1_deg, 6), "° / ", format_significant(p.theta2_deg, 6),
                  "°");
}

// "0.800 ± 0.012 (k=1, 95 % [0.777, 0.823])", or why there is none.
std::string uncertainty_text(const image::PlannedPair& p) {
    if (!p.has_value) return concat("no value: ", printable_text(p.reason));
    const OutputUncertainty& r = p.result;
    const std::string value = format_uncertain(r.value, r.uncertainty, kTextDigits, "sigma/T");
    const auto at_place = [&](double v) {
        const std::string t = format_uncertain(v, r.uncertainty, kTextDigits, "sigma/T");
        return t.substr(0, t.find(" ± "));
    };
    return concat("σ/T ", value, " (k=1, 95 % [", at_place(r.interval95_low), ", ",
                  at_place(r.interval95_high), "]), E1/E2 ", format_significant(p.E1_over_E2, 4));
}

std::string largest(const image::PlannedPair& p) {
    if (!p.has_value || p.result.budget.empty()) return "-";
    const BudgetLine& l = p.result.budget.front();
    return concat(printable_text(l.source), " (", format_fixed(100.0 * l.fraction, 0), " %)");
}

}  // namespace

Json to_json(const image::CapturePlan& plan) {
    const image::PlanRequest& r = plan.request;
    Json j;
    j["correlation"] = std::string(info(r.correlation).name);
    j["factor"] = std::string(to_string(r.factor));
    j["sigma_over_T"] = number(r.sigma_over_T);
    j["sigma_over_T_max"] = number(r.sigma_over_T_max);
    j["sigma_over_T_points"] = numbers(plan.sigma_over_T_points);
    j["exposure"] = std::string(to_string(r.exposure));
    j["fill"] = number(r.fill);
    j["noise_rel"] = number(r.noise_rel);
    Json t;
    t["angle_deg"] = number(plan.angle_deg);
    t["exposure_rel"] = number(plan.exposure_rel);
    t["black_level_rel"] = number(plan.black_level_rel);
    j["tolerances"] = std::move(t);
    j["assumed"] = plan.assumed;
    Json g;
    g["theta_min_deg"] = number(r.theta_min_deg);
    g["theta_max_deg"] = number(r.theta_max_deg);
    g["theta_step_deg"] = number(r.theta_step_deg);
    g["min_difference_deg"] = number(r.min_difference_deg);
    g["pairs"] = plan.pairs;
    g["pairs_with_value"] = plan.pairs_with_value;
    j["grid"] = std::move(g);
    j["recommended"] = pair_json(plan.recommended);
    j["paper_30_45"] = pair_json(plan.reference);
    Json top = Json::array();
    for (const image::PlannedPair& p : plan.top) top.push_back(pair_json(p));
    j["top"] = std::move(top);
    j["warnings"] = plan.warnings;
    return j;
}

std::string plan_text(const image::CapturePlan& plan) {
    const image::PlannedPair& best = plan.recommended;
    const image::PlannedPair& paper = plan.reference;
    std::vector<std::pair<std::string, std::string>> items{
        {"recommended", concat("theta1 / theta2 = ", angles(best), "  (camera on the normal)")},
        {"predicted", uncertainty_text(best)},
        {"largest source", largest(best)},
        {"paper 30° / 45°", uncertainty_text(paper)},
    };
    if (paper.has_value && best.has_value && best.result.uncertainty > 0.0)
        items.emplace_back(
            "30° / 45° vs recommended",
            concat(format_significant(paper.result.uncertainty / best.result.uncertainty, 3),
                   " × the uncertainty"));
    items.emplace_back(
        "tolerances",
        concat("angle ", format_significant(plan.angle_deg, 3), "°, exposure ",
               format_significant(plan.exposure_rel, 3), ", black level ",
               format_significant(plan.black_level_rel, 3), " of full scale, pixel noise ",
               format_significant(plan.request.noise_rel, 3), " (k = 1)"));
    items.emplace_back("pairs", concat(std::to_string(plan.pairs_with_value), " of ",
                                       std::to_string(plan.pairs), " with a value"));
    std::string out = key_value_lines(items);
    std::vector<std::vector<std::string>> rows;
    for (const image::PlannedPair& p : plan.top)
        rows.push_back({format_significant(p.theta1_deg, 6), format_significant(p.theta2_deg, 6),
                        format_significant(p.E1_over_E2, 4),
                        format_significant(p.result.uncertainty, 3),
                        format_fixed(100.0 * p.relative_uncertainty, 2), largest(p)});
    out += concat("\n",
                  text_table({"theta1", "theta2", "E1/E2", "u(sigma/T)", "u %", "largest"}, rows));
    for (const std::string& w : plan.warnings) out += concat("warning: ", w, "\n");
    return out;
}

}  // namespace roughscope::serialize
