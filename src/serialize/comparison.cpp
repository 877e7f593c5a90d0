// Output of the model comparison (serialize/comparison.hpp): JSON, CSV and Markdown.
#include "roughscope/serialize/comparison.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "io/json_reader.hpp"
#include "roughscope/brdf/curet.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/core/uncertainty.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/scattering/validity.hpp"
#include "roughscope/serialize/text.hpp"

namespace roughscope::serialize {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

std::string key(ComparisonModel m) { return std::string(to_string(m)); }

std::string fmt(double x, const char* spec = "%.6g") {
    char buf[64];
    std::snprintf(buf, sizeof buf, spec, x);
    return buf;
}

std::vector<double> normalised(const std::vector<double>& v) {
    double mx = -kInf;
    for (double x : v) mx = std::max(mx, x);
    std::vector<double> out(v.size(), 0.0);
    if (mx > 0.0)
        for (std::size_t j = 0; j < v.size(); ++j) out[j] = v[j] / mx;
    return out;
}

Json comparison_json(const Comparison& c, bool series) {
    Json j;
    j["sample"] = c.sample > 0 ? Json(c.sample) : Json(nullptr);
    j["name"] = text_or_null(c.name);
    j["channel"] = text_or_null(c.channel);
    j["measurements"] = c.total_measurements;
    j["used"] = c.measurement.size();
    const TwoPointEstimate& t = c.two_point;
    j["E1_over_E2"] = number(t.E1_over_E2);
    for (const Correlation k : kCorrelations)
        j[correlation_key("sigma_over_T", k)] = number(t.sigma_over_T(k));
    Json tp;
    tp["available"] = t.available;
    tp["reason"] = text_or_null(t.reason);
    tp["measurement1"] = t.measurement1;
    tp["measurement2"] = t.measurement2;
    tp["theta1_deg"] = t.E1 ? degrees(t.theta1_rad) : Json(nullptr);
    tp["theta2_deg"] = t.E2 ? degrees(t.theta2_rad) : Json(nullptr);
    tp["E1"] = number(t.E1);
    tp["E2"] = number(t.E2);
    tp["factor"] = "vh";
    for (const Correlation k : kCorrelations)
        tp[std::string(info(k).name) + "_reason"] = text_or_null(t.correlation_reason(k));
    // Caron's θK and the RMS slope (§3.5) where they are derived for the correlation function.
    for (const Correlation k : kCorrelations)
        if (info(k).caron_formulas && t.sigma_over_T(k)) {
            tp[correlation_key("theta_K_deg", k)] =
                number(rad_to_deg(caron_theta_K_rad(*t.sigma_over_T(k))));
            tp[correlation_key("rms_slope", k)] = number(rms_slope(*t.sigma_over_T(k)));
        }
    j["two_point"] = tp;
    Json sse, rmse, gsse;
    for (const ModelResult& r : c.models) {
        const std::string k = key(r.model);
        sse[k] = r.available ? number(r.errors.paper_sse) : Json(nullptr);
        rmse[k] = r.available ? number(r.errors.rmse) : Json(nullptr);
        gsse[k] = r.available ? number(r.errors.gain_sse) : Json(nullptr);
    }
    j["sse"] = sse;
    j["rmse"] = rmse;
    j["sse_gain"] = gsse;
    j["winner"] = c.winner ? Json(to_string(*c.winner)) : Json(nullptr);
    j["winner_paper_metric"] =
        c.winner_paper_metric ? Json(to_string(*c.winner_paper_metric)) : Json(nullptr);
    Json models;
    for (const ModelResult& r : c.models) {
        Json m;
        m["label"] = std::string(display_name(r.model));
        m["available"] = r.available;
        m["reason"] = text_or_null(r.reason);
        m["method"] = text_or_null(r.method);
        Json params = Json::object(), errs = Json::object();
        for (const ModelParameter& p : r.parameters) {
            params[p.name] = p.identified ? number(p.value) : Json(nullptr);
            if (p.standard_error) errs[p.name] = number(*p.standard_error);
        }
        m["parameters"] = params;
        m["standard_errors"] = errs;
        m["fit_status"] = r.fit_status ? Json(to_string(*r.fit_status)) : Json(nullptr);
        m["fit_message"] = text_or_null(r.fit_message);
        m["evaluations"] = r.evaluations;
        m["sse"] = r.available ? number(r.errors.paper_sse) : Json(nullptr);
        m["rmse"] = r.available ? number(r.errors.rmse) : Json(nullptr);
        m["sse_gain"] = r.available ? number(r.errors.gain_sse) : Json(nullptr);
        m["gain"] = r.available ? number(r.errors.gain) : Json(nullptr);
        models[key(r.model)] = m;
    }
    j["models"] = models;
    Json issues = Json::array();
    for (const DataIssue& d : c.data_issues) {
        Json i;
        i["measurement"] = d.measurement;
        i["f"] = number(d.value);
        i["issue"] = d.issue;
        i["excluded_from"] = d.excluded_from;
        i["note"] = d.note;
        issues.push_back(i);
    }
    j["data_issues"] = issues;
    if (series) {
        Json s;
        s["measurement"] = c.measurement;
        std::vector<double> ti, ts, ps;
        for (const Geometry& g : c.geometry) {
            ti.push_back(rad_to_deg(g.theta_i_rad));
            ts.push_back(rad_to_deg(g.theta_s_rad));
            ps.push_back(rad_to_deg(g.phi_s_rad));
        }
        s["theta_i_deg"] = ti;
        s["theta_s_deg"] = ts;
        s["phi_s_deg"] = ps;
        s["data"] = normalised(c.brightness);
        Json ms, mg;
        for (const ModelResult& r : c.models) {
            ms[key(r.model)] = r.available ? Json(normalised(r.prediction)) : Json(nullptr);
            if (!r.available) {
                mg[key(r.model)] = nullptr;
                continue;
            }
            std::vector<double> scaled(r.prediction.size());
            for (std::size_t k = 0; k < scaled.size(); ++k)
                scaled[k] = r.errors.gain * r.prediction[k];
            mg[key(r.model)] = scaled;
        }
        s["models"] = ms;       // each model / its maximum (the paper's Fig. 10)
        s["models_gain"] = mg;  // K · model with the optimal gain K (compare with `data`)
        j["series"] = s;
    }
    return j;
}

std::string csv_number(double v) { return std::isfinite(v) ? fmt(v, "%.10g") : ""; }
std::string csv_number(const std::optional<double>& v) { return v ? csv_number(*v) : ""; }

std::string csv_text(const std::string& s) {
    if (s.find_first_of(",\"\n") == std::string::npos) return s;
    std::string out = "\"";
    for (char ch : s) {
        if (ch == '"') out += '"';
        out += ch;
    }
    return out + "\"";
}

std::string issues_summary(const Comparison& c) {
    std::string s;
    for (const DataIssue& d : c.data_issues) {
        if (!s.empty()) s += "; ";
        s += std::to_string(d.measurement) + ":" + d.issue;
        if (!d.excluded_from.empty()) {
            s += " (excluded from";
            for (const std::string& e : d.excluded_from) s += " " + e;
            s += ")";
        }
    }
    return s;
}

std::string md_escape(const std::string& s) {
    std::string out;
    for (char ch : s) {
        if (ch == '|')
            out += "\\|";
        else if (ch == '\n')
            out += ' ';
        else
            out += ch;
    }
    return out;
}

// Significant digits of the text report's headline numbers (the CLI's precision, docs/cli.md).
constexpr int kTextDigits = 10;

// ASCII labels for the aligned text table (an en dash as "-").
std::string ascii(std::string_view s) {
    std::string out;
    for (std::size_t k = 0; k < s.size(); ++k) {
        if (k + 2 < s.size() && static_cast<unsigned char>(s[k]) == 0xE2 &&
            static_cast<unsigned char>(s[k + 1]) == 0x80 &&
            static_cast<unsigned char>(s[k + 2]) == 0x93) {
            out += '-';
            k += 2;
        } else {
            out += s[k];
        }
    }
    return out;
}

// Six significant digits for the text tables (the library's format_significant); throws on
// NaN/inf (never printed). A -0 read from a data file stays "-0" in the data-issue list.
std::string short_number(double v, std::string_view name) {
    if (v == 0.0 && std::signbit(v)) return "-0";
    return format_significant(v, 6, name);
}

}  // namespace

