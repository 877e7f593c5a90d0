// `roughscope surface`: height data (paper §3.1) — stats, generate, convert, predict.
//
// A thin front end over the surface topic: files are read and written by surface/formats.hpp
// (write_height_map goes through io::OutputFile: atomic, nothing half-written), statistics by
// surface/statistics.hpp, the bridge to the optics by surface/predict.hpp, and every document by
// serialize/surface.hpp (the same one the Python module returns). Figures (--plot) are drawn by
// the Python package: `python3 -m roughscope.plot surface --out FILE` reads the statistics with
// their curves and a subsampled height image from a pipe (python_runner.hpp).
#include "roughscope/serialize/surface.hpp"

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "commands.hpp"
#include "common.hpp"
#include "python_runner.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/memory.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/serialize/json.hpp"
#include "roughscope/surface/formats.hpp"
#include "roughscope/surface/generate.hpp"
#include "roughscope/surface/height_map.hpp"
#include "roughscope/surface/predict.hpp"
#include "roughscope/surface/statistics.hpp"

namespace roughscope::cli {
namespace {

namespace fs = std::filesystem;
using surface::HeightFormat;

// Largest grid side accepted on the command line (the library caps the product at 2^28).
constexpr long long kMaxSide = 1LL << 28;

// ---- Reading options (what a file does not say itself: surface/formats.hpp) ----------------
struct ReadArgs {
    std::optional<HeightFormat> format;
    double dx_um = 1.0, dy_um = 1.0, z_scale_um = 1.0;
    std::string unit;
    std::size_t nx = 0, ny = 0;
    surface::RawSampleType raw_type = surface::RawSampleType::Float64;
    bool big_endian = false;
    bool no_verify_checksums = false;
    CLI::Option *o_dx{}, *o_dy{}, *o_unit{}, *o_z{}, *o_nx{}, *o_ny{};
};

surface::RawSampleType parse_raw_type(std::string_view name) {
    if (name == "float32" || name == "f32") return surface::RawSampleType::Float32;
    if (name == "float64" || name == "f64") return surface::RawSampleType::Float64;
    throw InvalidArgument("raw sample type '" + std::string(name) +
                          "' is not recognised; valid values: float32, float64");
}

void add_read_options(CLI::App& cmd, ReadArgs& r) {
    const std::string g = "Reading (what the file does not say)";
    cmd.add_option_function<std::string>(
           "--format",
           [&r](const std::string& text) {
               try {
                   r.format = surface::parse_height_format(normalize_name(text));
               } catch (const roughscope::Error& e) {
                   throw CLI::ValidationError("--format", e.what());
               }
           },
           "File format (default: from the extension): csv, xyz, sdf, x3p, gwy, gsf, png, tiff, "
           "raw")
        ->group(g);
    r.o_dx = add_positive_option(cmd, "--dx-um", r.dx_um,
                                 "Spacing along x in um (csv, png, tiff, raw; default 1)", "um")
                 ->group(g);
    r.o_dy =
        add_positive_option(cmd, "--dy-um", r.dy_um, "Spacing along y in um (default dx)", "um")
            ->group(g);
    r.o_unit = cmd.add_option("--unit", r.unit,
                              "Length unit of csv/xyz numbers without a header: m, mm, um, nm "
                              "(default um)")
                   ->group(g);
    r.o_z = add_positive_option(cmd, "--z-scale-um", r.z_scale_um,
                                "Height per count in um (integer png/tiff images)", "um")
                ->group(g);
    r.o_nx = cmd.add_option("--nx", r.nx, "Points along x (raw files)")
                 ->transform(integer_validator(1, kMaxSide))
                 ->group(g);
    r.o_ny = cmd.add_option("--ny", r.ny, "Points along y (raw files)")
                 ->transform(integer_validator(1, kMaxSide))
                 ->group(g);
    add_enum_option(cmd, "--raw-type", r.raw_type, parse_raw_type,
                    "Raw sample type: float32 or float64 (default)")
        ->group(g);
    cmd.add_flag("--big-endian", r.big_endian, "Raw samples are big-endian")->group(g);
    cmd.add_flag("--no-verify-checksums", r.no_verify_checksums,
                 "x3p: read a file whose MD5 checksums do not match (edited after they were "
                 "written); default: a mismatch is an error")
        ->group(g);
}

surface::HeightReadOptions read_options(const ReadArgs& r) {
    surface::HeightReadOptions o;
    o.format = r.format;
    if (given(r.o_dx)) o.dx_um = r.dx_um;
    if (given(r.o_dy))
        o.dy_um = r.dy_um;
    else if (given(r.o_dx))
        o.dy_um = r.dx_um;
    if (given(r.o_unit)) o.length_unit = r.unit;
    if (given(r.o_z)) o.z_scale_um = r.z_scale_um;
    if (given(r.o_nx)) o.nx = r.nx;
    if (given(r.o_ny)) o.ny = r.ny;
    o.raw_type = r.raw_type;
    o.raw_big_endian = r.big_endian;
    o.x3p_verify_checksums = !r.no_verify_checksums;
    return o;
}

// The format name of `path` read with `options` ("" when neither names one).
std::string format_name(const fs::path& path, const surface::HeightReadOptions& options) {
    const auto f = options.format ? options.format : surface::height_format_from_extension(path);
    return f ? surface::to_string(*f) : std::string();
}

// ---- Statistics options -------------------------------------------------------------------
struct StatsArgs {
    surface::StatisticsOptions options;
    int order = 1;
    double cutoff_um = 0;
    CLI::Option *o_order{}, *o_cutoff{};
};

void add_stats_options(CLI::App& cmd, StatsArgs& s) {
    const std::string g = "Levelling and statistics";
    add_enum_option(cmd, "--level", s.options.leveling, surface::parse_leveling,
                    "Background removed: none, mean, line (each row), plane (default), "
                    "polynomial")
        ->group(g);
    s.o_order = cmd.add_option("--order", s.order,
                               "Order of the polynomial background with --level polynomial, 1..3 "
                               "(default 1)")
                    ->transform(integer_validator(1, 3))
                    ->group(g);
    s.o_cutoff = add_positive_option(cmd, "--cutoff-um", s.cutoff_um,
                                     "Cutoff wavelength lambda_c of the Gaussian roughness filter "
                                     "(ISO 16610-21/61), um; default: no filter",
                                     "um")
                     ->group(g);
    add_enum_option(cmd, "--acf", s.options.acf_estimator, surface::parse_acf_estimator,
                    "ACF estimator: unbiased (N-j, default) or biased (N)")
        ->group(g);
}

surface::StatisticsOptions stats_options(const StatsArgs& s, bool keep_curves) {
    surface::StatisticsOptions o = s.options;
    if (given(s.o_order)) {
        if (o.leveling != surface::Leveling::Polynomial)
            throw UsageError(
                "--order needs --level polynomial (it is the order of the "
                "polynomial background, 1..3)");
        o.polynomial_order = s.order;
    }
    if (given(s.o_cutoff)) o.cutoff_um = s.cutoff_um;
    o.keep_curves = keep_curves;
    return o;
}

struct OutputArgs {
    bool json_output = false;
    std::string output_path;
    CLI::Option* o_output{};
};

void add_output_options(CLI::App& cmd, OutputArgs& o) {
    cmd.add_flag("--json", o.json_output, "Print JSON (keys in docs/cli.md)")->group("Output");
    o.o_output = cmd.add_option("--output", o.output_path,
                                "Write the result to FILE atomically instead of stdout")
                     ->group("Output");
}

void emit(const OutputArgs& o, const std::string& text) {
    write_output(given(o.o_output) ? std::optional<fs::path>(o.output_path) : std::nullopt, text);
}

// ---- stats --------------------------------------------------------------------------------
struct StatsCommand {
    std::string file;
    ReadArgs read;
    StatsArgs stats;
    OutputArgs out;
    std::string plot_path;
};

void draw_plot(const json& document, const fs::path& out_png) {
    if (out_png.extension() != ".png")
        throw InvalidArgument("--plot: '" + out_png.string() +
                              "' must end in .png (the figure is a PNG)");
    run_python_module("roughscope.plot", {"surface", "--out", fs::absolute(out_png).string()},
                      serialize::dump(document, -1), "--plot");
}

void run_stats(const StatsCommand& c) {
    const surface::HeightReadOptions ro = read_options(c.read);
    surface::HeightMap map = surface::read_height_map(c.file, ro);
    const bool plot = !c.plot_path.empty();
    const surface::StatisticsOptions so = stats_options(c.stats, plot);
    const serialize::StatisticsInput input =
        serialize::statistics_input(map, so, c.file, format_name(c.file, ro));
    surface::SurfaceStatistics stats;
    if (plot) {
        stats = surface::surface_statistics(map, so);
        json doc = serialize::to_json(input, stats, true);
        // The image shows the heights the statistics saw: levelled, and filtered with a cutoff.
        surface::HeightMap shown = surface::level(std::move(map), so.leveling, so.polynomial_order);
        if (so.cutoff_um) shown = surface::gaussian_filter(shown, *so.cutoff_um).roughness;
        doc["image"] = serialize::height_image_json(shown);
        draw_plot(doc, c.plot_path);
    } else {
        // The map is not needed afterwards: levelled in place (one copy less at the peak).
        stats = surface::surface_statistics(std::move(map), so);
    }
    emit(c.out, c.out.json_output
                    ? serialize::dump(serialize::versioned(serialize::to_json(input, stats)))
                    : serialize::to_text(input, stats));
}

// ---- generate -----------------------------------------------------------------------------
struct GenerateCommand {
    surface::GenerationOptions gen;
    std::string out_path;
    std::optional<HeightFormat> out_format;
    double z_scale_um = 0;
    bool sdf_ascii = false;
    bool json_output = false;
    CLI::Option *o_dy{}, *o_z{};
};

surface::HeightWriteOptions write_options(std::optional<HeightFormat> format,
                                          const CLI::Option* o_z, double z_scale_um,
                                          bool sdf_ascii) {
    surface::HeightWriteOptions w;
    w.format = format;
    if (given(o_z)) {
        w.z_scale_um = z_scale_um;
        w.tiff_float = false;
    }
    w.sdf_binary = !sdf_ascii;
    return w;
}

void add_write_options(CLI::App& cmd, std::optional<HeightFormat>& format, double& z_scale_um,
                       CLI::Option*& o_z, bool& sdf_ascii, const std::string& z_flag) {
    const std::string g = "Writing";
    cmd.add_option_function<std::string>(
           "--out-format",
           [&format](const std::string& text) {
               try {
                   format = surface::parse_height_format(normalize_name(text));
               } catch (const roughscope::Error& e) {
                   throw CLI::ValidationError("--out-format", e.what());
               }
           },
           "Output format (default: from the extension): csv, xyz, sdf, x3p, gsf, png, tiff, raw")
        ->group(g);
    o_z = add_positive_option(cmd, z_flag, z_scale_um,
                              "Height per count in um for integer png/tiff output (tiff: "
                              "16-bit integers instead of float samples)",
                              "um")
              ->group(g);
    cmd.add_flag("--sdf-ascii", sdf_ascii, "Write SDF as ASCII (aISO-1.0) instead of binary")
        ->group(g);
}

void run_generate(GenerateCommand& c) {
    if (!given(c.o_dy)) c.gen.dy_um = c.gen.dx_um;
    const surface::HeightWriteOptions w =
        write_options(c.out_format, c.o_z, c.z_scale_um, c.sdf_ascii);
    // The surface and its file, made in memory before it is written: checked together first.
    const auto format =
        c.out_format ? c.out_format : surface::height_format_from_extension(c.out_path);
    if (format && c.gen.nx * c.gen.ny <= surface::kMaxHeightMapPoints) {
        check_memory(surface::generation_memory_bytes(c.gen) +
                         surface::encoded_size_estimate(c.gen.nx * c.gen.ny, *format, w),
                     concat("surface generate --nx ", std::to_string(c.gen.nx), " --ny ",
                            std::to_string(c.gen.ny), " (a ", surface::to_string(*format),
                            " file of ", std::to_string(c.gen.nx * c.gen.ny), " heights)"),
                     "give a smaller --nx or --ny, or a binary --out-format (raw, tiff)");
    }
    const surface::HeightMap map = surface::generate_surface(c.gen);
    surface::write_height_map(map, c.out_path, w);
    if (c.json_output && c.out_path != "-")
        write_output(std::nullopt,
                     serialize::dump(serialize::versioned(serialize::summary_json(map))));
}

// ---- convert ------------------------------------------------------------------------------
struct ConvertCommand {
    std::string in, out;
    ReadArgs read;
    std::optional<HeightFormat> out_format;
    double z_scale_um = 0;
    bool sdf_ascii = false;
    CLI::Option* o_z{};
};

void run_convert(const ConvertCommand& c) {
    const surface::HeightMap map = surface::read_height_map(c.in, read_options(c.read));
    surface::write_height_map(map, c.out,
                              write_options(c.out_format, c.o_z, c.z_scale_um, c.sdf_ascii));
}

// ---- predict ------------------------------------------------------------------------------
struct PredictCommand {
    std::string file;
    ReadArgs read;
    StatsArgs stats;
    OutputArgs out;
    double sigma_um = 0, T_um = 0;
    Correlation correlation = Correlation::Gaussian;
    std::vector<double> theta_i_deg, theta_s_deg, phi_s_deg;
    ModelOptions model;
    CLI::Option *o_sigma{}, *o_T{}, *o_correlation{}, *o_file{};
};

std::vector<Geometry> geometries(const PredictCommand& c) {
    return geometries_from_angle_lists(c.theta_i_deg, c.theta_s_deg, c.phi_s_deg);
}

void run_predict(const PredictCommand& c) {
    const bool from_file = !c.file.empty();
    if (from_file && (given(c.o_sigma) || given(c.o_T)))
        throw UsageError("FILE excludes --sigma-um/--T-um: give a height file, or sigma and T");
    if (!from_file && (!given(c.o_sigma) || !given(c.o_T)))
        throw UsageError("give a height FILE, or both --sigma-um (> 0 um) and --T-um (> 0 um)");
    const std::vector<Geometry> geoms = geometries(c);
    surface::SurfacePrediction prediction;
    std::string T_source;
    if (from_file) {
        const surface::HeightMap map = surface::read_height_map(c.file, read_options(c.read));
        const surface::SurfaceStatistics stats =
            surface::surface_statistics(map, stats_options(c.stats, false));
        const std::optional<Correlation> corr =
            given(c.o_correlation) ? std::optional<Correlation>(c.correlation) : std::nullopt;
        T_source = surface::surface_from_statistics(stats, corr).T_source;
        prediction = surface::predict_brightness(stats, geoms, c.model, corr);
    } else {
        prediction =
            surface::predict_brightness(Surface{c.sigma_um, c.T_um, c.correlation}, geoms, c.model);
    }
    const std::string source = from_file ? c.file : std::string("given");
    emit(c.out, c.out.json_output ? serialize::dump(serialize::versioned(
                                        serialize::to_json(prediction, c.model, source, T_source)))
                                  : serialize::to_text(prediction, c.model, source));
}

}  // namespace

void register_surface(CLI::App& app) {
    CLI::App* top = app.add_subcommand(
        "surface",
        "Height data (paper section 3.1): stats, generate, convert, predict. Lengths in um, "
        "angles in degrees.");
    top->require_subcommand(1);

    {
        auto cmd_args = std::make_shared<StatsCommand>();
        StatsCommand& c = *cmd_args;
        CLI::App* cmd = top->add_subcommand(
            "stats",
            "Roughness statistics of a height file: sigma (Sq), Sa, Ssk, Sku, Sp, Sv, Sz, the "
            "ACF and correlation length T, Sal, Str, RMS slope, PSD");
        cmd->add_option("FILE", c.file,
                        "Height file (csv, xyz, sdf, x3p, gwy, gsf, png, tiff, raw)")
            ->required();
        add_read_options(*cmd, c.read);
        add_stats_options(*cmd, c.stats);
        add_output_options(*cmd, c.out);
        cmd->add_option("--plot", c.plot_path,
                        "Write a PNG report: the height image, the ACF with the fitted curves and "
                        "the 1/e line, the PSD")
            ->group("Output");
        cmd->callback([cmd_args]() { run_stats(*cmd_args); });
    }
    {
        auto cmd_args = std::make_shared<GenerateCommand>();
        GenerateCommand& c = *cmd_args;
        CLI::App* cmd = top->add_subcommand(
            "generate",
            "A random surface with Gaussian heights and Gaussian or exponential correlation of "
            "given sigma and T (FFT filtering of white noise; periodic; reproducible by --seed)");
        add_enum_option(*cmd, "--correlation", c.gen.correlation, parse_correlation,
                        "gaussian (default) or exponential");
        add_positive_option(*cmd, "--sigma-um", c.gen.sigma_um, "RMS height sigma, um (default 1)",
                            "um");
        add_positive_option(*cmd, "--T-um", c.gen.T_um, "Correlation length T, um (default 10)",
                            "um");
        cmd->add_option("--nx", c.gen.nx, "Points along x (default 256)")
            ->transform(integer_validator(1, kMaxSide));
        cmd->add_option("--ny", c.gen.ny, "Points along y (default 256; 1 = a profile)")
            ->transform(integer_validator(1, kMaxSide));
        add_positive_option(*cmd, "--dx-um", c.gen.dx_um, "Spacing along x, um (default 1)", "um");
        c.o_dy = add_positive_option(*cmd, "--dy-um", c.gen.dy_um,
                                     "Spacing along y, um (default: dx)", "um");
        cmd->add_option("--seed", c.gen.seed, "Random seed (default 1): same seed, same surface")
            ->transform(integer_validator(0, std::numeric_limits<long long>::max()));
        cmd->add_option("--out", c.out_path,
                        "Height file to write (format by extension; written atomically)")
            ->required();
        add_write_options(*cmd, c.out_format, c.z_scale_um, c.o_z, c.sdf_ascii, "--z-scale-um");
        cmd->add_flag("--json", c.json_output, "Print a JSON summary of the surface written");
        cmd->callback([cmd_args]() { run_generate(*cmd_args); });
    }
    {
        auto cmd_args = std::make_shared<ConvertCommand>();
        ConvertCommand& c = *cmd_args;
        CLI::App* cmd = top->add_subcommand(
            "convert", "Convert a height file to another format (by the extension of OUT)");
        cmd->add_option("IN", c.in, "Height file to read")->required();
        cmd->add_option("OUT", c.out, "Height file to write (written atomically)")->required();
        add_read_options(*cmd, c.read);
        add_write_options(*cmd, c.out_format, c.z_scale_um, c.o_z, c.sdf_ascii, "--out-z-scale-um");
        cmd->callback([cmd_args]() { run_convert(*cmd_args); });
    }
    {
        auto cmd_args = std::make_shared<PredictCommand>();
        PredictCommand& c = *cmd_args;
        CLI::App* cmd = top->add_subcommand(
            "predict",
            "Brightness predicted by the B-K models (Eq. 1-5) from a height file's sigma, T and "
            "correlation, or from given values; g at the wavelength and the roughness regime");
        c.o_file =
            cmd->add_option("FILE", c.file, "Height file (optional: else --sigma-um, --T-um)");
        const std::string gs = "Surface (instead of FILE)";
        c.o_sigma =
            add_positive_option(*cmd, "--sigma-um", c.sigma_um, "RMS height sigma, um", "um")
                ->group(gs);
        c.o_T = add_positive_option(*cmd, "--T-um", c.T_um, "Correlation length T, um", "um")
                    ->group(gs);
        c.o_correlation = add_enum_option(*cmd, "--correlation", c.correlation, parse_correlation,
                                          "gaussian (default) or exponential; with FILE it "
                                          "overrides the better fit")
                              ->group(gs);
        const std::string gg = "Geometry (degrees; comma-separated lists, single values repeat)";
        cmd->add_option("--theta-i", c.theta_i_deg, "Incidence polar angle(s) [0,90)")
            ->delimiter(',')
            ->transform(polar_angle_validator())
            ->group(gg);
        cmd->add_option("--theta-s", c.theta_s_deg, "Viewing polar angle(s) [0,90)")
            ->delimiter(',')
            ->transform(polar_angle_validator())
            ->group(gg);
        cmd->add_option("--phi-s", c.phi_s_deg,
                        "Viewing azimuth(s); 0 = specular plane, 180 = retro-reflection")
            ->delimiter(',')
            ->transform(finite_validator())
            ->group(gg);
        const std::string gm = "Model";
        add_range_option(*cmd, "--wavelength-um,--wavelength", c.model.wavelength_um, kMinLengthUm,
                         kMaxLengthUm, "Mean wavelength lambda, um (default 0.555)")
            ->group(gm);
        add_factor_option(*cmd, c.model.factor)->group(gm);
        add_enum_option(*cmd, "--radiometry", c.model.radiometry, parse_radiometry,
                        "radiance (default) or intensity")
            ->group(gm);
        add_enum_option(*cmd, "--regime", c.model.regime, parse_regime,
                        "auto (default: the exact series), series, slightly-rough, very-rough, "
                        "very-rough-series-limit")
            ->group(gm);
        add_read_options(*cmd, c.read);
        add_stats_options(*cmd, c.stats);
        add_output_options(*cmd, c.out);
        cmd->callback([cmd_args]() { run_predict(*cmd_args); });
    }
}

}  // namespace roughscope::cli
