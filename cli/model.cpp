// `roughscope model`: evaluates a reflectance model (the B–K theory of §3 or a comparison model
// of §5) at one geometry given on the command line, or at every row of a CSV file.
//
// Angles are degrees here and radians in the library; lengths are µm. See docs/cli.md. Numbers
// go into JSON unrounded (round-trip precision; serialize/json.hpp); text and CSV show
// kPrintDigits significant digits.
#include "roughscope/serialize/model.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "commands.hpp"
#include "common.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/factors.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/scattering/reflectance_models.hpp"
#include "roughscope/scattering/validity.hpp"
#include "roughscope/serialize/json.hpp"
#include "roughscope/version.hpp"

namespace roughscope::cli {
namespace {

enum class ModelKind { BK, Lambert, OrenNayar, OrenNayarQualitative, Lafortune };

// --model names, in the library's enum-name scheme (roughscope/core/names.hpp): parsed
// case-insensitively with '-' equal to '_'.
constexpr std::array<NameEntry<ModelKind>, 5> kModelNames{{
    {"bk", ModelKind::BK},
    {"lambert", ModelKind::Lambert},
    {"oren_nayar", ModelKind::OrenNayar},
    {"oren_nayar_qualitative", ModelKind::OrenNayarQualitative},
    {"lafortune", ModelKind::Lafortune},
}};

ModelKind parse_model(std::string_view name) { return parse_name(kModelNames, "model", name); }

// The name printed in the output ("oren-nayar", the spelling of the command line's help).
std::string model_name(ModelKind m) {
    std::string name(name_of(kModelNames, m));
    std::replace(name.begin(), name.end(), '_', '-');
    return name;
}

// Everything the command line can set. Owned by the subcommand's callback (shared_ptr).
struct Args {
    // geometry
    double theta_i_deg = 0.0, theta_s_deg = 0.0, phi_s_deg = 0.0;
    double retro_deg = 0.0, specular_deg = 0.0, normal_view_deg = 0.0;
    std::string normal_text = "0,0,1", light_text, view_text, curet_frame_text;
    std::string csv_path;
    // model
    ModelKind model = ModelKind::BK;
    double sigma_um = 0.0, T_um = 0.0, sigma_over_T = 0.0;
    Correlation correlation = Correlation::Gaussian;
    GeometricFactor factor = GeometricFactor::VernoldHarvey;
    Regime regime = Regime::Auto;
    Radiometry radiometry = Radiometry::Radiance;
    double wavelength_um = 0.555, patch_x_um = 500.0, patch_y_um = 500.0;
    double on_sigma_rad = 0.0, albedo = 1.0;
    double lafortune_n = 1.0, rho_d = 0.0;
    std::vector<std::string> lobe_texts;
    // output
    bool json_output = false;
    std::string output_path;