ComparisonOptions comparison_options_from(const Json& options) {
    const io::JsonNode named(options, "comparison options", io::JsonSource::Arguments);
    if (!options.is_null())
        named.only({"theta1_deg", "theta2_deg", "pair", "on_sigma_rad", "on_albedo", "fits",
                    "radiometry", "max_overflow"});
    const auto number = [&](const char* key) -> std::optional<double> {
        if (const auto v = named.find(key)) return v->number();
        return std::nullopt;
    };
    ComparisonOptions o;
    const auto theta1 = number("theta1_deg");
    const auto theta2 = number("theta2_deg");
    if (theta1.has_value() != theta2.has_value())
        throw InvalidArgument("give both theta1_deg and theta2_deg (degrees) or neither");
    if (theta1) {
        o.theta1_rad = deg_to_rad(*theta1);
        o.theta2_rad = deg_to_rad(*theta2);
    }
    if (const auto pair = named.find("pair")) {
        // Two measurement numbers >= 1 (CUReT numbers them from 1).
        const auto items = pair->array(2, 2, "measurement numbers");
        o.measurement1 = static_cast<int>(items[0].integer(1, std::numeric_limits<int>::max()));
        o.measurement2 = static_cast<int>(items[1].integer(1, std::numeric_limits<int>::max()));
    }
    const auto on_sigma = number("on_sigma_rad");
    const auto on_albedo = number("on_albedo");
    if (on_sigma.has_value() != on_albedo.has_value())
        throw InvalidArgument("give both on_sigma_rad and on_albedo (Oren-Nayar) or neither");
    if (on_sigma) {
        o.oren_nayar = OrenNayarParams{*on_sigma, *on_albedo};
        o.oren_nayar_source = "given";
    }
    if (const auto fits = named.find("fits")) o.fits = fits->boolean();
    if (const auto r = named.find("radiometry")) o.radiometry = r->named(parse_radiometry);
    o.max_overflow_fraction = number("max_overflow");
    validate(o);
    return o;
}

