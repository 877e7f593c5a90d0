// `roughscope simulate`: ground truth from simulations (the simulation topic). cli/simulate.cpp
// creates the subcommand; each of its subcommands lives in its own file and adds itself here.
#pragma once

#include <CLI/CLI.hpp>

namespace roughscope::cli {

void add_simulate_scatter(CLI::App& simulate);  // cli/simulate_scatter.cpp — Kirchhoff Monte Carlo
void add_simulate_capture(CLI::App& simulate);  // cli/simulate_capture.cpp — synthetic captures

}  // namespace roughscope::cli
