// `roughscope estimate`: roughness from brightness measurements (paper §4).
//
//   estimate specular            σ from the specular reflectance (Eq. 12–13)
//   estimate correlation-length  T from two diffuse measurements, σ known (Eq. 14–15)
//   estimate slope               σ/T from a brightness ratio (Eq. 16–19), very rough surfaces
//   estimate fit                 least squares to N measurements from a CSV file (exit 3:
//                                not identifiable when the data cannot determine the fit)
//
// Angles in degrees, lengths in µm. See docs/estimation.md and docs/cli.md. The JSON documents
// are built by the library (roughscope/serialize/estimation.hpp), the same as the Python
// module's dicts; this file parses flags, calls the estimators and prints.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <system_error>
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
#include "roughscope/serialize/estimation.hpp"

namespace roughscope::cli {
namespace {

// Correlation choice of `estimate slope` / `estimate fit`: one (Gaussian or exponential), or both
// side by side (std::nullopt; parse_correlation_or_both in common.hpp).
using CorrelationChoice = std::optional<Correlation>;

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
    if (given(r.o_e1) && given(r.o_e2)) {
        const double ratio = r.e1 / r.e2;
        if (!(ratio > 0.0 && ratio <= std::numeric_limits<double>::max()))
            throw UsageError("--e1/--e2: E1/E2 = " + format_message(r.e1, 17) + "/" +
                             format_message(r.e2, 17) +
                             " underflows or overflows the double range; give values with a "
                             "representable ratio (or --ratio)");
        return ratio;
    }
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
CLI::Option* add_wavelength_option(
    CLI::App& cmd, double& wavelength_um,
    const std::string& description = "Mean wavelength lambda (um; default 0.555)") {
    // The library's length range (scattering/beckmann.hpp): no product of lengths overflows.
    return add_range_option(cmd, "--wavelength", wavelength_um, kMinLengthUm, kMaxLengthUm,
                            description);
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
    write_output(
        given(o.o_output) ? std::optional<std::filesystem::path>(o.output_path) : std::nullopt,
        o.json_output ? serialize::dump(serialize::versioned(record))
                      : serialize::estimate_text(record));
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
    emit(a.out,
         serialize::specular_estimate_json(in, estimate_sigma_specular(in), given(a.o_noise)));
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
    emit(a.out,
         serialize::correlation_length_estimate_json(in, estimate_correlation_length(in),
                                                     given(a.o_noise) || given(a.o_sigma_stderr)));
}

// ---------------------------------------------------------------------------------------------
// estimate slope

struct SlopeArgs {
    RatioArgs ratio;
    PairArgs pair;
    double noise = 0.0, sigma_um = 0.0, wavelength_um = 0.555;
    CorrelationChoice correlation = std::nullopt;  // both
    GeometricFactor factor = GeometricFactor::VernoldHarvey;
    Radiometry radiometry = Radiometry::Radiance;
    CLI::Option *o_noise{}, *o_sigma{};
    OutputArgs out;
};

SlopeInput slope_input(const SlopeArgs& a, const Geometry& g1, const Geometry& g2, double ratio) {
    SlopeInput in;
    in.E1_over_E2 = ratio;
    in.geom1 = g1;
    in.geom2 = g2;
    in.options.factor = a.factor;
    in.options.radiometry = a.radiometry;
    in.options.wavelength_um = a.wavelength_um;
    in.noise = {a.noise, a.noise};
    if (given(a.o_sigma)) in.sigma_um = a.sigma_um;
    return in;
}

RoughnessEstimate slope_for(const SlopeArgs& a, SlopeInput in, Correlation c) {
    in.correlation = c;
    try {
        return estimate_slope(in);
    } catch (const NoSolution& e) {
        if (a.correlation) throw;
        throw NoSolution(std::string(e.what()) + "; use --correlation " +
                         (c == Correlation::Gaussian ? "exponential" : "gaussian") +
                         " to estimate with the other correlation function alone");
    }
}

void run_slope(const SlopeArgs& a) {
    const auto [g1, g2] = geometries_from(a.pair);
    const SlopeInput in = slope_input(a, g1, g2, ratio_from(a.ratio));
    std::optional<RoughnessEstimate> eg, ee;
    if (a.correlation != Correlation::Exponential) eg = slope_for(a, in, Correlation::Gaussian);
    if (a.correlation != Correlation::Gaussian) ee = slope_for(a, in, Correlation::Exponential);
    emit(a.out, serialize::slope_estimate_json(in, eg, ee, given(a.o_noise)));
}

// ---------------------------------------------------------------------------------------------
// estimate fit

struct FitArgs {
    std::string measurements_path;
    FitModel model = FitModel::VeryRough;
    CorrelationChoice correlation = std::nullopt;  // both
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
// An upper bound of the data rows of a measurements file: its line count, and at most one row per
// 10 bytes (the shortest row, "0,0,0,0,1\n"). 0 if it cannot be read (the reader reports that).
std::size_t max_rows(const std::filesystem::path& path) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) return 0;
    std::ifstream in(path, std::ios::binary);
    if (!in) return 0;
    const auto size = std::filesystem::file_size(path, ec);
    if (ec) return 0;
    std::vector<char> buffer(std::size_t{1} << 16);
    std::size_t lines = 1;
    while (in) {
        in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
        const std::streamsize n = in.gcount();
        lines += static_cast<std::size_t>(std::count(buffer.data(), buffer.data() + n, '\n'));
        if (n == 0) break;
    }
    return std::min<std::size_t>(lines, static_cast<std::size_t>(size / 10 + 1));
}

// Streamed row by row: only the measurements are kept, not the rows.
std::vector<Measurement> read_measurements(const std::filesystem::path& path) {
    io::CsvReader reader(path, {"theta_i", "phi_i", "theta_s", "phi_s", "brightness"}, {"weight"});
    const std::size_t c_ti = *reader.column_index("theta_i");
    const std::size_t c_pi = *reader.column_index("phi_i");
    const std::size_t c_ts = *reader.column_index("theta_s");
    const std::size_t c_ps = *reader.column_index("phi_s");
    const std::size_t c_b = *reader.column_index("brightness");
    const std::optional<std::size_t> c_w = reader.column_index("weight");
    std::vector<Measurement> ms;
    ms.reserve(max_rows(path));  // one allocation, no slack
    CsvRow row;
    while (reader.next(row)) {
        try {
            for (const auto& [c, col] : {std::pair{c_ti, "theta_i"}, {c_ts, "theta_s"}}) {
                const double v = *row.value(c);
                if (!(v >= 0.0 && v < 90.0))
                    throw roughscope::InvalidArgument(
                        "column '" + std::string(col) + "': " + format_result(v, col) +
                        " is outside the valid range [0, 90) degrees");
            }
            const double b = *row.value(c_b);
            if (!(b > 0.0))
                throw roughscope::InvalidArgument("column 'brightness': " + format_result(b) +
                                                  " must be > 0");
            const double w = c_w ? row.value(*c_w).value_or(1.0) : 1.0;
            if (!(w > 0.0))
                throw roughscope::InvalidArgument("column 'weight': " + format_result(w) +
                                                  " must be > 0");
            const Geometry g = geometry_from_two_azimuths(
                deg_to_rad(*row.value(c_ti)), deg_to_rad(*row.value(c_pi)),
                deg_to_rad(*row.value(c_ts)), deg_to_rad(*row.value(c_ps)));
            ms.push_back({g, b, w});
        } catch (const roughscope::DataError&) {
            throw;
        } catch (const roughscope::InvalidArgument& e) {
            std::string where = path.string();
            where.append(":").append(std::to_string(row.line)).append(": ").append(e.what());
            throw roughscope::DataError(where);
        }
    }
    if (ms.empty())
        throw roughscope::DataError(reader.source() + ": no data rows after the header");
    return ms;
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

    // FitOptions are built by the library from named options, as for the Python module.
    json options = {{"model", std::string(to_string(a.model))},
                    {"factor", std::string(to_string(a.factor))},
                    {"radiometry", std::string(to_string(a.radiometry))},
                    {"regime", std::string(to_string(a.regime))},
                    {"wavelength_um", a.wavelength_um},
                    {"residual", std::string(to_string(a.residual))},
                    {"loss", std::string(to_string(a.loss))},
                    {"loss_scale", a.loss_scale},
                    {"max_iterations", a.max_iterations}};
    if (given(a.o_initial_sigma_over_T)) options["initial_sigma_over_T"] = a.initial_sigma_over_T;
    if (given(a.o_initial_sigma)) options["initial_sigma_um"] = a.initial_sigma_um;
    if (given(a.o_initial_T)) options["initial_T_um"] = a.initial_T_um;
    if (a.correlation) options["correlation"] = std::string(to_string(*a.correlation));
    const FitOptions o = serialize::fit_options_from(options);

    // A fit the data cannot determine is no result: exit 3 (no solution) when no fit is
    // identifiable; with both correlations and one identifiable, its numbers are printed and the
    // other's are unknown.
    auto no_solution = [&](const FitResult& r) {
        // The library's diagnosis (measurements, distinct geometries, parameters), without the
        // solver's notes that follow it.
        const std::size_t end = r.message.find("); ");
        return roughscope::NoSolution(
            "estimate fit (" + std::string(to_string(o.model)) + ", " +
            std::string(to_string(r.options.correlation)) + " correlation): " +
            (end == std::string::npos ? r.message : r.message.substr(0, end + 1)));
    };
    json out;
    if (!a.correlation) {  // both
        const CorrelationComparison c = compare_correlations(ms, o);
        if (c.gaussian.status == SolverStatus::NotIdentifiable &&
            c.exponential.status == SolverStatus::NotIdentifiable)
            throw no_solution(c.gaussian);
        out = serialize::fit_estimate_json(o, ms.size(), c, a.residuals);
        if (!a.out.json_output) {
            out["gaussian_fit"] = c.gaussian.brief_report();
            out["exponential_fit"] = c.exponential.brief_report();
        }
    } else {
        const FitResult r = fit_roughness(ms, o);
        if (r.status == SolverStatus::NotIdentifiable) throw no_solution(r);
        out = serialize::fit_estimate_json(o, ms.size(), r, a.residuals);
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
        add_enum_option(*cmd, "--correlation", a.correlation, parse_correlation_or_both,
                        "both (default), gaussian (Eq. 17) or exponential (Eq. 19)");
        add_pair_radiometry_option(*cmd, a.radiometry);
        a.o_noise = add_noise_option(*cmd, a.noise);
        a.o_sigma = add_positive_option(*cmd, "--sigma", a.sigma_um,
                                        "RMS height if known (um): adds T, g and the class", "um");
        add_wavelength_option(*cmd, a.wavelength_um,
                              "Wavelength for g with --sigma (um; default 0.555)");
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
            "gain K to brightness values at arbitrary geometries (Ceres; at least as many "
            "distinct geometries as parameters, else exit 3: not identifiable)");
        a.o_measurements = cmd->add_option(
            "--measurements", a.measurements_path,
            "CSV with header theta_i,phi_i,theta_s,phi_s,brightness[,weight] (degrees; "
            "phi_s = phi_i + 180 is the specular plane)");
        add_enum_option(*cmd, "--model", a.model, parse_fit_model,
                        "very_rough (default: sigma/T) or slightly_rough (sigma and T)");
        add_enum_option(*cmd, "--correlation", a.correlation, parse_correlation_or_both,
                        "both (default: fit both, compare by AIC), gaussian or exponential");
        add_factor_option(*cmd, a.factor);
        add_enum_option(*cmd, "--radiometry", a.radiometry, parse_radiometry,
                        "radiance (default) or intensity");
        a.o_regime = add_enum_option(*cmd, "--regime", a.regime, parse_regime,
                                     "slightly-rough model: slightly_rough (default, Eq. 3), "
                                     "series or auto");
        a.o_wavelength = add_wavelength_option(*cmd, a.wavelength_um,
                                               "slightly-rough model: wavelength (um; 0.555)");
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
            ->transform(integer_validator(1, 100000));
        cmd->add_flag("--residuals", a.residuals, "Include the residuals in the JSON output");
        add_output_options(*cmd, a.out);
        cmd->callback([args]() { run_fit(*args); });
    }
}

}  // namespace roughscope::cli