Json to_json(const Comparison& comparison, bool series) {
    return comparison_json(comparison, series);
}

Json to_json(const std::vector<Comparison>& comparisons, bool series) {
    Json arr = Json::array();
    for (const Comparison& c : comparisons) arr.push_back(comparison_json(c, series));
    return arr;
}

std::string csv_header() {
    std::ostringstream out;
    out << "sample,name,channel,used,E1_over_E2";
    for (const Correlation k : kCorrelations) out << "," << correlation_key("sigma_over_T", k);
    for (const char* measure : {"sse", "rmse", "sse_gain"})
        for (ComparisonModel m : kComparisonModels) out << "," << measure << "_" << to_string(m);
    out << ",lafortune_n,winner,winner_paper_metric,two_point_reason,nonpositive_count,"
           "data_issues\n";
    return out.str();
}

std::string csv_row(const Comparison& c) {
    std::ostringstream out;
    out << (c.sample > 0 ? std::to_string(c.sample) : "") << "," << csv_text(c.name) << ","
        << csv_text(c.channel) << "," << c.measurement.size() << ","
        << csv_number(c.two_point.E1_over_E2);
    for (const Correlation k : kCorrelations) out << "," << csv_number(c.two_point.sigma_over_T(k));
    for (int measure = 0; measure < 3; ++measure)
        for (const ModelResult& r : c.models) {
            out << ",";
            if (!r.available) continue;
            out << csv_number(measure == 0   ? r.errors.paper_sse
                              : measure == 1 ? r.errors.rmse
                                             : r.errors.gain_sse);
        }
    std::size_t nonpositive = 0;
    for (const DataIssue& d : c.data_issues) nonpositive += d.issue == "non_positive";
    out << "," << csv_number(c.result(ComparisonModel::Lafortune).parameter("n")) << ","
        << (c.winner ? std::string(to_string(*c.winner)) : "") << ","
        << (c.winner_paper_metric ? std::string(to_string(*c.winner_paper_metric)) : "") << ","
        << csv_text(c.two_point.available ? "" : c.two_point.reason) << "," << nonpositive << ","
        << csv_text(issues_summary(c)) << "\n";
    return out.str();
}

