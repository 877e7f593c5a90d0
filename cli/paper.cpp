// `roughscope paper tables`: the paper's Tables 1, 2 and 3 recomputed from their printed inputs
// with the §4 estimators, next to the printed values.
//
// The printed values are read from ../shared/reference/paper-tables.json (io/data_locator.hpp:
// $ROUGHSCOPE_SHARED_DIR, else searched upward from the current directory) or --reference FILE;
// they are not part of the repository. Each recomputed quantity is marked
//   exact            rounds to the printed value at the printed number of decimals;
//   within_rounding  the printed value lies in the range the recomputation spans when the
//                    printed inputs vary over their rounding interval (± half a unit of their
//                    last digit), widened by half a unit of the output's last digit;
//   differs          neither.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "common.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/estimation/estimation.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/scattering/validity.hpp"

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

double half_unit(int decimals) { return 0.5 * std::pow(10.0, -decimals); }

// One recomputed quantity against its printed value.
struct Check {
    double printed = 0.0;
    double recomputed = 0.0;
    double lo = 0.0, hi = 0.0;  // recomputation over the rounding box of the printed inputs
    int decimals = 0;           // printed decimals of the output

    std::string agreement() const {
        const double f = std::pow(10.0, decimals);
        if (std::llround(recomputed * f) == std::llround(printed * f)) return "exact";
        const double h = half_unit(decimals);
        if (printed >= lo - h && printed <= hi + h) return "within_rounding";
        return "differs";
    }
    json to_json() const {
        return {{"printed", finite_number(printed, "printed")},
                {"recomputed", finite_number(recomputed, "recomputed")},
                {"rounding_interval", json::array({finite_number(lo), finite_number(hi)})},
                {"agreement", agreement()}};
    }
};

// f at the printed inputs and over the corners of their rounding box (f monotonic in each).
Check check(double printed, int decimals, const std::vector<double>& inputs,
            const std::vector<int>& input_decimals,
            const std::function<double(const std::vector<double>&)>& f) {
    Check c;
    c.printed = printed;
    c.decimals = decimals;
    c.recomputed = f(inputs);
    c.lo = c.hi = c.recomputed;
    const std::size_t n = inputs.size();
    for (std::size_t mask = 0; mask < (std::size_t{1} << n); ++mask) {
        std::vector<double> x = inputs;
        for (std::size_t k = 0; k < n; ++k)
            x[k] += ((mask >> k) & 1 ? 1.0 : -1.0) * half_unit(input_decimals[k]);
        try {
            const double v = f(x);
            if (std::isfinite(v)) {
                c.lo = std::min(c.lo, v);
                c.hi = std::max(c.hi, v);
            }
        } catch (const roughscope::Error&) {
            // A corner outside the estimator's domain does not widen the interval.
        }
    }
    return c;
}

std::string mark(const Check& c) {
    const std::string a = c.agreement();
    return a == "exact" ? "=" : a == "within_rounding" ? "~" : "DIFFERS";
}

std::string num(double x, int decimals) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*f", decimals, x);
    return buf;
}

const json& need(const json& j, const char* key, const std::string& where) {
    if (!j.contains(key)) throw roughscope::DataError(where + ": missing key '" + key + "'");
    return j.at(key);
}

double num_at(const json& j, const char* key, const std::string& where) {
    const json& v = need(j, key, where);
    if (!v.is_number()) throw roughscope::DataError(where + ": key '" + key + "' is not a number");
    return v.get<double>();
}

// σ/T recomputed by Eq. 17 (Gaussian) and Eq. 19 (exponential) from the printed E1/E2 (given to
// `ratio_decimals` decimals) at θ1, θ2, against the row's printed sigma_over_T_G / _E (4 decimals).
struct SlopeChecks {
    Check gaussian, exponential;
};

SlopeChecks check_slope_ratios(const json& row, const std::string& where, double ratio,
                               int ratio_decimals, double theta1_rad, double theta2_rad) {
    const Check cg =
        check(num_at(row, "sigma_over_T_G", where), 4, {ratio}, {ratio_decimals},
              [&](const std::vector<double>& x) {
                  return sigma_over_T_gaussian_from_ratio(x[0], theta1_rad, theta2_rad);
              });
    const Check ce =
        check(num_at(row, "sigma_over_T_E", where), 4, {ratio}, {ratio_decimals},
              [&](const std::vector<double>& x) {
                  return sigma_over_T_exponential_from_ratio(x[0], theta1_rad, theta2_rad);
              });
    return {cg, ce};
}

