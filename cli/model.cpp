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

// A result record: its keys (string literals) in output order and their values. Unlike a JSON
// object it allocates no key, and one record is reused row after row (clear() keeps the slots and
// their strings' storage); to_json() gives the object, and RecordWriter formats the record
// directly with the bytes the object's dump would give.
class Record {
  public:
    // A number to record: null when unknown or not finite, as serialize::number gives it.
    struct NumberOrNull {
        std::optional<double> value;
    };
    // A JSON value: null, a boolean, a number, a string, or (Nested) any other JSON value.
    struct Value {
        enum class Kind { Null, Boolean, Number, Text, Nested };
        Kind kind = Kind::Null;
        bool boolean = false;
        double number = 0.0;
        std::string text;
        json nested;
        // The writer's last formatted number and its text: a record is reused row after row and
        // most of its numbers (the options echoed) repeat, so each is formatted once.
        enum class Style : std::uint8_t { None, Csv };
        mutable Style formatted_style = Style::None;
        mutable std::uint8_t formatted_size = 0;
        mutable std::uint64_t formatted_bits = 0;  // of the number formatted
        mutable std::array<char, 64> formatted{};

        // The text of `number` in `style`, by `format(buffer) -> end` when not the cached one.
        template <class Format>
        std::string_view number_text(Style style, Format&& format) const {
            const auto bits = std::bit_cast<std::uint64_t>(number);
            if (formatted_style != style || formatted_bits != bits) {
                const char* end = format(formatted.data());
                formatted_size = static_cast<std::uint8_t>(end - formatted.data());
                formatted_bits = bits;
                formatted_style = style;
            }
            return {formatted.data(), formatted_size};
        }

        Value& operator=(std::nullptr_t) {
            kind = Kind::Null;
            return *this;
        }
        Value& operator=(bool b) {
            kind = Kind::Boolean;
            boolean = b;
            return *this;
        }
        Value& operator=(std::string_view t) {
            kind = Kind::Text;
            text.assign(t);
            return *this;
        }
        Value& operator=(const char* t) { return *this = std::string_view(t); }
        // Numbers come as NumberOrNull (serialize::number's rule: finite, else null): a bare
        // double would otherwise convert to bool.
        Value& operator=(NumberOrNull n) {
            if (n.value && std::isfinite(*n.value)) {
                kind = Kind::Number;
                number = *n.value;
            } else {
                kind = Kind::Null;
            }
            return *this;
        }
        Value& operator=(double) = delete;
        Value& operator=(int) = delete;
        Value& operator=(const std::string& t) { return *this = std::string_view(t); }
        Value& operator=(const json& j) {
            if (j.is_null()) return *this = nullptr;
            if (j.is_boolean()) return *this = j.get<bool>();
            if (j.is_string()) return *this = std::string_view(j.get_ref<const std::string&>());
            if (j.is_number_float()) {
                kind = Kind::Number;
                number = j.get<double>();
                return *this;
            }
            kind = Kind::Nested;
            nested = j;
            return *this;
        }
        json to_json() const {
            switch (kind) {
                case Kind::Null:
                    return nullptr;
                case Kind::Boolean:
                    return boolean;
                case Kind::Number:
                    return number;
                case Kind::Text:
                    return text;
                case Kind::Nested:
                    break;
            }
            return nested;
        }
    };
    struct Item {
        std::string_view key;
        Value value;
    };

    Record() { items_.reserve(32); }  // every key of a record without regrowing
    void clear() {
        previous_size_ = size_;
        size_ = 0;
        same_prefix_ = true;
    }
    Value& operator[](std::string_view key) {
        // Row after row the keys come in the same order: while this record's keys so far are the
        // previous record's, a key that was new at this position then (it is not among them) is
        // new now, found without a search. Keys are literals, compared by address first.
        if (same_prefix_ && size_ < previous_size_) {
            const std::string_view slot = items_[size_].key;
            if (slot.data() == key.data() && slot.size() == key.size()) {
                Item& item = items_[size_++];
                item.value = nullptr;
                return item.value;
            }
        }
        for (std::size_t k = 0; k < size_; ++k)
            if (items_[k].key == key) return items_[k].value;
        same_prefix_ = false;
        if (size_ == items_.size()) items_.emplace_back();
        Item& item = items_[size_++];
        item.key = key;
        item.value = nullptr;
        return item.value;
    }
    bool contains(std::string_view key) const {
        return std::any_of(items_.begin(), items_.begin() + static_cast<std::ptrdiff_t>(size_),
                           [key](const Item& item) { return item.key == key; });
    }
    std::span<const Item> items() const { return {items_.data(), size_}; }
    json to_json() const {
        json out = json::object();
        for (const Item& item : items()) out[std::string(item.key)] = item.value.to_json();
        return out;
    }

