// Subcommand registration. Each subcommand lives in its own file (cli/<name>.cpp) and registers
// itself on the top-level CLI::App; main.cpp calls every register_* function.
#pragma once

#include <CLI/CLI.hpp>

namespace roughscope::cli {

void register_model(CLI::App& app);       // cli/model.cpp    — evaluate models (§3, §5)
void register_estimate(CLI::App& app);    // cli/estimate.cpp — roughness estimation (§4)
void register_paper(CLI::App& app);       // cli/paper.cpp    — paper tables recomputed
void register_curet(CLI::App& app);       // cli/curet.cpp    — CUReT comparison (§5.3)
void register_surface(CLI::App& app);     // cli/surface.cpp  — height data (§3.1)
void register_simulate(CLI::App& app);    // cli/simulate.cpp — simulations (ground truth)
void register_measure(CLI::App& app);     // cli/measure.cpp  — roughness from photographs
void register_calibrate(CLI::App& app);   // cli/calibrate.cpp — the light from a mirror sphere
void register_plan(CLI::App& app);        // cli/plan.cpp     — the light angles to choose
void register_completion(CLI::App& app);  // cli/completion.cpp — bash completion script

}  // namespace roughscope::cli
