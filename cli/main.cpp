// `roughscope`: the command-line front end. Each subcommand lives in cli/<name>.cpp and registers
// itself through commands.hpp; errors and exit codes are handled by run_app (common.hpp).
#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "common.hpp"
#include "roughscope/version.hpp"

int main(int argc, char** argv) {
    CLI::App app{
        "roughscope: surface roughness from brightness with the modified Beckmann-Kirchhoff\n"
        "scattering theory (Ragheb & Hancock, Pattern Recognition 2007). Angles in degrees,\n"
        "lengths in micrometres. See docs/cli.md.",
        "roughscope"};
    app.set_version_flag("--version", std::string("roughscope ") + ROUGHSCOPE_VERSION_STRING,
                         "Print the version and exit");
    app.require_subcommand(1);
    app.fallthrough(false);
    // Errors are printed by run_app as one line; never dump the whole help on failure.
    app.failure_message(CLI::FailureMessage::simple);

    // Ctrl-C or SIGTERM during a long write removes the pending temporary output files.
    roughscope::io::install_output_cleanup_handlers();

    roughscope::cli::register_model(app);
    roughscope::cli::register_estimate(app);
    roughscope::cli::register_paper(app);
    roughscope::cli::register_curet(app);
    roughscope::cli::register_surface(app);
    roughscope::cli::register_simulate(app);
    roughscope::cli::register_measure(app);
    roughscope::cli::register_calibrate(app);
    roughscope::cli::register_plan(app);
    // Last: the completion script describes every subcommand registered before it.
    roughscope::cli::register_completion(app);

    return roughscope::cli::run_app(app, argc, argv);
}