json load_reference(const fs::path& path) {
    std::ifstream in(path);
    if (!in)
        throw roughscope::DataError(
            "paper tables not found at " + path.string() +
            " (the printed values live beside the project in ../shared/reference/; run from the "
            "project root or give --reference FILE)");
    try {
        return json::parse(in);
    } catch (const json::exception& e) {
        throw roughscope::DataError(path.string() + ": not valid JSON (" + e.what() + ")");
    }
}

void run_tables(const Args& a) {
    const fs::path path = a.reference.empty()
                              ? roughscope::io::paper_tables_path().value_or(kDefaultReference)
                              : fs::path(a.reference);
    const json ref = load_reference(path);
    const std::string where = path.string();
    json out;
    out["reference"] = path.string();
    std::ostringstream text;

    // ---- Table 1 ------------------------------------------------------------------------------
    {
        const json& t = need(ref, "table1_slightly_rough", where);
        const json& cond = need(t, "conditions", where + ": table1");
        const double th = deg_to_rad(num_at(cond, "specular_theta_deg", where));
        const double t1 = deg_to_rad(num_at(cond, "theta1_deg", where));
        const double t2 = deg_to_rad(num_at(cond, "theta2_deg", where));
        const double lambda = num_at(cond, "lambda_um", where);
        json rows = json::array();
        std::vector<std::vector<std::string>> cells;
        for (const auto& row : need(t, "rows", where + ": table1")) {
            const std::string w = where + ": table1 row";
            const double R = num_at(row, "R_spec", w), s = num_at(row, "sigma_um", w),
                         r = num_at(row, "E1_over_E2", w);
            const Check cs = check(s, 3, {R}, {3}, [&](const std::vector<double>& x) {
                return sigma_from_specular(x[0], th, lambda);
            });
            auto T = [&](const std::vector<double>& x) {
                return correlation_length_from_ratio(x[1], x[0], t1, t2, lambda);
            };
            const Check cT = check(num_at(row, "T_um", w), 3, {s, r}, {3, 3}, T);
            const Check cm = check(num_at(row, "sigma_over_T", w), 3, {s, r}, {3, 3},
                                   [&](const std::vector<double>& x) { return x[0] / T(x); });
            const std::string name = need(row, "surface", w).get<std::string>();
            rows.push_back({{"surface", name},
                            {"R_spec", R},
                            {"E1_over_E2", r},
                            {"sigma_um", cs.to_json()},
                            {"T_um", cT.to_json()},
                            {"sigma_over_T", cm.to_json()}});
            cells.push_back({name, num(R, 3), num(s, 3), num(cs.recomputed, 4), mark(cs), num(r, 3),
                             num(cT.printed, 3), num(cT.recomputed, 4), mark(cT),
                             num(cm.printed, 3), num(cm.recomputed, 4), mark(cm)});
        }
        out["table1"] = {{"conditions", cond}, {"rows", rows}};
        text << "Table 1 (slightly rough; sigma from R_spec by Eq. 13 at theta = "
             << num(rad_to_deg(th), 0) << " deg, T from the printed sigma and E1/E2 by Eq. 15 at "
             << num(rad_to_deg(t1), 0) << "/" << num(rad_to_deg(t2), 0)
             << " deg, lambda = " << lambda << " um, R0 = 1, F_VH)\n";
        print_table(text,
                    {"surface", "R_spec", "sigma", "sigma*", "", "E1/E2", "T", "T*", "", "sigma/T",
                     "sigma/T*", ""},
                    cells);
    }

    // ---- Table 2 ------------------------------------------------------------------------------
    {
        const json& t = need(ref, "table2_very_rough", where);
        const json& cond = need(t, "conditions", where + ": table2");
        const double t1 = deg_to_rad(num_at(cond, "theta1_deg", where));
        const double t2 = deg_to_rad(num_at(cond, "theta2_deg", where));
        json rows = json::array();
        std::vector<std::vector<std::string>> cells;
        for (const auto& row : need(t, "rows", where + ": table2")) {
            const std::string w = where + ": table2 row";
            const double r = num_at(row, "E1_over_E2", w);
            const auto [cg, ce] = check_slope_ratios(row, w, r, 3, t1, t2);
            const double sG = cg.printed;
            const Check ck = check(
                num_at(row, "theta_K_deg", w), 0, {sG}, {4},
                [&](const std::vector<double>& x) { return rad_to_deg(caron_theta_K_rad(x[0])); });
            const Check cx =
                check(num_at(row, "xi_K_percent", w), 1, {sG}, {4},
                      [&](const std::vector<double>& x) { return 100.0 * caron_xi_K(x[0]); });
            const std::string name = need(row, "surface", w).get<std::string>();
            rows.push_back({{"surface", name},
                            {"E1_over_E2", r},
                            {"sigma_over_T_G", cg.to_json()},
                            {"sigma_over_T_E", ce.to_json()},
                            {"theta_K_deg", ck.to_json()},
                            {"xi_K_percent", cx.to_json()}});
            cells.push_back({name, num(r, 3), num(sG, 4), num(cg.recomputed, 4), mark(cg),
                             num(ce.printed, 4), num(ce.recomputed, 4), mark(ce),
                             num(ck.printed, 0), num(ck.recomputed, 2), mark(ck),
                             num(cx.printed, 1), num(cx.recomputed, 2), mark(cx)});
        }
        out["table2"] = {{"conditions", cond}, {"rows", rows}};
        text << "\nTable 2 (very rough; sigma/T from E1/E2 by Eq. 17 and 19 at "
             << num(rad_to_deg(t1), 0) << "/" << num(rad_to_deg(t2), 0)
             << " deg, F_VH; theta_K and xi_K from the printed sigma/T_G)\n";
        print_table(text,
                    {"surface", "E1/E2", "s/T_G", "s/T_G*", "", "s/T_E", "s/T_E*", "", "theta_K",
                     "theta_K*", "", "xi_K%", "xi_K%*", ""},
                    cells);
    }

    // ---- Table 3 ------------------------------------------------------------------------------
    {
        const json& t = need(ref, "table3_curet_parameters", where);
        const json& cond = need(t, "conditions", where + ": table3");
        const double t1 = deg_to_rad(num_at(cond, "theta1_deg", where));
        const double t2 = deg_to_rad(num_at(cond, "theta2_deg", where));
        json rows = json::array();
        std::vector<std::vector<std::string>> cells;
        for (const auto& row : need(t, "rows", where + ": table3")) {
            const std::string w = where + ": table3 row";
            const double r = num_at(row, "E1_over_E2", w);
            const auto [cg, ce] = check_slope_ratios(row, w, r, 6, t1, t2);
            std::string name = need(row, "name", w).get<std::string>();
            if (row.contains("sample"))
                name += " (" + std::to_string(row["sample"].get<int>()) + ")";
            rows.push_back({{"sample", name},
                            {"E1_over_E2", r},
                            {"sigma_over_T_G", cg.to_json()},
                            {"sigma_over_T_E", ce.to_json()}});
            cells.push_back({name, num(r, 6), num(cg.printed, 4), num(cg.recomputed, 4), mark(cg),
                             num(ce.printed, 4), num(ce.recomputed, 4), mark(ce)});
        }
        out["table3"] = {{"conditions", cond}, {"rows", rows}};
        text << "\nTable 3 (CUReT; sigma/T from E1/E2 by Eq. 17 and 19 at "
             << num(rad_to_deg(t1), 1) << "/" << num(rad_to_deg(t2), 1) << " deg, F_VH)\n";
        print_table(text, {"sample", "E1/E2", "s/T_G", "s/T_G*", "", "s/T_E", "s/T_E*", ""}, cells);
    }
    text << "\n* recomputed from the printed inputs.  = same at the printed digits;  ~ within the "
            "rounding of the printed inputs;  DIFFERS otherwise.\n";

    write_output(given(a.o_output) ? std::optional<fs::path>(a.output_path) : std::nullopt,
                 a.json_output ? dump_json(out) : text.str());
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