  private:
    std::vector<Item> items_;
    std::size_t size_ = 0;
    std::size_t previous_size_ = 0;  // the keys of the record before clear()
    bool same_prefix_ = false;       // items_[0, size_) are that record's first keys
};

// B–K model (Eq. 1–5, §3.2–3.3) at one point: adds its keys to `out`, returns the brightness.
double evaluate_bk(const Args& a, const Point& p, const Roughness& r, Record& out) {
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
            // The keys of serialize::to_json(ScatteredPower), set directly (once per CSV row).
            const ScatteredPower power = mean_scattered_power(*p.geom, surface, options);
            brightness = serialize::number(power.brightness).get<double>();
            out["coherent"] = Record::NumberOrNull{power.coherent};
            out["diffuse"] = Record::NumberOrNull{power.diffuse};
            out["total"] = Record::NumberOrNull{power.total};
            out["g"] = Record::NumberOrNull{power.g};
            out["regime"] = to_string(power.regime);
            out["roughness_class"] = to_string(power.roughness_class);
            out["method"] = to_string(power.method);
            out["relative_error_bound"] = Record::NumberOrNull{power.relative_error_bound};
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
        out["coherent"] = Record::NumberOrNull{coherent};
        out["diffuse"] = Record::NumberOrNull{diffuse};
        out["total"] = Record::NumberOrNull{total};
        out["g"] = Record::NumberOrNull{g};
        out["regime"] = regime ? json(*regime) : json(nullptr);
        out["roughness_class"] = roughness_class ? json(*roughness_class) : json(nullptr);
        out["method"] = to_string(DiffuseMethod::ClosedForm);
        out["relative_error_bound"] = Record::NumberOrNull{0.0};
    }
    out["scale"] = absolute ? "absolute" : "relative";
    out["correlation"] = to_string(a.correlation);
    out["factor"] = to_string(a.factor);
    out["radiometry"] = to_string(a.radiometry);
    out["wavelength_um"] = Record::NumberOrNull{a.wavelength_um};
    out["patch_x_um"] = Record::NumberOrNull{a.patch_x_um};
    out["patch_y_um"] = Record::NumberOrNull{a.patch_y_um};
    out["sigma_um"] = Record::NumberOrNull{r.sigma_um};
    out["T_um"] = Record::NumberOrNull{r.T_um};
    out["sigma_over_T"] = Record::NumberOrNull{m};
    // §3.5: Caron's angle of RMS slope (Gaussian height distribution and correlation only).
    std::optional<double> theta_K_deg;
    if (a.correlation == Correlation::Gaussian && m) {
        theta_K_deg = rad_to_deg(caron_theta_K_rad(*m));
    }
    out["caron_theta_K_deg"] = Record::NumberOrNull{theta_K_deg};
    return brightness;
}

// Evaluates the chosen model at one point into `out` (keys in output order).
void evaluate(const Args& a, const Point& p, const Roughness& r, Record& out) {
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
            out["on_sigma_rad"] = Record::NumberOrNull{a.on_sigma_rad};
            out["albedo"] = Record::NumberOrNull{a.albedo};
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
            json lobes_json = json::array();
            for (const auto& l : lobes) {
                lobes_json.push_back({{"Cx", serialize::number(l.Cx)},
                                      {"Cy", serialize::number(l.Cy)},
                                      {"Cz", serialize::number(l.Cz)},
                                      {"n", serialize::number(l.n)},
                                      {"rho", serialize::number(l.albedo)}});
            }
            out["rho_d"] = Record::NumberOrNull{a.rho_d};
            out["lobes"] = lobes_json;
            break;
        }
    }
    out["brightness"] = Record::NumberOrNull{brightness};
}

// ---------------------------------------------------------------------------------------------
// Output formatting

std::string cell_text(const json& v) {
    if (v.is_null()) return "";
    if (v.is_boolean()) return v.get<bool>() ? "true" : "false";
    if (v.is_string()) return v.get<std::string>();
    if (v.is_number()) return format_result(v.get<double>());
    return v.dump();  // arrays/objects (Lafortune lobes)
}

std::string human_text(const json& record) {
    std::vector<std::pair<std::string, std::string>> items;
    for (const auto& [key, value] : record.items()) {
        items.emplace_back(key, value.is_null() ? "unknown" : cell_text(value));
    }
    std::ostringstream os;
    print_key_values(os, items);
    return os.str();
}

// CSV header line: the keys of a record.
std::string csv_header(const json& record) {
    std::string out;
    bool first = true;
    for (const auto& [key, value] : record.items()) {
        if (!first) out += ',';
        out += csv_field(key);
        first = false;
    }
    out += '\n';
    return out;
}