std::string to_csv(const std::vector<Comparison>& comparisons) {
    std::string out = csv_header();
    for (const Comparison& c : comparisons) out += csv_row(c);
    return out;
}

std::string to_markdown(const std::vector<Comparison>& comparisons) {
    std::ostringstream out;
    out << "| sample | name | E1/E2";
    for (const Correlation k : kCorrelations) out << " | σ/T_" << info(k).letter;
    for (ComparisonModel m : kPaperComparisonModels) out << " | " << display_name(m);
    out << " | n_d | best fit (gain SSE) | winner, Table-4 metric | notes |\n";
    out << "|---:|---|---:";
    for (std::size_t k = 0; k < kCorrelationCount; ++k) out << "|---:";
    for (std::size_t k = 0; k < kPaperComparisonModels.size(); ++k) out << "|---:";
    out << "|---:|---|---|---|\n";
    auto cell = [](const std::optional<double>& v, const char* spec) {
        return v && std::isfinite(*v) ? fmt(*v, spec) : std::string("—");
    };
    for (const Comparison& c : comparisons) {
        out << "| " << (c.sample > 0 ? std::to_string(c.sample) : "") << " | " << md_escape(c.name)
            << " | " << cell(c.two_point.E1_over_E2, "%.6f");
        for (const Correlation k : kCorrelations)
            out << " | " << cell(c.two_point.sigma_over_T(k), "%.4f");
        for (ComparisonModel m : kPaperComparisonModels) {
            const ModelResult& r = c.result(m);
            out << " | " << (r.available ? cell(r.errors.paper_sse, "%.3f") : std::string("—"));
        }
        out << " | " << cell(c.result(ComparisonModel::Lafortune).parameter("n"), "%.2f");
        out << " | "
            << (c.winner ? std::string(display_name(*c.winner)) + " (" +
                               fmt(c.result(*c.winner).errors.gain_sse, "%.3f") + ")"
                         : std::string("—"));
        out << " | "
            << (c.winner_paper_metric ? std::string(display_name(*c.winner_paper_metric))
                                      : std::string("—"));
        std::string notes;
        if (!c.two_point.available) notes = "two-point estimate unavailable: " + c.two_point.reason;
        std::size_t nonpositive = 0;
        for (const DataIssue& d : c.data_issues) nonpositive += d.issue == "non_positive";
        if (nonpositive)
            notes += (notes.empty() ? "" : "; ") + std::to_string(nonpositive) +
                     " non-positive value(s) kept in the sums";
        out << " | " << md_escape(notes) << " |\n";
    }
    return out.str();
}
std::string to_text(const Comparison& c) {
    std::ostringstream out;
    out << (c.sample ? "CUReT sample " + std::to_string(c.sample) : c.name);
    if (c.sample && !curet_sample_name(c.sample).empty()) out << " (" << c.name << ")";
    out << ", channel " << (c.channel.empty() ? "-" : c.channel) << ": " << c.measurement.size()
        << " of " << c.total_measurements << " measurements used\n\n";
    const TwoPointEstimate& t = c.two_point;
    out << "Two-point estimate (Table 3; measurements " << t.measurement1 << " and "
        << t.measurement2 << ", F_VH, viewer on the normal):\n";
    if (t.available) {
        std::vector<std::pair<std::string, std::string>> kv;
        kv.emplace_back("theta1, theta2 (deg)",
                        short_number(rad_to_deg(t.theta1_rad), "theta1") + ", " +
                            short_number(rad_to_deg(t.theta2_rad), "theta2"));
        kv.emplace_back("E1/E2", format_significant(*t.E1_over_E2, kTextDigits, "E1/E2"));
        kv.emplace_back("sigma/T (Gaussian, Eq. 17)",
                        t.sigma_over_T_gaussian
                            ? format_significant(*t.sigma_over_T_gaussian, kTextDigits, "sigma/T")
                            : "unavailable: " + t.gaussian_reason);
        kv.emplace_back("sigma/T (exponential, Eq. 19)",
                        t.sigma_over_T_exponential ? format_significant(*t.sigma_over_T_exponential,
                                                                        kTextDigits, "sigma/T")
                                                   : "unavailable: " + t.exponential_reason);
        out << key_value_lines(kv);
    } else {
        out << "  unavailable: " << t.reason << "\n";
    }
    out << "\nErrors (Table 4 = sum of squared differences of max-normalised brightness; RMSE = "
           "sqrt(Table 4 / N); gain SSE = after the optimal gain):\n";
    std::vector<std::vector<std::string>> rows;
    auto skipped = [](const ModelResult& r) {
        return is_fit(r.model) && r.reason == "fits not requested";
    };
    for (const ModelResult& r : c.models) {
        if (skipped(r)) continue;
        std::vector<std::string> row{ascii(display_name(r.model))};
        if (!r.available) {
            row.insert(row.end(), {"-", "-", "-", "-", "unavailable"});
            rows.push_back(row);
            continue;
        }
        std::string params;
        for (const ModelParameter& p : r.parameters) {
            if (p.name == "gain") continue;
            if (!p.identified) {  // no number for what the data do not determine
                params += (params.empty() ? "" : ", ") + p.name + "=not-identifiable";
                continue;
            }
            // "name=value ± error" (core/uncertainty.hpp), the value alone with 6 digits.
            const std::string value = p.value == 0.0 && std::signbit(p.value)
                                          ? short_number(p.value, p.name)
                                          : format_uncertain(p.value, p.standard_error, 6, p.name);
            params += (params.empty() ? "" : ", ") + p.name + "=" + value;
        }
        row.push_back(params);
        row.push_back(short_number(r.errors.paper_sse, "Table-4 error"));
        row.push_back(short_number(r.errors.rmse, "RMSE"));
        row.push_back(short_number(r.errors.gain_sse, "gain SSE"));
        row.push_back(r.fit_status ? std::string(to_string(*r.fit_status)) : "");
        rows.push_back(row);
    }
    out << text_table({"model", "parameters", "Table 4", "RMSE", "gain SSE", "status"}, rows);
    out << "\nWinner by gain SSE (fits included): "
        << (c.winner ? ascii(display_name(*c.winner)) : std::string("-"))
        << "\nWinner by the Table-4 metric (paper's methods): "
        << (c.winner_paper_metric ? ascii(display_name(*c.winner_paper_metric)) : std::string("-"))
        << "\n";
    for (const ModelResult& r : c.models)
        if (!r.available && !skipped(r))
            out << "  " << ascii(display_name(r.model)) << ": " << r.reason << "\n";
    if (!c.data_issues.empty()) {
        out << "\nData issues (" << c.data_issues.size() << "):\n";
        for (const DataIssue& d : c.data_issues)
            out << "  measurement " << d.measurement << ": f = " << short_number(d.value, "f")
                << ", " << d.issue << " - " << d.note << "\n";
    }
    return out.str();
}