    // option handles, to know what was given
    CLI::Option *o_theta_i{}, *o_theta_s{}, *o_phi_s{}, *o_retro{}, *o_specular{}, *o_normal_view{},
        *o_normal{}, *o_light{}, *o_view{}, *o_curet{}, *o_csv{};
    CLI::Option *o_sigma{}, *o_T{}, *o_sigma_over_T{}, *o_correlation{}, *o_factor{}, *o_regime{},
        *o_radiometry{}, *o_wavelength{}, *o_patch_x{}, *o_patch_y{};
    CLI::Option *o_on_sigma{}, *o_albedo{}, *o_n{}, *o_lobe{}, *o_rho_d{}, *o_output{};
};

// One evaluation point: the geometry (absent when L or V is below the horizon) and the angles
// to report.
struct Point {
    std::optional<Geometry> geom;
    double theta_i_deg = 0.0;
    double theta_s_deg = 0.0;
    std::optional<double> phi_s_deg;
    // The degrees typed for θi, θs, φs when the geometry was made from them (CSV rows): the echo
    // of an angle typed with few digits is then that angle (serialize::degrees).
    std::optional<std::array<double, 3>> typed_deg;
};

Point point_from(const Geometry& g) {
    return {g, rad_to_deg(g.theta_i_rad), rad_to_deg(g.theta_s_rad), rad_to_deg(g.phi_s_rad),
            std::nullopt};
}

// Roughness of the B–K model for one evaluation: σ and T (absolute scale) or σ/T alone
// (very-rough shapes, constants dropped).
struct Roughness {
    std::optional<double> sigma_um, T_um, sigma_over_T;
};

Eigen::Vector3d parse_direction(const std::string& text, const std::string& flag) {
    const auto v = parse_number_list(text, 3, flag);
    Eigen::Vector3d d(v[0], v[1], v[2]);
    const double norm = d.norm();
    if (!(norm > 1e-12) || !std::isfinite(norm)) {
        throw roughscope::InvalidArgument(flag + ": the vector '" + text +
                                          "' has zero length; give a non-zero direction x,y,z");
    }
    return d / norm;
}

// Angle between two unit vectors in degrees (clamped, never NaN).
double angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return rad_to_deg(std::acos(std::clamp(a.dot(b), -1.0, 1.0)));
}

// Checks a polar angle given in degrees: 0 <= θ < 90; `what` names the flag or column.
void check_polar_deg(double deg, const std::string& what) {
    if (!(deg >= 0.0 && deg < 90.0)) {
        throw roughscope::InvalidArgument(what + ": " + format_result(deg, what) +
                                          " is outside the valid range [0, 90) degrees");
    }
}

// The single geometry given on the command line (not --csv).
Point point_from_flags(const Args& a) {
    if (given(a.o_retro)) return point_from(retro_geometry(deg_to_rad(a.retro_deg)));
    if (given(a.o_specular)) return point_from(specular_geometry(deg_to_rad(a.specular_deg)));
    if (given(a.o_normal_view)) {
        return point_from(normal_view_geometry(deg_to_rad(a.normal_view_deg)));
    }
    if (given(a.o_curet)) {
        const auto v = parse_number_list(a.curet_frame_text, 4, "--curet-frame");
        check_polar_deg(v[0], "--curet-frame theta_i");
        check_polar_deg(v[2], "--curet-frame theta_v");
        return point_from(geometry_from_two_azimuths(deg_to_rad(v[0]), deg_to_rad(v[1]),
                                                     deg_to_rad(v[2]), deg_to_rad(v[3])));
    }
    if (given(a.o_light) || given(a.o_view) || given(a.o_normal)) {
        if (!given(a.o_light) || !given(a.o_view)) {
            throw UsageError(
                "--normal/--light/--view: give both --light x,y,z and --view x,y,z "
                "(--normal defaults to 0,0,1)");
        }
        const Eigen::Vector3d N = parse_direction(a.normal_text, "--normal");
        const Eigen::Vector3d L = parse_direction(a.light_text, "--light");
        const Eigen::Vector3d V = parse_direction(a.view_text, "--view");
        const auto geom = geometry_from_vectors(N, L, V);
        if (geom) return point_from(*geom);
        return {std::nullopt, angle_deg(N, L), angle_deg(N, V), std::nullopt, std::nullopt};
    }
    // --theta-i --theta-s --phi-s
    if (!given(a.o_theta_i) || !given(a.o_theta_s) || !given(a.o_phi_s)) {
        std::string missing;
        for (auto [o, name] : {std::pair{a.o_theta_i, "--theta-i"},
                               {a.o_theta_s, "--theta-s"},
                               {a.o_phi_s, "--phi-s"}}) {
            if (!given(o)) missing += std::string(missing.empty() ? "" : ", ") + name;
        }
        throw UsageError("missing " + missing +
                         ": give all of --theta-i DEG --theta-s DEG --phi-s DEG (phi_s = 0 is the "
                         "specular plane, 180 retro-reflection)");
    }
    return point_from(make_geometry(deg_to_rad(a.theta_i_deg), deg_to_rad(a.theta_s_deg),
                                    deg_to_rad(a.phi_s_deg)));
}

// Exactly one source of geometry must be given.
void check_geometry_source(const Args& a) {
    std::vector<std::string> sources;
    if (given(a.o_theta_i) || given(a.o_theta_s) || given(a.o_phi_s)) {
        sources.push_back("--theta-i/--theta-s/--phi-s");
    }
    if (given(a.o_retro)) sources.push_back("--retro");
    if (given(a.o_specular)) sources.push_back("--specular");
    if (given(a.o_normal_view)) sources.push_back("--normal-view");
    if (given(a.o_normal) || given(a.o_light) || given(a.o_view)) {
        sources.push_back("--normal/--light/--view");
    }
    if (given(a.o_curet)) sources.push_back("--curet-frame");
    if (given(a.o_csv)) sources.push_back("--csv");
    if (sources.empty()) {
        throw UsageError(
            "no geometry given: use --theta-i/--theta-s/--phi-s, --retro, "
            "--specular, --normal-view, --light/--view, --curet-frame or --csv");
    }
    if (sources.size() > 1) {
        std::string list;
        for (const auto& s : sources) list += (list.empty() ? "" : ", ") + s;
        throw UsageError("give exactly one geometry; got " + list);
    }
}

// Options that belong to one model only are rejected with the others.
void check_model_options(const Args& a) {
    const auto reject = [&](const CLI::Option* o, const char* flag, const char* models) {
        if (given(o)) {
            throw UsageError(std::string(flag) + " applies to --model " + models +
                             " only (model is " + model_name(a.model) + ")");
        }
    };
    if (a.model != ModelKind::BK) {
        for (auto [o, f] : {std::pair{a.o_sigma, "--sigma"},
                            {a.o_T, "--T"},
                            {a.o_sigma_over_T, "--sigma-over-T"},
                            {a.o_correlation, "--correlation"},
                            {a.o_factor, "--factor"},
                            {a.o_regime, "--regime"},
                            {a.o_radiometry, "--radiometry"},
                            {a.o_wavelength, "--wavelength"},
                            {a.o_patch_x, "--patch-x"},
                            {a.o_patch_y, "--patch-y"}}) {
            reject(o, f, "bk");
        }
    }
    if (a.model != ModelKind::OrenNayar && a.model != ModelKind::OrenNayarQualitative) {
        reject(a.o_on_sigma, "--on-sigma", "oren-nayar or oren-nayar-qualitative");
        reject(a.o_albedo, "--albedo", "oren-nayar or oren-nayar-qualitative");
    }
    if (a.model != ModelKind::Lafortune) {
        reject(a.o_n, "--n", "lafortune");
        reject(a.o_lobe, "--lobe", "lafortune");
        reject(a.o_rho_d, "--rho-d", "lafortune");
    }
    if (a.model == ModelKind::BK) {
        if (given(a.o_sigma_over_T) && (given(a.o_sigma) || given(a.o_T))) {
            throw UsageError(
                "--sigma-over-T excludes --sigma/--T: give either --sigma UM --T UM "
                "or --sigma-over-T M");
        }
        if (given(a.o_sigma) != given(a.o_T) && !given(a.o_csv)) {
            throw UsageError(std::string("missing ") + (given(a.o_sigma) ? "--T" : "--sigma") +
                             ": the B-K model needs both --sigma UM and --T UM (or "
                             "--sigma-over-T M for the very-rough forms)");
        }
        if (!given(a.o_sigma) && !given(a.o_T) && !given(a.o_sigma_over_T) && !given(a.o_csv)) {
            throw UsageError(
                "missing roughness: the B-K model needs --sigma UM and --T UM "
                "(> 0), or --sigma-over-T M (> 0) for the very-rough forms");
        }
    }
    if (a.model == ModelKind::OrenNayar || a.model == ModelKind::OrenNayarQualitative) {
        if (!given(a.o_on_sigma)) {
            throw UsageError(
                "missing --on-sigma: the Oren-Nayar model needs the facet slope "
                "deviation in radians (>= 0)");
        }
    }
    if (a.model == ModelKind::Lafortune && !given(a.o_n) && !given(a.o_lobe)) {
        throw UsageError(
            "missing --n: the Lafortune model needs --n N (> 0, diffuse lobe "
            "Cz = 1) and/or --lobe Cx,Cy,Cz,n,rho");
    }
}

std::vector<LafortuneLobe> lafortune_lobes(const Args& a) {
    std::vector<LafortuneLobe> lobes;
    if (given(a.o_n)) lobes.push_back({0.0, 0.0, 1.0, a.lafortune_n, 1.0});
    for (const auto& text : a.lobe_texts) {
        const auto v = parse_number_list(text, 5, "--lobe Cx,Cy,Cz,n,rho");
        if (!(v[3] > 0.0)) {
            throw roughscope::InvalidArgument("--lobe: exponent n = " + format_result(v[3]) +
                                              " must be > 0");
        }
        if (!(v[4] >= 0.0)) {
            throw roughscope::InvalidArgument("--lobe: rho = " + format_result(v[4]) +
                                              " must be >= 0");
        }
        lobes.push_back({v[0], v[1], v[2], v[3], v[4]});
    }
    return lobes;
}

using serialize::ModelRecord;

// B–K model (Eq. 1–5, §3.2–3.3) at one point: adds its keys to `out`, returns the brightness.
double evaluate_bk(const Args& a, const Point& p, const Roughness& r, ModelRecord& out) {
    const bool absolute = r.sigma_um.has_value();
    std::optional<double> coherent, diffuse, total, g;
    std::optional<std::string> regime, roughness_class;
    double brightness = 0.0;
    std::optional<double> m =
        absolute ? std::optional<double>(*r.sigma_um / *r.T_um) : r.sigma_over_T;

    if (absolute) {
        const Surface surface{*r.sigma_um, *r.T_um, a.correlation};
        ModelOptions options;
        options.factor = a.factor;
        options.radiometry = a.radiometry;
        options.regime = a.regime;
        options.wavelength_um = a.wavelength_um;
        options.patch_x_um = a.patch_x_um;
        options.patch_y_um = a.patch_y_um;
        if (p.geom) {
            const ScatteredPower power = mean_scattered_power(*p.geom, surface, options);
            brightness = serialize::number(power.brightness).get<double>();
            serialize::set_power(out, power);
        } else {
            coherent = diffuse = total = 0.0;  // light or viewer below the horizon
        }
    } else {
        // σ/T alone: only the very-rough closed forms (Eq. 4, Eq. 5) are defined.
        const bool series_limit_ok =
            a.regime == Regime::VeryRoughSeriesLimit && a.correlation == Correlation::Gaussian;
        if (a.regime != Regime::Auto && a.regime != Regime::VeryRough && !series_limit_ok) {
            throw UsageError(
                "--regime " + std::string(to_string(a.regime)) + " with " +
                std::string(to_string(a.correlation)) +
                " correlation needs --sigma and --T; with --sigma-over-T only --regime auto or "
                "very_rough (Eq. 4/5; for gaussian also very_rough_series_limit) are possible");
        }
        regime = std::string(
            to_string(series_limit_ok ? Regime::VeryRoughSeriesLimit : Regime::VeryRough));
        if (p.geom) {
            brightness = very_rough_brightness(*p.geom, *m, a.correlation, a.factor, a.radiometry);
            // D itself is the shape of Eq. 4 / Eq. 5 before the radiometric factor of §3.3,
            // i.e. the brightness under the radiance interpretation (factor 1).
            diffuse =
                very_rough_brightness(*p.geom, *m, a.correlation, a.factor, Radiometry::Radiance);
        } else {
            diffuse = 0.0;
        }
    }

    if (!out.contains("coherent")) {  // not from the serialized ScatteredPower
        out["coherent"] = ModelRecord::NumberOrNull{coherent};
        out["diffuse"] = ModelRecord::NumberOrNull{diffuse};
        out["total"] = ModelRecord::NumberOrNull{total};
        out["g"] = ModelRecord::NumberOrNull{g};
        out["regime"] = regime ? json(*regime) : json(nullptr);
        out["roughness_class"] = roughness_class ? json(*roughness_class) : json(nullptr);
        out["method"] = to_string(DiffuseMethod::ClosedForm);
        out["relative_error_bound"] = ModelRecord::NumberOrNull{0.0};
    }
    out["scale"] = absolute ? "absolute" : "relative";
    out["correlation"] = to_string(a.correlation);
    out["factor"] = to_string(a.factor);
    out["radiometry"] = to_string(a.radiometry);
    out["wavelength_um"] = ModelRecord::NumberOrNull{a.wavelength_um};
    out["patch_x_um"] = ModelRecord::NumberOrNull{a.patch_x_um};
    out["patch_y_um"] = ModelRecord::NumberOrNull{a.patch_y_um};
    out["sigma_um"] = ModelRecord::NumberOrNull{r.sigma_um};
    out["T_um"] = ModelRecord::NumberOrNull{r.T_um};
    out["sigma_over_T"] = ModelRecord::NumberOrNull{m};
    // §3.5: Caron's angle of RMS slope (Gaussian height distribution and correlation only).
    std::optional<double> theta_K_deg;
    if (a.correlation == Correlation::Gaussian && m) {
        theta_K_deg = rad_to_deg(caron_theta_K_rad(*m));
    }
    out["caron_theta_K_deg"] = ModelRecord::NumberOrNull{theta_K_deg};
    return brightness;
}

// Evaluates the chosen model at one point into `out` (keys in output order).
void evaluate(const Args& a, const Point& p, const Roughness& r, ModelRecord& out) {
    out.clear();
    out["model"] = model_name(a.model);
    // Angles of a geometry echoed as the shortest degrees that map to the same radians.
    const auto echo = [&](double rad, std::size_t k) {
        return p.typed_deg ? serialize::degrees(rad, (*p.typed_deg)[k]) : serialize::degrees(rad);
    };
    out["theta_i_deg"] = p.geom ? echo(p.geom->theta_i_rad, 0) : serialize::number(p.theta_i_deg);
    out["theta_s_deg"] = p.geom ? echo(p.geom->theta_s_rad, 1) : serialize::number(p.theta_s_deg);
    out["phi_s_deg"] = p.geom ? echo(p.geom->phi_s_rad, 2) : json(nullptr);
    out["visible"] = p.geom.has_value();
    out["brightness"] = nullptr;  // placeholder keeps the key order

    double brightness = 0.0;
    switch (a.model) {
        case ModelKind::BK:
            brightness = evaluate_bk(a, p, r, out);
            break;
        case ModelKind::Lambert:
            if (p.geom) brightness = lambert_brightness(p.geom->theta_i_rad);
            break;
        case ModelKind::OrenNayar:
        case ModelKind::OrenNayarQualitative: {
            const OrenNayarParams params{a.on_sigma_rad, a.albedo};
            if (p.geom) {
                brightness = a.model == ModelKind::OrenNayar
                                 ? oren_nayar_radiance(*p.geom, params)
                                 : oren_nayar_qualitative_radiance(*p.geom, params);
            }
            out["on_sigma_rad"] = ModelRecord::NumberOrNull{a.on_sigma_rad};
            out["albedo"] = ModelRecord::NumberOrNull{a.albedo};
            break;
        }
        case ModelKind::Lafortune: {
            const auto lobes = lafortune_lobes(a);
            if (p.geom) {
                // Brightness = BRDF × cos θi (unit irradiance along L).
                brightness =
                    (lobes.size() == 1 && a.lobe_texts.empty() && a.rho_d == 0.0)
                        ? lafortune_diffuse_brightness(*p.geom, a.lafortune_n)
                        : lafortune_brdf(*p.geom, lobes, a.rho_d) * std::cos(p.geom->theta_i_rad);
            }
            out["rho_d"] = ModelRecord::NumberOrNull{a.rho_d};
            out["lobes"] = serialize::to_json(lobes);
            break;
        }
    }
    out["brightness"] = ModelRecord::NumberOrNull{brightness};
}

// ---------------------------------------------------------------------------------------------
// Output formatting

std::string human_text(const json& record) {
    std::vector<std::pair<std::string, std::string>> items;
    for (const auto& [key, value] : record.items()) {
        items.emplace_back(
            key, value.is_null() ? "unknown" : serialize::model_cell_text(value, kPrintDigits));
    }
    std::ostringstream os;
    print_key_values(os, items);
    return os.str();
}

Roughness roughness_from_flags(const Args& a) {
    Roughness r;
    if (given(a.o_sigma)) r.sigma_um = a.sigma_um;
    if (given(a.o_T)) r.T_um = a.T_um;
    if (given(a.o_sigma_over_T)) r.sigma_over_T = a.sigma_over_T;
    return r;
}

// Per-row roughness: row columns override the flags (see docs/cli.md).
template <class Where>
Roughness roughness_for_row(const Args& a, const CsvRow& row, const Where& where_of) {
    Roughness r = roughness_from_flags(a);
    const auto s = row.find("sigma_um");
    const auto t = row.find("T_um");
    const auto m = row.find("sigma_over_T");
    if (m && (s || t)) {
        throw roughscope::DataError(where_of() +
                                    "give either sigma_um,T_um or sigma_over_T on a row, "
                                    "not both");
    }
    if (m) {
        r = Roughness{};
        r.sigma_over_T = *m;
    } else if (s || t) {
        r.sigma_over_T.reset();
        if (s) r.sigma_um = *s;
        if (t) r.T_um = *t;
    }
    if (r.sigma_um.has_value() != r.T_um.has_value()) {
        throw roughscope::DataError(where_of() + "missing " + (r.sigma_um ? "T_um" : "sigma_um") +
                                    ": the B-K model needs both sigma_um and T_um (column or "
                                    "--sigma/--T), or sigma_over_T");
    }
    if (!r.sigma_um && !r.sigma_over_T) {
        throw roughscope::DataError(where_of() +
                                    "no roughness: give --sigma and --T or "
                                    "--sigma-over-T, or columns sigma_um,T_um or "
                                    "sigma_over_T");
    }
    if (r.sigma_over_T && !(*r.sigma_over_T > 0.0)) {
        throw roughscope::DataError(where_of() + "column 'sigma_over_T': " +
                                    format_result(*r.sigma_over_T) + " must be > 0");
    }
    for (auto [v, col] : {std::pair{r.sigma_um, "sigma_um"}, {r.T_um, "T_um"}}) {
        if (v && !(*v > 0.0)) {
            throw roughscope::DataError(where_of() + "column '" + std::string(col) +
                                        "': " + format_result(*v) + " must be > 0 um");
        }
    }
    return r;
}

void run_model(const Args& a) {
    check_geometry_source(a);
    check_model_options(a);
    if (a.model == ModelKind::Lafortune) (void)lafortune_lobes(a);  // validate --lobe early

    const std::optional<std::filesystem::path> output =
        given(a.o_output) ? std::optional<std::filesystem::path>(a.output_path) : std::nullopt;

    if (!given(a.o_csv)) {
        const Point p = point_from_flags(a);
        ModelRecord result;
        evaluate(a, p, roughness_from_flags(a), result);
        const json record = result.to_json();
        std::string text;
        if (a.json_output) {
            text = serialize::dump(serialize::versioned(record));
        } else if (output) {
            text = serialize::model_record_csv(record, kPrintDigits);
        } else {
            text = human_text(record);
        }
        write_output(output, text);
        return;
    }

    // Streamed: one row read, evaluated and written at a time (memory independent of the number
    // of rows). The output is committed only when every row succeeded.
    const std::filesystem::path csv_path(a.csv_path);
    io::CsvReader reader(csv_path, {"theta_i", "theta_s", "phi_s"},
                         {"sigma_um", "T_um", "sigma_over_T"});
    const std::size_t c_ti = *reader.column_index("theta_i");
    const std::size_t c_ts = *reader.column_index("theta_s");
    const std::size_t c_ps = *reader.column_index("phi_s");
    io::OutputFile out = io::open_output(output);
    serialize::ModelRecordWriter writer(out, a.json_output, kPrintDigits);
    ModelRecord record;  // reused row after row
    CsvRow row;
    while (reader.next(row)) {
        const double ti = *row.value(c_ti), ts = *row.value(c_ts), ps = *row.value(c_ps);
        const auto where = [&] {
            std::string w = csv_path.string();
            w.append(":").append(std::to_string(row.line)).append(": ");
            return w;
        };
        try {
            check_polar_deg(ti, "column 'theta_i'");
            check_polar_deg(ts, "column 'theta_s'");
            const Roughness r =
                a.model == ModelKind::BK ? roughness_for_row(a, row, where) : Roughness{};
            Point p = point_from(make_geometry(deg_to_rad(ti), deg_to_rad(ts), deg_to_rad(ps)));
            p.typed_deg = {ti, ts, ps};
            evaluate(a, p, r, record);
            writer.add(record);
        } catch (const UsageError&) {
            throw;  // about the flags, not the row
        } catch (const roughscope::DataError&) {
            throw;
        } catch (const roughscope::InvalidArgument& e) {
            throw roughscope::DataError(where() + e.what());
        }
    }
    if (writer.count() == 0)
        throw roughscope::DataError(reader.source() + ": no data rows after the header");
    writer.finish();
    out.commit();
}

}  // namespace

