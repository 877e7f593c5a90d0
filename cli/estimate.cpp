// `roughscope estimate`: roughness from brightness measurements (paper §4).
//
//   estimate specular            σ from the specular reflectance (Eq. 12–13)
//   estimate correlation-length  T from two diffuse measurements, σ known (Eq. 14–15)
//   estimate slope               σ/T from a brightness ratio (Eq. 16–19), very rough surfaces
//   estimate fit                 least squares to N ≥ 3 measurements from a CSV file
//
// Angles in degrees, lengths in µm. See docs/estimation.md and docs/cli.md.
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "common.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/estimation/estimation.hpp"
#include "roughscope/fit/fit.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/factors.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/scattering/validity.hpp"

namespace roughscope::cli {
namespace {

// Correlation choice of `estimate slope` / `estimate fit`: one, or both side by side.
enum class CorrelationChoice { Gaussian, Exponential, Both };

CorrelationChoice parse_correlation_choice(std::string_view name) {
    if (name == "both") return CorrelationChoice::Both;
    if (name == "gaussian") return CorrelationChoice::Gaussian;
    if (name == "exponential") return CorrelationChoice::Exponential;
    throw roughscope::InvalidArgument("correlation '" + std::string(name) +
                                      "' is not one of: gaussian, exponential, both");
}

// ---------------------------------------------------------------------------------------------
// Shared pieces: the brightness ratio, the two geometries, noise, output.

struct RatioArgs {
    double ratio = 0.0, e1 = 0.0, e2 = 0.0;
    CLI::Option *o_ratio{}, *o_e1{}, *o_e2{};
};

void add_ratio_options(CLI::App& cmd, RatioArgs& r) {
    const std::string g = "Brightness (give --ratio, or --e1 and --e2)";
    r.o_ratio =
        add_positive_option(cmd, "--ratio", r.ratio, "Brightness ratio E1/E2 (> 0)")->group(g);
    r.o_e1 = add_positive_option(cmd, "--e1", r.e1, "Brightness E1 at geometry 1 (> 0)")->group(g);
    r.o_e2 = add_positive_option(cmd, "--e2", r.e2, "Brightness E2 at geometry 2 (> 0)")->group(g);
}

double ratio_from(const RatioArgs& r) {
    if (given(r.o_ratio) && (given(r.o_e1) || given(r.o_e2)))
        throw UsageError("--ratio excludes --e1/--e2: give either --ratio R or --e1 E1 --e2 E2");
    if (given(r.o_ratio)) return r.ratio;
    if (given(r.o_e1) && given(r.o_e2)) return r.e1 / r.e2;
    if (given(r.o_e1) || given(r.o_e2))
        throw UsageError(std::string("missing ") + (given(r.o_e1) ? "--e2" : "--e1") +
                         ": give both brightness values --e1 E1 --e2 E2 (or --ratio R)");
    throw UsageError("missing brightness: give --ratio E1/E2, or --e1 E1 --e2 E2 (all > 0)");
}

struct PairArgs {
    double theta1_deg = 0.0, theta2_deg = 0.0;
    double theta_s1_deg = 0.0, phi_s1_deg = 0.0, theta_s2_deg = 0.0, phi_s2_deg = 0.0;
    CLI::Option *o_theta1{}, *o_theta2{};
};

void add_pair_options(CLI::App& cmd, PairArgs& p) {
    const std::string g = "Geometry (viewer on the normal unless --theta-s1/--theta-s2 given)";
    p.o_theta1 = add_angle_option(cmd, "--theta1", p.theta1_deg,
                                  "Incidence angle of measurement 1, degrees [0,90) (required)")
                     ->group(g);
    p.o_theta2 = add_angle_option(cmd, "--theta2", p.theta2_deg,
                                  "Incidence angle of measurement 2, degrees [0,90) (required)")
                     ->group(g);
    add_angle_option(cmd, "--theta-s1", p.theta_s1_deg,
                     "Viewing angle of measurement 1 (deg; default 0 = normal view)")
        ->group(g);
    add_azimuth_option(cmd, "--phi-s1", p.phi_s1_deg,
                       "Viewing azimuth of measurement 1 (deg; 0 = specular plane, 180 = retro)")
        ->group(g);
    add_angle_option(cmd, "--theta-s2", p.theta_s2_deg,
                     "Viewing angle of measurement 2 (deg; default 0)")
        ->group(g);
    add_azimuth_option(cmd, "--phi-s2", p.phi_s2_deg, "Viewing azimuth of measurement 2 (deg)")
        ->group(g);
}

std::pair<Geometry, Geometry> geometries_from(const PairArgs& p) {
    if (!given(p.o_theta1) || !given(p.o_theta2))
        throw UsageError(std::string("missing ") +
                         (!given(p.o_theta1) && !given(p.o_theta2) ? "--theta1 and --theta2"
                          : !given(p.o_theta1)                     ? "--theta1"
                                                                   : "--theta2") +
                         ": give both incidence angles in degrees [0, 90)");
    return {make_geometry(deg_to_rad(p.theta1_deg), deg_to_rad(p.theta_s1_deg),
                          deg_to_rad(p.phi_s1_deg)),
            make_geometry(deg_to_rad(p.theta2_deg), deg_to_rad(p.theta_s2_deg),
                          deg_to_rad(p.phi_s2_deg))};
}

bool normal_view(const Geometry& g) { return g.theta_s_rad == 0.0; }

struct OutputArgs {
    bool json_output = false;
    std::string output_path;
    CLI::Option* o_output{};
};

void add_output_options(CLI::App& cmd, OutputArgs& o) {
    cmd.add_flag("--json", o.json_output, "Print JSON (keys in docs/estimation.md)")
        ->group("Output");
    o.o_output = cmd.add_option("--output", o.output_path,
                                "Write the result to FILE atomically instead of stdout")
                     ->group("Output");
}

// Options that read the same in several subcommands.
CLI::Option* add_wavelength_option(CLI::App& cmd, double& wavelength_um) {
    return add_positive_option(cmd, "--wavelength", wavelength_um,
                               "Mean wavelength lambda (um; default 0.555)", "um");
}

CLI::Option* add_noise_option(CLI::App& cmd, double& noise) {
    return add_non_negative_option(cmd, "--noise", noise,
                                   "Relative 1-sigma noise of each brightness value");
}

CLI::Option* add_pair_radiometry_option(CLI::App& cmd, Radiometry& radiometry) {
    return add_enum_option(cmd, "--radiometry", radiometry, parse_radiometry,
                           "radiance (default) or intensity (matters only with theta_s > 0)");
}

void emit(const OutputArgs& o, const json& record) {
    std::string text;
    if (o.json_output) {
        text = dump_json(record);
    } else {
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
                v = format_result(value.get<double>(), key);
            } else if (value.is_array() && key.rfind("valid_ratio_range", 0) == 0) {
                // Open interval; no upper bound is written "> lower" (never "inf").
                v = value[1].is_null() ? "> " + format_result(value[0].get<double>(), key)
                                       : "(" + format_result(value[0].get<double>(), key) + ", " +
                                             format_result(value[1].get<double>(), key) + ")";
            } else if (value.is_array()) {
                if (key == "warnings") continue;  // printed below, one per line
                for (const auto& x : value) {
                    if (!v.empty()) v += ", ";
                    v += x.is_number() ? format_result(x.get<double>(), key) : x.dump();
                }
                if (v.empty()) v = "(none)";
            } else {
                continue;  // nested objects: JSON only
            }
            items.emplace_back(key, v);
        }
        std::ostringstream os;
        print_key_values(os, items);
        if (record.contains("warnings"))
            for (const auto& w : record["warnings"])
                os << "warning: " << w.get<std::string>() << "\n";
        text = os.str();
    }
    write_output(
        given(o.o_output) ? std::optional<std::filesystem::path>(o.output_path) : std::nullopt,
        text);
}