// One CSV line: the values of a record.
void append_csv_line(std::string& out, const json& record) {
    bool first = true;
    for (const auto& [key, value] : record.items()) {
        if (!first) out += ',';
        const std::string cell = cell_text(value);
        if (cell.find_first_of(",\"\n\r") == std::string::npos)
            out += cell;  // csv_field would return it unchanged
        else
            out += csv_field(cell);
        first = false;
    }
    out += '\n';
}

std::string csv_text(const json& record) {
    std::string out = csv_header(record);
    append_csv_line(out, record);
    return out;
}

// A string that JSON and CSV output write as its bytes: printable ASCII without quote, backslash
// or CSV separator (every key and word of a record). One table look-up per character.
bool plain_text(std::string_view text) {
    static constexpr auto kPlain = [] {
        std::array<bool, 256> plain{};
        for (int c = 0x20; c < 0x7f; ++c) plain[static_cast<std::size_t>(c)] = true;
        for (char c : {'"', '\\', ','}) plain[static_cast<unsigned char>(c)] = false;
        return plain;
    }();
    for (char c : text)
        if (!kPlain[static_cast<unsigned char>(c)]) return false;
    return true;
}

// Appends the CSV cell of a value (cell_text, quoted by csv_field when needed).
void append_csv_cell(std::string& out, const Record::Value& v) {
    using Kind = Record::Value::Kind;
    if (v.kind == Kind::Number && std::isfinite(v.number)) {
        // format_result's "%.10g" (no "-0"), without a temporary string.
        static_assert(roughscope::kSignificantBufferSize <= 64);
        out += v.number_text(Record::Value::Style::Csv, [&](char* buf) {
            return roughscope::write_significant(buf, v.number == 0.0 ? 0.0 : v.number,
                                                 kPrintDigits);
        });
        return;
    }
    if (v.kind == Kind::Null) return;  // cell_text: ""
    if (v.kind == Kind::Boolean) {
        out += v.boolean ? "true" : "false";
        return;
    }
    if (v.kind == Kind::Text && plain_text(v.text)) {
        out += v.text;
        return;
    }
    const std::string cell = cell_text(v.to_json());
    if (cell.find_first_of(",\"\n\r") == std::string::npos)
        out += cell;  // csv_field would return it unchanged
    else
        out += csv_field(cell);
}

// Writes the records of `model --csv` one at a time: CSV (header from the first record) or a JSON
// array byte-identical to serialize::dump of the whole array, without holding the records. Each
// record is formatted straight into the chunk of rows that goes to the output once it holds
// kChunkBytes.
class RecordWriter {
  public:
    RecordWriter(io::OutputFile& out, bool json_output) : out_(out), json_(json_output) {}

    void add(const Record& record) {
        if (json_) {
            chunk_.append(count_ == 0 ? "[\n" : ",\n");
            if (!append_json_element(record)) {
                // Nested values (Lafortune lobes) or strings to escape: the element as the whole
                // array's dump indents it: "[\n" + element + "\n]\n".
                json one = json::array();
                one.push_back(serialize::versioned(record.to_json()));
                const std::string text = serialize::dump(one);
                chunk_.append(text, 2, text.size() - 5);
            }
        } else {
            if (count_ == 0) {
                bool first = true;
                for (const auto& item : record.items()) {
                    if (!first) chunk_ += ',';
                    chunk_ += csv_field(std::string(item.key));
                    first = false;
                }
                chunk_ += '\n';
            }
            bool first = true;
            for (const auto& item : record.items()) {
                if (!first) chunk_ += ',';
                append_csv_cell(chunk_, item.value);
                first = false;
            }
            chunk_ += '\n';
        }
        ++count_;
        if (chunk_.size() >= kChunkBytes) {
            out_.write(chunk_);
            chunk_.clear();
        }
    }

    // Closes the array (JSON) and writes what is pending; the caller commits the output.
    void finish() {
        if (json_ && count_ > 0) chunk_ += "\n]\n";
        out_.write(chunk_);
        chunk_.clear();
    }

    std::size_t count() const { return count_; }

  private:
    // Rows are written out in chunks of this size: large enough that the output file writes
    // them through without copying (io::OutputFile), small enough to stay in the cache.
    static constexpr std::size_t kChunkBytes = std::size_t{64} << 10;

    // The text before a record's value at one position: ",\n    \"key\": ", made once; `usable` is
    // false for a key that needs escaping or does not fit (the element then goes the slow way).
    static constexpr std::size_t kBlock = 64;
    struct KeyText {
        std::string_view key;
        bool usable = false;
        std::uint8_t size = 0;
        std::array<char, kBlock> text{};
    };

    // Numbers formatted before, in a direct-mapped cache by their bits: the B-K records'
    // brightness, diffuse and total are often the same double, and the angles of a table of
    // measurements repeat from row to row (a grid of geometries).
    struct CachedNumber {
        std::uint64_t bits = 0;
        std::uint8_t size = 0;  // 0: empty
        std::array<char, serialize::kNumberBufferSize> text{};
    };
    static constexpr int kCacheBits = 10;

