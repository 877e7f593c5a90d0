// JSON and text forms of the surface topic (serialize/surface.hpp).
#include "roughscope/serialize/surface.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/core/uncertainty.hpp"
#include "roughscope/scattering/factors.hpp"
#include "roughscope/scattering/validity.hpp"
#include "roughscope/serialize/model.hpp"
#include "roughscope/serialize/text.hpp"

namespace roughscope::serialize {

namespace {

Json curve_json(const surface::Curve& curve, const char* x_key, const char* y_key) {
    Json out = Json::object();
    out[x_key] = numbers(curve.x);
    out[y_key] = numbers(curve.y);
    return out;
}

Json strings(const std::vector<std::string>& items) {
    Json out = Json::array();
    for (const std::string& s : items) out.push_back(s);
    return out;
}

// "1.23457" (6 significant digits) or "-" for an unknown value.
std::string text_of(const Json& value) {
    if (value.is_null()) return "-";
    if (value.is_string()) return value.get<std::string>();
    if (value.is_boolean()) return value.get<bool>() ? "yes" : "no";
    if (value.is_number_integer() || value.is_number_unsigned()) return value.dump();
    return format_significant(value.get<double>(), 6);
}

// Aligned "label  value unit" lines.
void print_lines(std::ostringstream& out,
                 const std::vector<std::pair<std::string, std::string>>& items) {
    out << key_value_lines(items);
}

std::string with_unit(const Json& value, const char* unit) {
    std::string s = text_of(value);
    if (!value.is_null()) s.append(" ").append(unit);
    return s;
}

// "value ± error unit" (core/uncertainty.hpp; the value alone with 6 digits without an error),
// or "-" for an unknown value.
std::string uncertain_with_unit(const Json& value, const Json& error, const char* unit) {
    if (value.is_null()) return "-";
    const std::optional<double> e =
        error.is_number() ? std::optional<double>(error.get<double>()) : std::nullopt;
    return concat(format_uncertain(value.get<double>(), e, 6), " ", unit);
}

}  // namespace

StatisticsInput statistics_input(const surface::HeightMap& map,
                                 const surface::StatisticsOptions& options, const std::string& file,
                                 const std::string& format) {
    StatisticsInput in;
    in.file = file;
    in.format = format;
    in.nx = map.nx;
    in.ny = map.ny;
    in.dx_um = map.dx_um;
    in.dy_um = map.dy_um;
    in.options = options;
    return in;
}

Json to_json(const StatisticsInput& input, const surface::SurfaceStatistics& s, bool with_curves) {
    const surface::StatisticsOptions& o = input.options;
    Json j = Json::object();
    j["file"] = text_or_null(input.file);
    j["format"] = text_or_null(input.format);
    j["nx"] = input.nx;
    j["ny"] = input.ny;
    j["dx_um"] = number(input.dx_um);
    j["dy_um"] = number(input.dy_um);
    j["leveling"] = surface::to_string(o.leveling);
    j["polynomial_order"] =
        o.leveling == surface::Leveling::Polynomial ? Json(o.polynomial_order) : Json(nullptr);
    j["cutoff_um"] = number(o.cutoff_um);
    j["acf_estimator"] = surface::to_string(o.acf_estimator);
    j["points"] = s.points;
    j["sigma_um"] = number(s.sigma_um);
    j["sigma_stderr_um"] = number(s.sigma_stderr_um);
    j["Sa_um"] = number(s.Sa_um);
    j["Ssk"] = number(s.Ssk);
    j["Sku"] = number(s.Sku);
    j["Sp_um"] = number(s.Sp_um);
    j["Sv_um"] = number(s.Sv_um);
    j["Sz_um"] = number(s.Sz_um);
    j["T_um"] = number(s.T_um);
    j["T_y_um"] = number(s.T_y_um);
    j["T_stderr_um"] = number(s.T_stderr_um);
    for (const Correlation c : kCorrelations)
        j["T_fit_" + std::string(info(c).name) + "_um"] = number(s.fitted_T_um(c));
    j["correlation"] = s.correlation ? Json(std::string(to_string(*s.correlation))) : Json(nullptr);
    j["T_extrapolated_um"] = number(s.T_extrapolated_um);
    j["period_um"] = number(s.period_um);
    j["period_y_um"] = number(s.period_y_um);
    j["Sal_um"] = number(s.Sal_um);
    j["Str"] = number(s.Str);
    j["Str_note"] = text_or_null(s.Str_note);
    j["rms_slope"] = number(s.rms_slope);
    j["rms_slope_y"] = number(s.rms_slope_y);
    j["Sdq"] = number(s.Sdq);
    j["m_from_T"] = number(s.m_from_T);
    j["warnings"] = strings(s.warnings);
    if (with_curves) {
        Json c = Json::object();
        c["acf_x"] = curve_json(s.acf_x, "lag_um", "acf");
        c["acf_y"] = curve_json(s.acf_y, "lag_um", "acf");
        c["acf_radial"] = curve_json(s.acf_radial, "lag_um", "acf");
        c["psd_x"] = curve_json(s.psd_x, "frequency_per_um", "psd");
        c["psd_radial"] = curve_json(s.psd_radial, "frequency_per_um", "psd");
        j["curves"] = std::move(c);
    }
    return j;
}

std::string to_text(const StatisticsInput& input, const surface::SurfaceStatistics& s) {
    const Json j = to_json(input, s, false);
    std::ostringstream out;
    // The file name as typed, its control characters escaped (core/text.hpp).
    std::string source = input.file.empty() ? std::string("heights") : printable_text(input.file);
    if (!input.format.empty()) source.append(" (").append(input.format).append(")");
    out << source << ": " << input.nx << " x " << input.ny
        << " points, dx = " << text_of(j["dx_um"]) << " um, dy = " << text_of(j["dy_um"])
        << " um; levelling " << j["leveling"].get<std::string>();
    if (!j["polynomial_order"].is_null()) out << " (order " << j["polynomial_order"].dump() << ")";
    if (!j["cutoff_um"].is_null())
        out << ", Gaussian filter cutoff " << text_of(j["cutoff_um"]) << " um";
    out << "; " << j["acf_estimator"].get<std::string>() << " ACF\n";
    const std::string sigma = uncertain_with_unit(j["sigma_um"], j["sigma_stderr_um"], "um");
    const std::string T = uncertain_with_unit(j["T_um"], j["T_stderr_um"], "um");
    std::string Str = text_of(j["Str"]);
    if (!j["Str_note"].is_null())
        Str.append(" (").append(j["Str_note"].get<std::string>()).append(")");
    std::vector<std::pair<std::string, std::string>> lines{
        {"points", text_of(j["points"])},
        {"sigma (Sq)", sigma},
        {"Sa", with_unit(j["Sa_um"], "um")},
        {"Ssk", text_of(j["Ssk"])},
        {"Sku", text_of(j["Sku"])},
        {"Sp", with_unit(j["Sp_um"], "um")},
        {"Sv", with_unit(j["Sv_um"], "um")},
        {"Sz", with_unit(j["Sz_um"], "um")},
        {"T (1/e, x)", T},
        {"T (1/e, y)", with_unit(j["T_y_um"], "um")},
    };
    for (const Correlation c : kCorrelations)  // "T (Gaussian fit)", "T (exponential fit)"
        lines.emplace_back("T (" + std::string(info(c).adjective) + " fit)",
                           with_unit(j["T_fit_" + std::string(info(c).name) + "_um"], "um"));
    lines.insert(lines.end(), {
                                  {"correlation (AIC)", text_of(j["correlation"])},
                                  {"T (extrapolated)", with_unit(j["T_extrapolated_um"], "um")},
                                  {"period (ACF, x)", with_unit(j["period_um"], "um")},
                                  {"period (ACF, y)", with_unit(j["period_y_um"], "um")},
                                  {"Sal (s = 0.2)", with_unit(j["Sal_um"], "um")},
                                  {"Str", Str},
                                  {"RMS slope along x (Rdq)", text_of(j["rms_slope"])},
                                  {"RMS slope along y (Rdq)", text_of(j["rms_slope_y"])},
                                  {"RMS gradient (Sdq)", text_of(j["Sdq"])},
                                  {"m = sigma*sqrt(2)/T", text_of(j["m_from_T"])},
                              });
    print_lines(out, lines);
    for (const std::string& w : s.warnings) out << "warning: " << w << '\n';
    return out.str();
}

Json to_json(const surface::SurfacePrediction& p, const ModelOptions& options,
             const std::string& source, const std::string& T_source) {
    Json j = Json::object();
    j["source"] = source.empty() ? std::string("given") : source;
    j["T_source"] = text_or_null(T_source);
    j["sigma_um"] = number(p.surface.sigma_um);
    j["T_um"] = number(p.surface.T_um);
    j["correlation"] = std::string(to_string(p.surface.correlation));
    j["wavelength_um"] = number(p.wavelength_um);
    j["factor"] = std::string(to_string(options.factor));
    j["radiometry"] = std::string(to_string(options.radiometry));
    j["regime"] = std::string(to_string(options.regime));
    j["sigma_over_T"] = number(p.sigma_over_T);
    j["rms_slope"] = number(p.rms_slope);
    j["theta_K_deg"] = degrees(p.theta_K_rad);
    j["xi_K"] = number(p.xi_K);
    j["g_normal"] = number(p.g_normal);
    j["roughness_class"] = std::string(to_string(p.roughness_class));
    Json points = Json::array();
    for (const surface::PredictedBrightness& b : p.points) {
        Json q = Json::object();
        q["theta_i_deg"] = degrees(b.geometry.theta_i_rad);
        q["theta_s_deg"] = degrees(b.geometry.theta_s_rad);
        q["phi_s_deg"] = degrees(b.geometry.phi_s_rad);
        const Json power = to_json(b.power);
        for (auto it = power.begin(); it != power.end(); ++it) q[it.key()] = *it;
        q["very_rough_brightness"] = number(b.very_rough_brightness);
        q["beyond_theta_K"] = b.beyond_theta_K;
        points.push_back(std::move(q));
    }
    j["points"] = std::move(points);
    j["warnings"] = strings(p.warnings);
    return j;
}

std::string to_text(const surface::SurfacePrediction& p, const ModelOptions& options,
                    const std::string& source) {
    const Json j = to_json(p, options, source);
    std::ostringstream out;
    out << "surface (" << j["source"].get<std::string>()
        << "): sigma = " << with_unit(j["sigma_um"], "um") << ", T = " << with_unit(j["T_um"], "um")
        << ", " << j["correlation"].get<std::string>() << " correlation\n";
    print_lines(out, {
                         {"sigma/T", text_of(j["sigma_over_T"])},
                         {"RMS slope m", text_of(j["rms_slope"])},
                         {"Caron theta_K", with_unit(j["theta_K_deg"], "deg")},
                         {"Caron xi_K", text_of(j["xi_K"])},
                         {"wavelength", with_unit(j["wavelength_um"], "um")},
                         {"g at normal view", text_of(j["g_normal"])},
                         {"roughness class", j["roughness_class"].get<std::string>()},
                     });
    out << '\n';
    const std::vector<std::string> header = {"theta_i",    "theta_s", "phi_s", "brightness",
                                             "very_rough", "g",       "class"};
    std::vector<std::vector<std::string>> rows;
    for (const Json& q : j["points"])
        rows.push_back({text_of(q["theta_i_deg"]), text_of(q["theta_s_deg"]),
                        text_of(q["phi_s_deg"]), text_of(q["brightness"]),
                        text_of(q["very_rough_brightness"]), text_of(q["g"]),
                        q["roughness_class"].get<std::string>()});
    out << text_table(header, rows, TextTableStyle{.first_column_left = false, .rule = false});
    for (const std::string& w : p.warnings) out << "warning: " << w << '\n';
    return out.str();
}

Json summary_json(const surface::HeightMap& map) {
    std::size_t valid = 0;
    double lo = 0.0, hi = 0.0, sum = 0.0;
    for (double z : map.heights_um) {
        if (std::isnan(z)) continue;
        if (valid == 0) lo = hi = z;
        lo = std::min(lo, z);
        hi = std::max(hi, z);
        sum += z;
        ++valid;
    }
    Json j = Json::object();
    j["nx"] = map.nx;
    j["ny"] = map.ny;
    j["dx_um"] = number(map.dx_um);
    j["dy_um"] = number(map.dy_um);
    j["length_x_um"] = number(map.length_x_um());
    j["length_y_um"] = number(map.length_y_um());
    j["points"] = valid;
    j["missing"] = map.size() - valid;
    j["min_um"] = valid ? number(lo) : Json(nullptr);
    j["max_um"] = valid ? number(hi) : Json(nullptr);
    j["mean_um"] = valid ? number(sum / static_cast<double>(valid)) : Json(nullptr);
    j["title"] = text_or_null(map.title);
    return j;
}

Json height_image_json(const surface::HeightMap& map, std::size_t max_side) {
    if (max_side < 1) throw InvalidArgument("height image: max_side must be >= 1");
    const std::size_t side = std::max(map.nx, map.ny);
    const std::size_t stride = side <= max_side ? 1 : (side + max_side - 1) / max_side;
    const std::size_t nx = (map.nx + stride - 1) / stride, ny = (map.ny + stride - 1) / stride;
    Json rows = Json::array();
    for (std::size_t iy = 0; iy < ny; ++iy) {
        Json row = Json::array();
        for (std::size_t ix = 0; ix < nx; ++ix)
            row.push_back(number(map.at(ix * stride, iy * stride)));
        rows.push_back(std::move(row));
    }
    Json j = Json::object();
    j["nx"] = nx;
    j["ny"] = ny;
    j["dx_um"] = number(map.dx_um * static_cast<double>(stride));
    j["dy_um"] = number(map.dy_um * static_cast<double>(stride));
    j["stride"] = stride;
    j["heights_um"] = std::move(rows);
    return j;
}

}  // namespace roughscope::serialize