// An estimate's value and (when computed) its standard error.
void put(json& out, const std::string& key, const std::optional<Estimate>& e, bool with_error,
         double scale = 1.0) {
    out[key] = e ? finite_number(e->value * scale, key) : json(nullptr);
    if (with_error)
        out[key + "_stderr"] =
            e ? finite_number(e->std_error * scale, key + "_stderr") : json(nullptr);
}

// The keys every estimate carries (§3.5 derived quantities, class, g, warnings).
void put_derived(json& out, const RoughnessEstimate& e, bool with_error) {
    put(out, "theta_K_deg", e.theta_K_rad, with_error, 180.0 / kPi);
    put(out, "xi_K", e.xi_K, with_error);
    put(out, "rms_slope", e.rms_slope, with_error);
    out["roughness_class"] = std::string(to_string(e.roughness_class));
    out["roughness_class_assumed"] = e.roughness_class_assumed;
    if (e.g.empty()) {
        out["g"] = nullptr;
    } else {
        json g = json::array();
        for (double x : e.g) g.push_back(finite_number(x, "g"));
        out["g"] = g;
    }
}

json warnings_json(const std::vector<std::string>& ws) {
    json w = json::array();
    for (const auto& s : ws) w.push_back(s);
    return w;
}

json geometry_json(const Geometry& g) {
    return {{"theta_i_deg", finite_number(rad_to_deg(g.theta_i_rad))},
            {"theta_s_deg", finite_number(rad_to_deg(g.theta_s_rad))},
            {"phi_s_deg", finite_number(rad_to_deg(g.phi_s_rad))}};
}