void register_model(CLI::App& app) {
    auto args = std::make_shared<Args>();
    Args& a = *args;
    CLI::App* cmd = app.add_subcommand(
        "model",
        "Evaluate a reflectance model (B-K theory of the paper, Lambert, Oren-Nayar, Lafortune) "
        "at one geometry or at every row of a CSV file. Angles in degrees, lengths in um.");

    // Geometry (exactly one of the groups).
    const std::string geo = "Geometry (give exactly one)";
    add_angle_option(*cmd, "--theta-i", a.theta_i_deg, "Incidence polar angle, degrees [0,90)")
        ->group(geo);
    add_angle_option(*cmd, "--theta-s", a.theta_s_deg, "Viewing polar angle, degrees [0,90)")
        ->group(geo);
    add_azimuth_option(*cmd, "--phi-s", a.phi_s_deg,
                       "Viewing azimuth, degrees (light at 180; 0 = specular plane, "
                       "180 = retro-reflection)")
        ->group(geo);
    add_angle_option(*cmd, "--retro", a.retro_deg, "Retro-reflection L = V at this angle (deg)")
        ->group(geo);
    add_angle_option(*cmd, "--specular", a.specular_deg,
                     "Specular geometry theta_i = theta_s at this angle, phi_s = 0 (deg)")
        ->group(geo);
    add_angle_option(*cmd, "--normal-view", a.normal_view_deg,
                     "Viewer along the normal (theta_s = 0), light at this angle (deg)")
        ->group(geo);
    cmd->add_option("--normal", a.normal_text, "Surface normal N as x,y,z (default 0,0,1)")
        ->group(geo);
    cmd->add_option("--light", a.light_text,
                    "Light direction L as x,y,z (normalised; below the horizon gives 0)")
        ->group(geo);
    cmd->add_option("--view", a.view_text, "Viewing direction V as x,y,z (normalised)")->group(geo);
    cmd->add_option("--curet-frame", a.curet_frame_text,
                    "Both azimuths given: theta_i,phi_i,theta_v,phi_v in degrees")
        ->group(geo);
    cmd->add_option("--csv", a.csv_path,
                    "CSV with header theta_i,theta_s,phi_s (deg) [,sigma_um,T_um,sigma_over_T]; "
                    "one result per row")
        ->group(geo);

    // Model.
    const std::string mod = "Model";
    add_enum_option(*cmd, "--model", a.model, parse_model,
                    "bk (default), lambert, oren-nayar, oren-nayar-qualitative, lafortune")
        ->group(mod);
    const std::string bk = "B-K model (--model bk)";
    add_positive_option(*cmd, "--sigma", a.sigma_um, "RMS height sigma (um, > 0)", "um")->group(bk);
    add_positive_option(*cmd, "--T", a.T_um, "Correlation length T (um, > 0)", "um")->group(bk);
    add_positive_option(*cmd, "--sigma-over-T", a.sigma_over_T,
                        "Slope ratio sigma/T (> 0) instead of --sigma/--T: very-rough forms "
                        "Eq. 4/5 only, relative scale")
        ->group(bk);
    add_enum_option(*cmd, "--correlation", a.correlation, parse_correlation,
                    "gaussian (default) or exponential")
        ->group(bk);
    add_factor_option(*cmd, a.factor)->group(bk);
    add_enum_option(*cmd, "--regime", a.regime, parse_regime,
                    "auto (default), series, slightly_rough, very_rough, "
                    "very_rough_series_limit ('-' or '_')")
        ->group(bk);
    add_enum_option(*cmd, "--radiometry", a.radiometry, parse_radiometry,
                    "radiance (default, Harvey) or intensity (Ogilvy)")
        ->group(bk);
    add_positive_option(*cmd, "--wavelength", a.wavelength_um,
                        "Wavelength lambda (um, > 0; default 0.555)", "um")
        ->group(bk);
    add_positive_option(*cmd, "--patch-x", a.patch_x_um,
                        "Half-size X of the illuminated patch (um, > 0; default 500)", "um")
        ->group(bk);
    add_positive_option(*cmd, "--patch-y", a.patch_y_um,
                        "Half-size Y of the illuminated patch (um, > 0; default 500)", "um")
        ->group(bk);
    const std::string on = "Oren-Nayar (--model oren-nayar[-qualitative])";
    add_non_negative_option(*cmd, "--on-sigma", a.on_sigma_rad,
                            "Facet slope standard deviation (radians, >= 0)", "rad")
        ->group(on);
    add_range_option(*cmd, "--albedo", a.albedo, 0.0, 1.0, "Facet albedo in [0,1] (default 1)")
        ->group(on);
    const std::string laf = "Lafortune (--model lafortune)";
    add_positive_option(*cmd, "--n", a.lafortune_n,
                        "Exponent of the diffuse lobe Cx = Cy = 0, Cz = 1 (> 0)")
        ->group(laf);
    cmd->add_option("--lobe", a.lobe_texts,
                    "Extra lobe Cx,Cy,Cz,n,rho (repeatable; n > 0, rho >= 0)")
        ->allow_extra_args(false)
        ->group(laf);
    add_non_negative_option(*cmd, "--rho-d", a.rho_d, "Lambertian term rho_d/pi (>= 0; default 0)")
        ->group(laf);

    // Output.
    const std::string outg = "Output";
    cmd->add_flag("--json", a.json_output, "Print JSON: one object, or an array with --csv")
        ->group(outg);
    cmd->add_option("--output", a.output_path,
                    "Write the results to FILE (CSV, or JSON with --json) atomically")
        ->group(outg);

    // Handles for "was it given?".
    a.o_theta_i = cmd->get_option("--theta-i");
    a.o_theta_s = cmd->get_option("--theta-s");
    a.o_phi_s = cmd->get_option("--phi-s");
    a.o_retro = cmd->get_option("--retro");
    a.o_specular = cmd->get_option("--specular");
    a.o_normal_view = cmd->get_option("--normal-view");
    a.o_normal = cmd->get_option("--normal");
    a.o_light = cmd->get_option("--light");
    a.o_view = cmd->get_option("--view");
    a.o_curet = cmd->get_option("--curet-frame");
    a.o_csv = cmd->get_option("--csv");
    a.o_sigma = cmd->get_option("--sigma");
    a.o_T = cmd->get_option("--T");
    a.o_sigma_over_T = cmd->get_option("--sigma-over-T");
    a.o_correlation = cmd->get_option("--correlation");
    a.o_factor = cmd->get_option("--factor");
    a.o_regime = cmd->get_option("--regime");
    a.o_radiometry = cmd->get_option("--radiometry");
    a.o_wavelength = cmd->get_option("--wavelength");
    a.o_patch_x = cmd->get_option("--patch-x");
    a.o_patch_y = cmd->get_option("--patch-y");
    a.o_on_sigma = cmd->get_option("--on-sigma");
    a.o_albedo = cmd->get_option("--albedo");
    a.o_n = cmd->get_option("--n");
    a.o_lobe = cmd->get_option("--lobe");
    a.o_rho_d = cmd->get_option("--rho-d");
    a.o_output = cmd->get_option("--output");

    cmd->callback([args]() { run_model(*args); });
}

}  // namespace roughscope::cli
