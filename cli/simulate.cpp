// `roughscope simulate`: numerical Kirchhoff scattering on random surfaces (scatter) and synthetic
// camera captures (capture). Each subcommand is in its own file (simulate.hpp).
#include "simulate.hpp"

#include "commands.hpp"

namespace roughscope::cli {

void register_simulate(CLI::App& app) {
    auto* simulate = app.add_subcommand(
        "simulate",
        "Ground truth: Monte Carlo Kirchhoff scattering on generated surfaces, synthetic captures");
    simulate->require_subcommand(1);
    add_simulate_scatter(*simulate);
    add_simulate_capture(*simulate);
}

}  // namespace roughscope::cli