// ---------------------------------------------------------------------------------------------
// estimate specular

struct SpecularArgs {
    double r_spec = 0.0, e_tot = 0.0, e_dif = 0.0, theta_deg = 0.0, wavelength_um = 0.555,
           r0 = kDefaultSmoothReflectanceR0, noise = 0.0;
    CLI::Option *o_r_spec{}, *o_e_tot{}, *o_e_dif{}, *o_theta{}, *o_noise{};
    OutputArgs out;
};

void run_specular(const SpecularArgs& a) {
    if (!given(a.o_theta))
        throw UsageError(
            "missing --theta: the specular angle theta = theta_i = theta_s in degrees "
            "[0, 90)");
    SpecularInput in;
    if (given(a.o_r_spec) && (given(a.o_e_tot) || given(a.o_e_dif)))
        throw UsageError(
            "--r-spec excludes --e-tot/--e-dif: give R_spec, or both brightness "
            "values (R_spec = 1 - E_dif/E_tot)");
    if (given(a.o_r_spec)) {
        in.R_spec = a.r_spec;
    } else if (given(a.o_e_tot) && given(a.o_e_dif)) {
        in.E_tot = a.e_tot;
        in.E_dif = a.e_dif;
    } else {
        throw UsageError(
            "missing specular measurement: give --r-spec R, or --e-tot E --e-dif E "
            "(peak and surrounding diffuse brightness)");
    }
    in.theta_rad = deg_to_rad(a.theta_deg);
    in.wavelength_um = a.wavelength_um;
    in.R0 = a.r0;
    in.relative_noise_tot = in.relative_noise_dif = a.noise;
    const RoughnessEstimate e = estimate_sigma_specular(in);
    const bool err = given(a.o_noise);
    const double R =
        in.E_tot ? specular_reflectance_from_brightness(*in.E_tot, *in.E_dif) : in.R_spec;

    json out;
    out["estimator"] = "specular (Eq. 12-13)";
    put(out, "sigma_um", e.sigma_um, err);
    out["R_spec"] = finite_number(R, "R_spec");
    out["R0"] = finite_number(a.r0, "R0");
    out["theta_deg"] = finite_number(a.theta_deg, "theta_deg");
    out["wavelength_um"] = finite_number(a.wavelength_um, "wavelength_um");
    put_derived(out, e, err);
    out["warnings"] = warnings_json(e.warnings);
    emit(a.out, out);
}

// ---------------------------------------------------------------------------------------------
// estimate correlation-length

struct CorrelationLengthArgs {
    RatioArgs ratio;
    PairArgs pair;
    double sigma_um = 0.0, sigma_stderr_um = 0.0, wavelength_um = 0.555, noise = 0.0;
    Correlation correlation = Correlation::Gaussian;
    GeometricFactor factor = GeometricFactor::VernoldHarvey;
    Radiometry radiometry = Radiometry::Radiance;
    Regime regime = Regime::SlightlyRough;
    CLI::Option *o_sigma{}, *o_sigma_stderr{}, *o_noise{};
    OutputArgs out;
};

