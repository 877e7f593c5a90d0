// JSON schemas of the §4 estimates and the fits (serialize/estimation.hpp).
#include "roughscope/serialize/estimation.hpp"

#include <algorithm>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "io/json_reader.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/scattering/correlation.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/scattering/validity.hpp"
#include "roughscope/serialize/text.hpp"

namespace roughscope::serialize {
namespace {

// An estimate's value and, when asked, its standard error (scaled, e.g. rad → deg).
void put(Json& out, const std::string& key, const std::optional<Estimate>& e, bool with_stderr,
         double scale = 1.0) {
    out[key] = e ? number(e->value * scale) : Json(nullptr);
    if (with_stderr) out[key + "_stderr"] = e ? number(e->std_error * scale) : Json(nullptr);
}

// §3.5 derived quantities, the class and g, present in every estimate.
void put_derived(Json& out, const RoughnessEstimate& e, bool with_stderr) {
    put(out, "theta_K_deg", e.theta_K_rad, with_stderr, 180.0 / kPi);
    put(out, "xi_K", e.xi_K, with_stderr);
    put(out, "rms_slope", e.rms_slope, with_stderr);
    out["roughness_class"] = std::string(to_string(e.roughness_class));
    out["roughness_class_assumed"] = e.roughness_class_assumed;
    out["g"] = e.g.empty() ? Json(nullptr) : numbers(e.g);
}

Json strings(const std::vector<std::string>& items) {
    Json out = Json::array();
    for (const auto& s : items) out.push_back(s);
    return out;
}

Json geometry_json(const Geometry& g) {
    return {{"theta_i_deg", degrees(g.theta_i_rad)},
            {"theta_s_deg", degrees(g.theta_s_rad)},
            {"phi_s_deg", degrees(g.phi_s_rad)}};
}

// The closed forms of §4 need the viewer on the normal (Fig. 5b); estimation.hpp: "normal view
// (θs = φs = 0) selects the closed form", otherwise the two-geometry solver.
bool normal_view(const Geometry& g) { return g.theta_s_rad == 0.0; }

Json ratio_range_json(const RatioRange& r) {
    return Json::array({number(r.lower), number(r.upper)});  // upper = inf → null
}

// The text reports' precision (the CLI's, docs/cli.md).
std::string significant(double value, std::string_view name) {
    return format_significant(value, 10, name);
}

}  // namespace

// ---------------------------------------------------------------------------------------------

FitOptions fit_options_from(const Json& options) {
    const io::JsonNode named(options, "fit options", io::JsonSource::Arguments);
    if (!options.is_null())
        named.only({"model", "correlation", "factor", "radiometry", "regime", "wavelength_um",
                    "residual", "loss", "loss_scale", "initial_sigma_over_T", "initial_sigma_um",
                    "initial_T_um", "sigma_over_T_bounds", "sigma_bounds_um", "T_bounds_um",
                    "max_iterations", "scale_covariance"});
    const auto number = [&](const char* key) -> std::optional<double> {
        if (const auto v = named.find(key)) return v->number();
        return std::nullopt;
    };
    const auto bounds = [&](const char* key, double& lower, double& upper) {
        if (const auto v = named.find(key)) {
            const auto pair = v->numbers(2);
            lower = pair[0];
            upper = pair[1];
        }
    };
    FitOptions o;
    if (const auto v = named.find("model")) o.model = v->named(parse_fit_model);
    if (const auto v = named.find("correlation")) o.correlation = v->named(parse_correlation);
    if (const auto v = named.find("factor")) o.factor = v->named(parse_geometric_factor);
    if (const auto v = named.find("radiometry")) o.radiometry = v->named(parse_radiometry);
    if (const auto v = named.find("regime")) o.regime = v->named(parse_regime);
    if (const auto v = number("wavelength_um")) o.wavelength_um = *v;
    if (const auto v = named.find("residual")) o.residual = v->named(parse_residual_type);
    if (const auto v = named.find("loss")) o.loss = v->named(parse_loss_type);
    if (const auto v = number("loss_scale")) o.loss_scale = *v;
    o.initial_sigma_over_T = number("initial_sigma_over_T");
    o.initial_sigma_um = number("initial_sigma_um");
    o.initial_T_um = number("initial_T_um");
    bounds("sigma_over_T_bounds", o.sigma_over_T_min, o.sigma_over_T_max);
    bounds("sigma_bounds_um", o.sigma_min_um, o.sigma_max_um);
    bounds("T_bounds_um", o.T_min_um, o.T_max_um);
    if (const auto v = named.find("max_iterations"))
        o.max_iterations = static_cast<int>(
            v->integer(std::numeric_limits<int>::min(), std::numeric_limits<int>::max()));
    if (const auto v = named.find("scale_covariance")) o.scale_covariance = v->boolean();
    return o;
}

Json budget_json(const std::vector<BudgetLine>& budget) {
    Json lines = Json::array();
    for (const BudgetLine& line : budget) {
        Json l;
        l["source"] = line.source;
        l["u_input"] = number(line.u_input);
        l["sensitivity"] = number(line.sensitivity);
        l["contribution"] = number(line.contribution);
        l["fraction"] = number(line.fraction);
        lines.push_back(l);
    }
    return lines;
}

Json to_json(const RoughnessEstimate& e, bool with_stderr) {
    Json out;
    put(out, "sigma_um", e.sigma_um, with_stderr);
    put(out, "T_um", e.T_um, with_stderr);
    put(out, "sigma_over_T", e.sigma_over_T, with_stderr);
    put_derived(out, e, with_stderr);
    out["warnings"] = strings(e.warnings);
    return out;
}

Json specular_estimate_json(const SpecularInput& in, const RoughnessEstimate& e, bool with_stderr) {
    const double R = in.E_tot && in.E_dif
                         ? specular_reflectance_from_brightness(*in.E_tot, *in.E_dif)
                         : in.R_spec;
    Json out;
    out["estimator"] = "specular (Eq. 12-13)";
    put(out, "sigma_um", e.sigma_um, with_stderr);
    out["R_spec"] = number(R);
    out["R0"] = number(in.R0);
    out["theta_deg"] = degrees(in.theta_rad);
    out["wavelength_um"] = number(in.wavelength_um);
    put_derived(out, e, with_stderr);
    out["warnings"] = strings(e.warnings);
    return out;
}

Json correlation_length_estimate_json(const CorrelationLengthInput& in, const RoughnessEstimate& e,
                                      bool with_stderr) {
    // CorrelationLengthInput: Eq. 15 at normal view for Gaussian correlation and Eq. 3.
    const bool closed = normal_view(in.geom1) && normal_view(in.geom2) &&
                        info(in.correlation).slightly_rough_inverse &&
                        in.options.regime == Regime::SlightlyRough;
    Json out;
    out["estimator"] = closed ? "correlation length (Eq. 14-15)"
                              : "correlation length (two-geometry solver, TOMS 748)";
    put(out, "sigma_um", e.sigma_um, with_stderr);
    put(out, "T_um", e.T_um, with_stderr);
    put(out, "sigma_over_T", e.sigma_over_T, with_stderr);
    put_derived(out, e, with_stderr);
    out["E1_over_E2"] = number(in.E1_over_E2);
    out["geometry1"] = geometry_json(in.geom1);
    out["geometry2"] = geometry_json(in.geom2);
    out["correlation"] = std::string(to_string(in.correlation));
    out["factor"] = std::string(to_string(in.options.factor));
    out["regime"] = std::string(to_string(in.options.regime));
    out["wavelength_um"] = number(in.options.wavelength_um);
    out["warnings"] = strings(e.warnings);
    return out;
}

Json slope_estimate_json(const SlopeInput& in,
                         const PerCorrelation<std::optional<RoughnessEstimate>>& estimates,
                         bool with_stderr) {
    std::vector<Correlation> given;  // the correlations with an estimate, in kCorrelations order
    for (const Correlation c : kCorrelations)
        if (estimates[c]) given.push_back(c);
    if (given.empty())
        throw InvalidArgument(
            "slope_estimate_json: give the estimate of at least one "
            "correlation function (" +
            correlation_names_text() + ")");
    // θK, ξK, m as in Table 2: from the Gaussian estimate when there is one (the first given).
    const RoughnessEstimate& primary = *estimates[given.front()];
    const bool closed = normal_view(in.geom1) && normal_view(in.geom2);  // Eq. 17 / 19
    Json out;
    out["estimator"] =
        closed ? "slope ratio (Eq. 16-19)" : "slope ratio (two-geometry solver, TOMS 748)";
    put(out, "sigma_over_T", primary.sigma_over_T, with_stderr);
    for (const Correlation c : kCorrelations)
        put(out, correlation_key("sigma_over_T", c),
            estimates[c] ? estimates[c]->sigma_over_T : std::nullopt, with_stderr);
    put(out, "sigma_um", primary.sigma_um, false);  // given, not estimated
    put(out, "T_um", primary.T_um, with_stderr);
    if (given.size() == kCorrelationCount && in.sigma_um)
        for (const Correlation c : kCorrelations)
            put(out, correlation_key("T_um", c), estimates[c]->T_um, with_stderr);
    put_derived(out, primary, with_stderr);
    out["E1_over_E2"] = number(in.E1_over_E2);
    const double t1 = in.geom1.theta_i_rad, t2 = in.geom2.theta_i_rad;
    for (const Correlation c : given)
        out[correlation_key("valid_ratio_range", c)] =
            closed ? ratio_range_json(ratio_range(c, t1, t2, in.options.factor)) : Json(nullptr);
    out["geometry1"] = geometry_json(in.geom1);
    out["geometry2"] = geometry_json(in.geom2);
    out["factor"] = std::string(to_string(in.options.factor));
    out["radiometry"] = std::string(to_string(in.options.radiometry));
    std::vector<std::string> ws;
    for (const Correlation c : given)
        for (const auto& w : estimates[c]->warnings)
            ws.push_back((given.size() > 1 ? std::string(info(c).name) + ": " : std::string()) + w);
    out["warnings"] = strings(ws);
    return out;
}

Json slope_estimate_json(const SlopeInput& in, const std::optional<RoughnessEstimate>& eg,
                         const std::optional<RoughnessEstimate>& ee, bool with_stderr) {
    PerCorrelation<std::optional<RoughnessEstimate>> estimates;
    estimates[Correlation::Gaussian] = eg;
    estimates[Correlation::Exponential] = ee;
    return slope_estimate_json(in, estimates, with_stderr);
}

// ---------------------------------------------------------------------------------------------

Json to_json(const FitResult& r, bool with_residuals) {
    Json out;
    const RoughnessEstimate& e = r.estimate;
    const bool err = r.covariance_available;
    out["correlation"] = std::string(to_string(r.options.correlation));
    out["status"] = std::string(to_string(r.status));
    put(out, "sigma_over_T", e.sigma_over_T, true);
    if (!err) out["sigma_over_T_stderr"] = nullptr;
    if (r.options.model == FitModel::SlightlyRough) {
        put(out, "sigma_um", e.sigma_um, true);
        put(out, "T_um", e.T_um, true);
        if (!err) out["sigma_um_stderr"] = out["T_um_stderr"] = nullptr;
    }
    const FitParameter* gain = nullptr;
    for (const auto& p : r.parameters)
        if (p.name == "gain") gain = &p;
    const bool gain_known = gain && gain->identified;
    out["gain"] = gain_known ? number(gain->value) : Json(nullptr);
    out["gain_stderr"] = gain_known && err ? number(gain->std_error) : Json(nullptr);
    put_derived(out, e, true);
    if (!err)
        for (const char* k : {"theta_K_deg_stderr", "xi_K_stderr", "rms_slope_stderr"})
            out[k] = nullptr;
    out["sse"] = number(r.sse);
    out["aic"] = number(r.aic);
    out["aicc"] = number(r.aicc);  // inf when N <= p + 1 → null
    out["n"] = r.num_measurements;
    out["parameters"] = r.num_parameters;
    out["iterations"] = r.iterations;
    Json table = Json::array();
    for (const auto& p : r.parameters)
        table.push_back({{"name", p.name},
                         {"value", p.identified ? number(p.value) : Json(nullptr)},
                         {"identified", p.identified},
                         {"stderr", err ? number(p.std_error) : Json(nullptr)},
                         {"lower", number(p.lower)},
                         {"upper", number(p.upper)},
                         {"at_bound", p.at_bound}});
    out["parameter_table"] = table;
    out["not_identifiable"] = strings(r.not_identifiable);
    if (err) {
        Json cov = Json::array();
        for (Eigen::Index a = 0; a < r.covariance.rows(); ++a) {
            Json row = Json::array();
            for (Eigen::Index b = 0; b < r.covariance.cols(); ++b)
                row.push_back(number(r.covariance(a, b)));
            cov.push_back(row);
        }
        out["covariance"] = cov;
    } else {
        out["covariance"] = nullptr;
    }
    if (with_residuals) {
        out["residuals"] = numbers(r.residuals);
        out["predicted"] = numbers(r.predicted);
    }
    out["message"] = r.message;
    out["report"] = r.brief_report();
    out["warnings"] = strings(e.warnings);
    return out;
}

Json to_json(const CorrelationComparison& c, bool with_residuals) {
    PerCorrelation<Json> fits;
    for (const Correlation k : kCorrelations) fits[k] = to_json(c[k], with_residuals);
    const Json& jb = fits[c.preferred];
    // Caron's θK, ξK, m come from the first correlation they are derived for (Gaussian, §3.5).
    const Correlation caron = *std::find_if(kCorrelations.begin(), kCorrelations.end(),
                                            [](Correlation k) { return info(k).caron_formulas; });
    const Json& jg = fits[caron];
    Json out;
    out["preferred_correlation"] = std::string(to_string(c.preferred));
    out["delta_aic"] = number(c.delta_aic);
    for (const char* k : {"sigma_over_T", "sigma_over_T_stderr"}) out[k] = jb[k];
    for (const Correlation k : kCorrelations) {
        out[correlation_key("sigma_over_T", k)] = fits[k]["sigma_over_T"];
        out[correlation_key("sigma_over_T", k) + "_stderr"] = fits[k]["sigma_over_T_stderr"];
    }
    if (c[c.preferred].options.model == FitModel::SlightlyRough)
        for (const char* k : {"sigma_um", "sigma_um_stderr", "T_um", "T_um_stderr"}) out[k] = jb[k];
    for (const char* k : {"theta_K_deg", "theta_K_deg_stderr", "xi_K", "xi_K_stderr", "rms_slope",
                          "rms_slope_stderr", "roughness_class", "roughness_class_assumed", "g"})
        out[k] = jg[k];
    for (const Correlation k : kCorrelations) out[std::string(info(k).name)] = fits[k];
    std::vector<std::string> ws;
    for (const Correlation k : kCorrelations)
        for (const auto& w : c[k].estimate.warnings)
            ws.push_back(std::string(info(k).name) + ": " + w);
    out["warnings"] = strings(ws);
    return out;
}

namespace {
Json fit_header(const FitOptions& o, std::size_t measurements) {
    Json out;
    out["estimator"] = "least squares (Ceres), " + std::string(to_string(o.model));
    out["measurements"] = measurements;
    out["factor"] = std::string(to_string(o.factor));
    out["radiometry"] = std::string(to_string(o.radiometry));
    out["residual"] = std::string(to_string(o.residual));
    out["loss"] = std::string(to_string(o.loss));
    return out;
}
}  // namespace

Json fit_estimate_json(const FitOptions& options, std::size_t measurements, const FitResult& fit,
                       bool with_residuals) {
    Json out = fit_header(options, measurements);
    const Json body = to_json(fit, with_residuals);
    for (const auto& [k, v] : body.items()) out[k] = v;
    return out;
}

Json fit_estimate_json(const FitOptions& options, std::size_t measurements,
                       const CorrelationComparison& comparison, bool with_residuals) {
    Json out = fit_header(options, measurements);
    const Json body = to_json(comparison, with_residuals);
    for (const auto& [k, v] : body.items()) out[k] = v;
    return out;
}

std::string estimate_text(const Json& record) {
    std::vector<std::pair<std::string, std::string>> items;
    for (const auto& [key, value] : record.items()) {
        std::string v;
        if (value.is_null()) {
            v = "unknown";
        } else if (value.is_boolean()) {
            v = value.get<bool>() ? "true" : "false";
        } else if (value.is_string()) {
            v = value.get<std::string>();
        } else if (value.is_number()) {
            v = significant(value.get<double>(), key);
        } else if (value.is_array() && key.rfind("valid_ratio_range", 0) == 0) {
            // Open interval; no upper bound is written "> lower" (never "inf").
            v = value[1].is_null() ? "> " + significant(value[0].get<double>(), key)
                                   : "(" + significant(value[0].get<double>(), key) + ", " +
                                         significant(value[1].get<double>(), key) + ")";
        } else if (value.is_array()) {
            if (key == "warnings") continue;  // printed below, one per line
            for (const auto& x : value) {
                if (!v.empty()) v += ", ";
                v += x.is_number() ? significant(x.get<double>(), key) : x.dump();
            }
            if (v.empty()) v = "(none)";
        } else {
            continue;  // nested objects: JSON only
        }
        items.emplace_back(key, v);
    }
    std::ostringstream os;
    os << key_value_lines(items);
    if (record.contains("warnings"))
        for (const auto& w : record["warnings"]) os << "warning: " << w.get<std::string>() << "\n";
    return os.str();
}

}  // namespace roughscope::serialize
