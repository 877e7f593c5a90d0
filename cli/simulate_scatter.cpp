// `roughscope simulate scatter`: Monte Carlo Kirchhoff scattering on generated surfaces
// (simulation/kirchhoff.hpp) next to the exact series at the same geometry. Documents come from
// serialize/simulation.hpp (the same as the Python module's); progress goes to stderr when it is
// a terminal; Ctrl-C stops the run with nothing written (io::OutputFile).
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <unistd.h>

#include "common.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/serialize/json.hpp"
#include "roughscope/serialize/simulation.hpp"
#include "roughscope/simulation/kirchhoff.hpp"
#include "simulate.hpp"

namespace roughscope::cli {
namespace {

namespace fs = std::filesystem;

struct ScatterCommand {
    simulation::ScatterOptions options;
    std::vector<double> theta_i_deg, theta_s_deg, phi_s_deg;
    std::string csv_path;
    bool json_output = false;
    std::string output_path;
    CLI::Option *o_csv{}, *o_output{}, *o_sigma{}, *o_T{};
};

std::vector<Geometry> geometries_from_flags(const ScatterCommand& c) {
    return geometries_from_angle_lists(c.theta_i_deg, c.theta_s_deg, c.phi_s_deg,
                                       ", or --csv FILE");
}

std::vector<Geometry> geometries_from_csv(const std::string& path) {
    io::CsvReader reader(fs::path(path), {"theta_i", "theta_s", "phi_s"});
    const std::size_t c_ti = *reader.column_index("theta_i");
    const std::size_t c_ts = *reader.column_index("theta_s");
    const std::size_t c_ps = *reader.column_index("phi_s");
    std::vector<Geometry> out;
    CsvRow row;
    while (reader.next(row)) {
        try {
            out.push_back(make_geometry(deg_to_rad(*row.value(c_ti)), deg_to_rad(*row.value(c_ts)),
                                        deg_to_rad(*row.value(c_ps))));
        } catch (const roughscope::InvalidArgument& e) {
            throw roughscope::DataError(path + ":" + std::to_string(row.line) + ": " + e.what());
        }
    }
    if (out.empty())
        throw roughscope::DataError(reader.source() + ": no data rows after the header");
    return out;
}

// "simulate scatter: 340/1000 realisations" rewritten in place on a terminal.
class TerminalProgress {
  public:
    TerminalProgress() : enabled_(::isatty(STDERR_FILENO) == 1) {}
    TerminalProgress(const TerminalProgress&) = delete;
    TerminalProgress& operator=(const TerminalProgress&) = delete;
    ~TerminalProgress() {
        if (enabled_ && shown_) std::fputs("\r\033[K", stderr);
    }
    void operator()(std::size_t done, std::size_t total) {
        if (!enabled_) return;
        const std::size_t percent = total == 0 ? 100 : done * 100 / total;
        if (shown_ && percent == last_percent_ && done != total) return;
        last_percent_ = percent;
        shown_ = true;
        std::fprintf(stderr, "\rsimulate scatter: %zu/%zu realisations (%zu%%)", done, total,
                     percent);
        std::fflush(stderr);
    }