void run_correlation_length(const CorrelationLengthArgs& a) {
    if (!given(a.o_sigma))
        throw UsageError(
            "missing --sigma: the RMS height in um (> 0), e.g. from `estimate "
            "specular`");
    const auto [g1, g2] = geometries_from(a.pair);
    if (a.regime == Regime::VeryRough || a.regime == Regime::VeryRoughSeriesLimit)
        throw UsageError("--regime " + std::string(to_string(a.regime)) +
                         ": T cannot be separated from sigma for a very rough surface (only "
                         "sigma/T: use `estimate slope`); use slightly_rough, series or auto");
    CorrelationLengthInput in;
    in.E1_over_E2 = ratio_from(a.ratio);
    in.sigma_um = a.sigma_um;
    in.sigma_um_std_error = a.sigma_stderr_um;
    in.geom1 = g1;
    in.geom2 = g2;
    in.correlation = a.correlation;
    in.options.factor = a.factor;
    in.options.radiometry = a.radiometry;
    in.options.regime = a.regime;
    in.options.wavelength_um = a.wavelength_um;
    in.noise = {a.noise, a.noise};
    const RoughnessEstimate e = estimate_correlation_length(in);
    const bool err = given(a.o_noise) || given(a.o_sigma_stderr);
    const bool closed = normal_view(g1) && normal_view(g2) &&
                        a.correlation == Correlation::Gaussian && a.regime == Regime::SlightlyRough;

    json out;
    out["estimator"] = closed ? "correlation length (Eq. 14-15)"
                              : "correlation length (two-geometry solver, TOMS 748)";
    put(out, "sigma_um", e.sigma_um, err);
    put(out, "T_um", e.T_um, err);
    put(out, "sigma_over_T", e.sigma_over_T, err);
    put_derived(out, e, err);
    out["E1_over_E2"] = finite_number(in.E1_over_E2, "E1_over_E2");
    out["geometry1"] = geometry_json(g1);
    out["geometry2"] = geometry_json(g2);
    out["correlation"] = std::string(to_string(a.correlation));
    out["factor"] = std::string(to_string(a.factor));
    out["regime"] = std::string(to_string(a.regime));
    out["wavelength_um"] = finite_number(a.wavelength_um, "wavelength_um");
    out["warnings"] = warnings_json(e.warnings);
    emit(a.out, out);
}

// ---------------------------------------------------------------------------------------------
// estimate slope

struct SlopeArgs {
    RatioArgs ratio;
    PairArgs pair;
    double noise = 0.0, sigma_um = 0.0, wavelength_um = 0.555;
    CorrelationChoice correlation = CorrelationChoice::Both;
    GeometricFactor factor = GeometricFactor::VernoldHarvey;
    Radiometry radiometry = Radiometry::Radiance;
    CLI::Option *o_noise{}, *o_sigma{};
    OutputArgs out;
};

RoughnessEstimate slope_for(const SlopeArgs& a, const Geometry& g1, const Geometry& g2,
                            double ratio, Correlation c) {
    SlopeInput in;
    in.E1_over_E2 = ratio;
    in.geom1 = g1;
    in.geom2 = g2;
    in.correlation = c;
    in.options.factor = a.factor;
    in.options.radiometry = a.radiometry;
    in.options.wavelength_um = a.wavelength_um;
    in.noise = {a.noise, a.noise};
    if (given(a.o_sigma)) in.sigma_um = a.sigma_um;
    try {
        return estimate_slope(in);
    } catch (const NoSolution& e) {
        if (a.correlation != CorrelationChoice::Both) throw;
        throw NoSolution(std::string(e.what()) + "; use --correlation " +
                         (c == Correlation::Gaussian ? "exponential" : "gaussian") +
                         " to estimate with the other correlation function alone");
    }
}

void run_slope(const SlopeArgs& a) {
    const auto [g1, g2] = geometries_from(a.pair);
    const double ratio = ratio_from(a.ratio);
    const bool err = given(a.o_noise);
    std::optional<RoughnessEstimate> eg, ee;
    if (a.correlation != CorrelationChoice::Exponential)
        eg = slope_for(a, g1, g2, ratio, Correlation::Gaussian);
    if (a.correlation != CorrelationChoice::Gaussian)
        ee = slope_for(a, g1, g2, ratio, Correlation::Exponential);
    // θK, ξK, m as in Table 2: from the Gaussian estimate when there is one.
    const RoughnessEstimate& primary = eg ? *eg : *ee;

    json out;
    const bool closed = normal_view(g1) && normal_view(g2);
    out["estimator"] =
        closed ? "slope ratio (Eq. 16-19)" : "slope ratio (two-geometry solver, TOMS 748)";
    put(out, "sigma_over_T", primary.sigma_over_T, err);
    put(out, "sigma_over_T_gaussian", eg ? eg->sigma_over_T : std::nullopt, err);
    put(out, "sigma_over_T_exponential", ee ? ee->sigma_over_T : std::nullopt, err);
    put(out, "sigma_um", primary.sigma_um, false);
    put(out, "T_um", primary.T_um, err);
    if (eg && ee && given(a.o_sigma)) {
        put(out, "T_um_gaussian", eg->T_um, err);
        put(out, "T_um_exponential", ee->T_um, err);
    }
    put_derived(out, primary, err);
    out["E1_over_E2"] = finite_number(ratio, "E1_over_E2");
    const auto range = [&](Correlation c) -> json {
        if (!closed) return nullptr;
        const RatioRange r =
            c == Correlation::Gaussian
                ? ratio_range_gaussian(g1.theta_i_rad, g2.theta_i_rad, a.factor)
                : ratio_range_exponential(g1.theta_i_rad, g2.theta_i_rad, a.factor);
        return json::array(
            {finite_number(r.lower), std::isinf(r.upper) ? json(nullptr) : finite_number(r.upper)});
    };
    if (eg) out["valid_ratio_range_gaussian"] = range(Correlation::Gaussian);
    if (ee) out["valid_ratio_range_exponential"] = range(Correlation::Exponential);
    out["geometry1"] = geometry_json(g1);
    out["geometry2"] = geometry_json(g2);
    out["factor"] = std::string(to_string(a.factor));
    out["radiometry"] = std::string(to_string(a.radiometry));
    std::vector<std::string> ws;
    if (eg)
        for (const auto& w : eg->warnings) ws.push_back((ee ? "gaussian: " : "") + w);
    if (ee)
        for (const auto& w : ee->warnings) ws.push_back((eg ? "exponential: " : "") + w);
    out["warnings"] = warnings_json(ws);
    emit(a.out, out);
}