std::string to_text(const std::vector<Comparison>& all) {
    std::vector<std::vector<std::string>> rows;
    for (const Comparison& c : all) {
        std::vector<std::string> row{std::to_string(c.sample)};
        const TwoPointEstimate& t = c.two_point;
        row.push_back(t.E1_over_E2 ? short_number(*t.E1_over_E2, "E1/E2") : "-");
        row.push_back(t.sigma_over_T_gaussian ? short_number(*t.sigma_over_T_gaussian, "s/T")
                                              : "-");
        row.push_back(t.sigma_over_T_exponential ? short_number(*t.sigma_over_T_exponential, "s/T")
                                                 : "-");
        for (ComparisonModel m : kPaperComparisonModels) {
            const ModelResult& r = c.result(m);
            row.push_back(r.available ? short_number(r.errors.paper_sse, "error") : "-");
        }
        row.push_back(c.winner ? ascii(display_name(*c.winner)) : "-");
        row.push_back(std::to_string(c.data_issues.size()));
        rows.push_back(row);
    }
    std::ostringstream out;
    std::vector<std::string> header{"sample", "E1/E2", "s/T_G", "s/T_E"};
    for (ComparisonModel m : kPaperComparisonModels) header.push_back(ascii(display_name(m)));
    header.push_back("best (gain SSE)");
    header.push_back("issues");
    out << text_table(header, rows);
    return out.str();
}

}  // namespace roughscope::serialize