  private:
    bool enabled_;
    bool shown_ = false;
    std::size_t last_percent_ = 0;
};

void run_scatter(const ScatterCommand& c) {
    const bool from_csv = given(c.o_csv);
    if (from_csv && (!c.theta_i_deg.empty() || !c.theta_s_deg.empty() || !c.phi_s_deg.empty()))
        throw UsageError("--csv excludes --theta-i/--theta-s/--phi-s: give one or the other");
    const std::vector<Geometry> geoms =
        from_csv ? geometries_from_csv(c.csv_path) : geometries_from_flags(c);
    simulation::check_scatter_options(c.options);
    for (const Geometry& g : geoms) simulation::choose_scatter_grid(g, c.options);
    TerminalProgress progress;
    const std::vector<simulation::ScatterResult> results = simulation::simulate_scattering(
        geoms, c.options,
        [&progress](std::size_t done, std::size_t total) { progress(done, total); });
    std::string text;
    if (c.json_output) {
        text = serialize::dump(serialize::versioned(serialize::to_json(results, c.options)));
    } else if (given(c.o_output)) {
        text = serialize::scatter_csv(results);
    } else {
        text = serialize::to_text(results, c.options);
    }
    write_output(given(c.o_output) ? std::optional<fs::path>(c.output_path) : std::nullopt, text);
}

}  // namespace

void add_simulate_scatter(CLI::App& simulate) {
    auto args = std::make_shared<ScatterCommand>();
    ScatterCommand& c = *args;
    c.options.factor = GeometricFactor::Beckmann;
    CLI::App* cmd = simulate.add_subcommand(
        "scatter",
        "Monte Carlo Kirchhoff scattering on generated surfaces (paper 3.1): coherent and diffuse "
        "power with standard errors, next to the exact series at the same geometry");
    const std::string gs = "Surface";
    add_enum_option(*cmd, "--correlation", c.options.correlation, parse_correlation,
                    "gaussian (default) or exponential")
        ->group(gs);
    c.o_sigma = add_range_option(*cmd, "--sigma-um", c.options.sigma_um, kMinLengthUm, 1e28,
                                 "RMS height sigma, um (required)")
                    ->required()
                    ->group(gs);
    c.o_T = add_range_option(*cmd, "--T-um", c.options.T_um, kMinLengthUm, kMaxLengthUm,
                             "Correlation length T, um (required)")
                ->required()
                ->group(gs);
    add_range_option(*cmd, "--wavelength-um", c.options.wavelength_um, kMinLengthUm, kMaxLengthUm,
                     "Wavelength lambda, um (default 0.555)")
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
    c.o_csv = cmd->add_option("--csv", c.csv_path,
                              "Geometries from a CSV file with columns theta_i, theta_s, phi_s "
                              "(degrees)")
                  ->group(gg);
    const std::string gm = "Simulation";
    cmd->add_option("--nx", c.options.n,
                    "Points per side of the square patch, 8..4096 (default: chosen from g and "
                    "T*v_xy, docs/simulation.md)")
        ->transform(integer_validator(8, 4096))
        ->group(gm);
    add_range_option(*cmd, "--dx-um", c.options.dx_um, kMinLengthUm, kMaxLengthUm,
                     "Grid spacing, um (default: chosen to resolve the diffuse kernel)")
        ->group(gm);
    add_range_option(*cmd, "--patch-over-T", c.options.patch_over_T, 1.0, 1e4,
                     "Patch side in units of T when --nx is chosen (default: 6 for gaussian, "
                     "8..11 for exponential, docs/simulation.md)")
        ->group(gm);
    cmd->add_option("--realisations", c.options.realisations,
                    "Surfaces per geometry, 10..10000000 (default 100; fewer give no usable "
                    "standard error)")
        ->transform(integer_validator(10, 10'000'000))
        ->group(gm);
    cmd->add_option("--seed", c.options.seed, "Seed of the surfaces (default 1)")
        ->transform(integer_validator(0, 9'223'372'036'854'775'807LL))
        ->group(gm);
    add_enum_option(*cmd, "--layout", c.options.layout, simulation::parse_patch_layout,
                    "lattice-aligned (default: the direction on the FFT lattice, no leakage) or "
                    "fixed (the given grid, direct summation)")
        ->group(gm);
    add_enum_option(*cmd, "--factor", c.options.factor, parse_geometric_factor,
                    "Geometric factor F of the field and the series: beckmann (default), vh, "
                    "ogilvy, kirchhoff")
        ->group(gm);
    cmd->add_option("--threads", c.options.threads, "Worker threads, 0 = all cores (default)")
        ->transform(integer_validator(0, 1024))
        ->group(gm);
    cmd->add_flag("--json", c.json_output, "Print JSON (keys in docs/simulation.md)")
        ->group("Output");
    c.o_output = cmd->add_option("--output", c.output_path,
                                 "Write the results to FILE atomically (CSV, or JSON with --json)")
                     ->group("Output");
    cmd->callback([args]() { run_scatter(*args); });
}

}  // namespace roughscope::cli