// ---------------------------------------------------------------------------------------------
// estimate fit

struct FitArgs {
    std::string measurements_path;
    FitModel model = FitModel::VeryRough;
    CorrelationChoice correlation = CorrelationChoice::Both;
    GeometricFactor factor = GeometricFactor::VernoldHarvey;
    Radiometry radiometry = Radiometry::Radiance;
    Regime regime = Regime::SlightlyRough;
    ResidualType residual = ResidualType::Relative;
    LossType loss = LossType::None;
    double loss_scale = 0.05, wavelength_um = 0.555;
    double initial_sigma_over_T = 0.0, initial_sigma_um = 0.0, initial_T_um = 0.0;
    int max_iterations = 200;
    bool residuals = false;
    CLI::Option *o_measurements{}, *o_initial_sigma_over_T{}, *o_initial_sigma{}, *o_initial_T{},
        *o_regime{}, *o_wavelength{};
    OutputArgs out;
};

// Reads theta_i, phi_i, theta_s, phi_s, brightness[, weight] (degrees); errors name file:line.
std::vector<Measurement> read_measurements(const std::filesystem::path& path) {
    const auto rows = read_csv_with_header(
        path, {"theta_i", "phi_i", "theta_s", "phi_s", "brightness"}, {"weight"});
    std::vector<Measurement> ms;
    ms.reserve(rows.size());
    for (const auto& row : rows) {
        const std::string where = path.string() + ":" + std::to_string(row.line) + ": ";
        try {
            for (const char* col : {"theta_i", "theta_s"}) {
                const double v = row.at(col);
                if (!(v >= 0.0 && v < 90.0))
                    throw roughscope::InvalidArgument(
                        "column '" + std::string(col) + "': " + format_result(v, col) +
                        " is outside the valid range [0, 90) degrees");
            }
            const double b = row.at("brightness");
            if (!(b > 0.0))
                throw roughscope::InvalidArgument("column 'brightness': " + format_result(b) +
                                                  " must be > 0");
            const double w = row.find("weight").value_or(1.0);
            if (!(w > 0.0))
                throw roughscope::InvalidArgument("column 'weight': " + format_result(w) +
                                                  " must be > 0");
            const Geometry g = geometry_from_two_azimuths(
                deg_to_rad(row.at("theta_i")), deg_to_rad(row.at("phi_i")),
                deg_to_rad(row.at("theta_s")), deg_to_rad(row.at("phi_s")));
            ms.push_back({g, b, w});
        } catch (const roughscope::DataError&) {
            throw;
        } catch (const roughscope::InvalidArgument& e) {
            throw roughscope::DataError(where + e.what());
        }
    }
    return ms;
}