    // serialize::dump's own number formatter (the same bytes by construction), unless the same
    // double is in the cache.
    char* write_number(char* out, double value) {
        const auto bits = std::bit_cast<std::uint64_t>(value);
        CachedNumber& c = cache_[(bits * 0x9E3779B97F4A7C15ULL) >> (64 - kCacheBits)];
        if (c.size != 0 && c.bits == bits) return std::copy_n(c.text.data(), c.size, out);
        char* const end = serialize::write_number(out, value);
        c.bits = bits;
        c.size = static_cast<std::uint8_t>(end - out);
        std::copy(out, end, c.text.data());
        return end;
    }

    // The key texts of the record's positions, made when a position's key is new: keys are
    // literals, so the same address and size is the same key.
    void update_keys(std::span<const Record::Item> items) {
        if (keys_.size() < items.size()) keys_.resize(items.size());
        for (std::size_t k = 0; k < items.size(); ++k) {
            const std::string_view key = items[k].key;
            KeyText& slot = keys_[k];
            if (slot.key.data() == key.data() && slot.key.size() == key.size()) continue;
            slot.key = key;
            constexpr std::string_view kBefore = ",\n    \"", kAfter = "\": ";
            const std::size_t size = kBefore.size() + key.size() + kAfter.size();
            slot.usable = plain_text(key) && size <= kBlock;
            if (!slot.usable) continue;
            char* p = std::copy(kBefore.begin(), kBefore.end(), slot.text.data());
            p = std::copy(key.begin(), key.end(), p);
            std::copy(kAfter.begin(), kAfter.end(), p);
            slot.size = static_cast<std::uint8_t>(size);
        }
    }

    // The element "  {\n    \"key\": value,\n ...\n  }" as dump(2) indents it inside the array;
    // false (chunk_ unchanged) when a value is nested or a key or string needs escaping.
    bool append_json_element(const Record& record) {
        using Kind = Record::Value::Kind;
        static constexpr std::string_view kTail = "\n  }";
        const std::string_view head = head_;
        const std::span<const Record::Item> items = record.items();
        update_keys(items);
        // Pass 1: whether every value is written as is, and room for the text (whole blocks).
        std::size_t room = head.size() + kTail.size();
        for (std::size_t k = 0; k < items.size(); ++k) {
            const Record::Value& v = items[k].value;
            if (!keys_[k].usable || v.kind == Kind::Nested) return false;
            if (v.kind == Kind::Text && !plain_text(v.text)) return false;
            room += keys_[k].size +
                    (v.kind == Kind::Text ? v.text.size() + 2 : serialize::kNumberBufferSize);
        }
        // Pass 2: the text, straight into the chunk.
        const std::size_t mark = chunk_.size();
        chunk_.resize(mark + room);
        char* p = std::copy(head.begin(), head.end(), chunk_.data() + mark);
        for (std::size_t k = 0; k < items.size(); ++k) {
            const KeyText& key = keys_[k];
            p = std::copy_n(key.text.data(), key.size, p);
            const Record::Value& v = items[k].value;
            switch (v.kind) {
                case Kind::Null:
                    p = std::copy_n("null", 4, p);
                    break;
                case Kind::Boolean:
                    p = v.boolean ? std::copy_n("true", 4, p) : std::copy_n("false", 5, p);
                    break;
                case Kind::Number:
                    p = write_number(p, v.number);
                    break;
                case Kind::Text:
                    *p++ = '"';
                    p = std::copy(v.text.begin(), v.text.end(), p);
                    *p++ = '"';
                    break;
                case Kind::Nested:
                    break;  // refused in pass 1
            }
        }
        p = std::copy(kTail.begin(), kTail.end(), p);
        chunk_.resize(static_cast<std::size_t>(p - chunk_.data()));
        return true;
    }

    io::OutputFile& out_;
    bool json_;
    // serialize::versioned: the version first in every element.
    const std::string head_ = std::string("  {\n    \"") + serialize::kVersionKey +
                              "\": \"" ROUGHSCOPE_VERSION_STRING "\"";
    std::size_t count_ = 0;
    std::string chunk_;
    std::vector<KeyText> keys_;  // by position in the record
    std::vector<CachedNumber> cache_ = std::vector<CachedNumber>(std::size_t{1} << kCacheBits);
};

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
        Record result;
        evaluate(a, p, roughness_from_flags(a), result);
        const json record = result.to_json();
        std::string text;
        if (a.json_output) {
            text = serialize::dump(serialize::versioned(record));
        } else if (output) {
            text = csv_text(record);
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
    RecordWriter writer(out, a.json_output);
    Record record;  // reused row after row
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