json fit_json(const FitResult& r, bool with_residuals) {
    json out;
    out["correlation"] = std::string(to_string(r.options.correlation));
    out["status"] = std::string(to_string(r.status));
    const auto& e = r.estimate;
    const bool err = r.covariance_available;
    put(out, "sigma_over_T", e.sigma_over_T, err);
    if (r.options.model == FitModel::SlightlyRough) {
        put(out, "sigma_um", e.sigma_um, err);
        put(out, "T_um", e.T_um, err);
    }
    const FitParameter& gain = r.parameter("gain");
    out["gain"] = finite_number(gain.value, "gain");
    out["gain_stderr"] = err ? finite_number(gain.std_error, "gain_stderr") : json(nullptr);
    put_derived(out, e, err);
    out["sse"] = finite_number(r.sse, "sse");
    out["aic"] = finite_number(r.aic, "aic");
    out["aicc"] = std::isfinite(r.aicc) ? finite_number(r.aicc, "aicc") : json(nullptr);
    out["n"] = r.num_measurements;
    out["parameters"] = r.num_parameters;
    out["iterations"] = r.iterations;
    json params = json::array();
    for (const auto& p : r.parameters)
        params.push_back({{"name", p.name},
                          {"value", finite_number(p.value, p.name)},
                          {"stderr", err ? finite_number(p.std_error, p.name) : json(nullptr)},
                          {"at_bound", p.at_bound}});
    out["parameter_table"] = params;
    if (err) {
        json cov = json::array();
        for (int a = 0; a < r.covariance.rows(); ++a) {
            json row = json::array();
            for (int b = 0; b < r.covariance.cols(); ++b)
                row.push_back(finite_number(r.covariance(a, b), "covariance"));
            cov.push_back(row);
        }
        out["covariance"] = cov;
    } else {
        out["covariance"] = nullptr;
    }
    if (with_residuals) {
        json res = json::array();
        for (double x : r.residuals) res.push_back(finite_number(x, "residual"));
        out["residuals"] = res;
    }
    out["message"] = r.message;
    out["report"] = r.brief_report();
    out["warnings"] = warnings_json(e.warnings);
    return out;
}

void run_fit(const FitArgs& a) {
    if (!given(a.o_measurements))
        throw UsageError(
            "missing --measurements FILE.csv (columns theta_i, phi_i, theta_s, "
            "phi_s, brightness[, weight]; degrees)");
    if (a.model == FitModel::VeryRough) {
        for (auto [o, f] : {std::pair{a.o_initial_sigma, "--initial-sigma"},
                            {a.o_initial_T, "--initial-T"},
                            {a.o_regime, "--regime"},
                            {a.o_wavelength, "--wavelength"}})
            if (given(o))
                throw UsageError(std::string(f) + " applies to --model slightly-rough only");
    } else if (given(a.o_initial_sigma_over_T)) {
        throw UsageError("--initial-sigma-over-T applies to --model very-rough only");
    }
    const auto ms = read_measurements(a.measurements_path);

    FitOptions o;
    o.model = a.model;
    o.factor = a.factor;
    o.radiometry = a.radiometry;
    o.regime = a.regime;
    o.wavelength_um = a.wavelength_um;
    o.residual = a.residual;
    o.loss = a.loss;
    o.loss_scale = a.loss_scale;
    o.max_iterations = a.max_iterations;
    if (given(a.o_initial_sigma_over_T)) o.initial_sigma_over_T = a.initial_sigma_over_T;
    if (given(a.o_initial_sigma)) o.initial_sigma_um = a.initial_sigma_um;
    if (given(a.o_initial_T)) o.initial_T_um = a.initial_T_um;

    json out;
    out["estimator"] = "least squares (Ceres), " + std::string(to_string(a.model));
    out["measurements"] = static_cast<int>(ms.size());
    out["factor"] = std::string(to_string(a.factor));
    out["radiometry"] = std::string(to_string(a.radiometry));
    out["residual"] = std::string(to_string(a.residual));
    out["loss"] = std::string(to_string(a.loss));
    if (a.correlation == CorrelationChoice::Both) {
        const CorrelationComparison c = compare_correlations(ms, o);
        const FitResult& best = c.preferred == Correlation::Gaussian ? c.gaussian : c.exponential;
        const json jg = fit_json(c.gaussian, a.residuals);
        const json je = fit_json(c.exponential, a.residuals);
        const json jb = fit_json(best, false);
        out["preferred_correlation"] = std::string(to_string(c.preferred));
        out["delta_aic"] = finite_number(c.delta_aic, "delta_aic");
        for (const char* k : {"sigma_over_T", "sigma_over_T_stderr"}) out[k] = jb[k];
        out["sigma_over_T_gaussian"] = jg["sigma_over_T"];
        out["sigma_over_T_gaussian_stderr"] = jg["sigma_over_T_stderr"];
        out["sigma_over_T_exponential"] = je["sigma_over_T"];
        out["sigma_over_T_exponential_stderr"] = je["sigma_over_T_stderr"];
        if (a.model == FitModel::SlightlyRough)
            for (const char* k : {"sigma_um", "sigma_um_stderr", "T_um", "T_um_stderr"})
                out[k] = jb[k];
        // Caron's θK, ξK, m from the Gaussian fit (they are Gaussian-correlation quantities).
        for (const char* k :
             {"theta_K_deg", "theta_K_deg_stderr", "xi_K", "xi_K_stderr", "rms_slope",
              "rms_slope_stderr", "roughness_class", "roughness_class_assumed", "g"})
            out[k] = jg[k];
        out["gaussian"] = jg;
        out["exponential"] = je;
        std::vector<std::string> ws;
        for (const auto& w : c.gaussian.estimate.warnings) ws.push_back("gaussian: " + w);
        for (const auto& w : c.exponential.estimate.warnings) ws.push_back("exponential: " + w);
        out["warnings"] = warnings_json(ws);
        if (!a.out.json_output) {
            out["gaussian_fit"] = c.gaussian.brief_report();
            out["exponential_fit"] = c.exponential.brief_report();
        }
    } else {
        o.correlation = a.correlation == CorrelationChoice::Gaussian ? Correlation::Gaussian
                                                                     : Correlation::Exponential;
        const FitResult r = fit_roughness(ms, o);
        const json jr = fit_json(r, a.residuals);
        for (const auto& [k, v] : jr.items()) out[k] = v;
    }
    emit(a.out, out);
}

}  // namespace

void register_estimate(CLI::App& app) {
    CLI::App* est = app.add_subcommand(
        "estimate",
        "Estimate roughness from brightness (paper section 4): specular, correlation-length, "
        "slope, fit. Angles in degrees, lengths in um.");
    est->require_subcommand(1);

    // --- specular -----------------------------------------------------------------------------
    {
        auto args = std::make_shared<SpecularArgs>();
        SpecularArgs& a = *args;
        CLI::App* cmd = est->add_subcommand(
            "specular",
            "RMS height sigma from the specular reflectance R_spec = 1 - E_dif/E_tot at "
            "theta_i = theta_s = theta (Eq. 12-13)");
        const std::string g = "Specular measurement (give --r-spec, or --e-tot and --e-dif)";
        a.o_r_spec = add_positive_option(*cmd, "--r-spec", a.r_spec,
                                         "Relative specular brightness R_spec in (0, R0)")
                         ->group(g);
        a.o_e_tot = add_positive_option(*cmd, "--e-tot", a.e_tot,
                                        "Peak brightness at the centre of the highlight (> 0)")
                        ->group(g);
        a.o_e_dif = add_positive_option(*cmd, "--e-dif", a.e_dif,
                                        "Diffuse brightness beside the highlight (> 0, < E_tot)")
                        ->group(g);
        a.o_theta = add_angle_option(*cmd, "--theta", a.theta_deg,
                                     "Specular angle theta = theta_i = theta_s, degrees [0,90)");
        add_wavelength_option(*cmd, a.wavelength_um);
        add_positive_option(*cmd, "--r0", a.r0,
                            "Specular reflectance R0 of the smooth surface, on the scale of "
                            "R_spec (default 1)");
        a.o_noise = add_non_negative_option(
            *cmd, "--noise", a.noise,
            "Relative 1-sigma noise of each brightness value (e.g. 0.01): adds *_stderr");
        add_output_options(*cmd, a.out);
        cmd->callback([args]() { run_specular(*args); });
    }

    // --- correlation-length -------------------------------------------------------------------
    {
        auto args = std::make_shared<CorrelationLengthArgs>();
        CorrelationLengthArgs& a = *args;
        CLI::App* cmd = est->add_subcommand(
            "correlation-length",
            "Correlation length T of a slightly rough surface from two diffuse brightness values "
            "with sigma known (Eq. 14-15; any geometry via the numeric solver)");
        a.o_sigma =
            add_positive_option(*cmd, "--sigma", a.sigma_um, "RMS height sigma (um, > 0)", "um");
        a.o_sigma_stderr =
            add_non_negative_option(*cmd, "--sigma-stderr", a.sigma_stderr_um,
                                    "Standard error of sigma (um), propagated", "um");
        add_ratio_options(*cmd, a.ratio);
        add_pair_options(*cmd, a.pair);
        add_wavelength_option(*cmd, a.wavelength_um);
        add_factor_option(*cmd, a.factor);
        add_enum_option(*cmd, "--correlation", a.correlation, parse_correlation,
                        "gaussian (default; Eq. 15) or exponential (numeric)");
        add_enum_option(*cmd, "--regime", a.regime, parse_regime,
                        "slightly_rough (default, Eq. 3), series or auto (exact series)");
        add_pair_radiometry_option(*cmd, a.radiometry);
        a.o_noise = add_noise_option(*cmd, a.noise);
        add_output_options(*cmd, a.out);
        cmd->callback([args]() { run_correlation_length(*args); });
    }

    // --- slope --------------------------------------------------------------------------------
    {
        auto args = std::make_shared<SlopeArgs>();
        SlopeArgs& a = *args;
        CLI::App* cmd = est->add_subcommand(
            "slope",
            "Slope ratio sigma/T of a very rough surface from a brightness ratio E1/E2 "
            "(Eq. 16-19; any geometry via the numeric solver)");
        add_ratio_options(*cmd, a.ratio);
        add_pair_options(*cmd, a.pair);
        add_factor_option(*cmd, a.factor);
        add_enum_option(*cmd, "--correlation", a.correlation, parse_correlation_choice,
                        "both (default), gaussian (Eq. 17) or exponential (Eq. 19)");
        add_pair_radiometry_option(*cmd, a.radiometry);
        a.o_noise = add_noise_option(*cmd, a.noise);
        a.o_sigma = add_positive_option(*cmd, "--sigma", a.sigma_um,
                                        "RMS height if known (um): adds T, g and the class", "um");
        add_positive_option(*cmd, "--wavelength", a.wavelength_um,
                            "Wavelength for g with --sigma (um; default 0.555)", "um");
        add_output_options(*cmd, a.out);
        cmd->callback([args]() { run_slope(*args); });
    }

    // --- fit ----------------------------------------------------------------------------------
    {
        auto args = std::make_shared<FitArgs>();
        FitArgs& a = *args;
        CLI::App* cmd = est->add_subcommand(
            "fit",
            "Least-squares fit of sigma/T (very rough) or sigma and T (slightly rough) and the "
            "gain K to N >= 3 brightness values at arbitrary geometries (Ceres)");
        a.o_measurements = cmd->add_option(
            "--measurements", a.measurements_path,
            "CSV with header theta_i,phi_i,theta_s,phi_s,brightness[,weight] (degrees; "
            "phi_s = phi_i + 180 is the specular plane)");
        add_enum_option(*cmd, "--model", a.model, parse_fit_model,
                        "very_rough (default: sigma/T) or slightly_rough (sigma and T)");
        add_enum_option(*cmd, "--correlation", a.correlation, parse_correlation_choice,
                        "both (default: fit both, compare by AIC), gaussian or exponential");
        add_factor_option(*cmd, a.factor);
        add_enum_option(*cmd, "--radiometry", a.radiometry, parse_radiometry,
                        "radiance (default) or intensity");
        a.o_regime = add_enum_option(*cmd, "--regime", a.regime, parse_regime,
                                     "slightly-rough model: slightly_rough (default, Eq. 3), "
                                     "series or auto");
        a.o_wavelength = add_positive_option(*cmd, "--wavelength", a.wavelength_um,
                                             "slightly-rough model: wavelength (um; 0.555)", "um");
        add_enum_option(*cmd, "--residual", a.residual, parse_residual_type,
                        "relative (default), absolute or log");
        add_enum_option(*cmd, "--loss", a.loss, parse_loss_type,
                        "Robust loss: none (default), huber, cauchy, soft_l_one");
        add_positive_option(*cmd, "--loss-scale", a.loss_scale,
                            "Residual size where the robust loss bends (default 0.05)");
        a.o_initial_sigma_over_T =
            add_positive_option(*cmd, "--initial-sigma-over-T", a.initial_sigma_over_T,
                                "Starting sigma/T (default: automatic)");
        a.o_initial_sigma = add_positive_option(*cmd, "--initial-sigma", a.initial_sigma_um,
                                                "Starting sigma (um; default automatic)", "um");
        a.o_initial_T = add_positive_option(*cmd, "--initial-T", a.initial_T_um,
                                            "Starting T (um; default automatic)", "um");
        cmd->add_option("--max-iterations", a.max_iterations, "Solver iterations (default 200)")
            ->check(CLI::Range(1, 100000));
        cmd->add_flag("--residuals", a.residuals, "Include the residuals in the JSON output");
        add_output_options(*cmd, a.out);
        cmd->callback([args]() { run_fit(*args); });
    }
}

}  // namespace roughscope::cli
