// JSON, CSV and text forms of the simulation topic: the documents of `roughscope simulate scatter`
// and the dicts of roughscope.simulate_scatter (keys in docs/simulation.md). Both front ends call
// these functions; neither derives a key. Numbers are not rounded; nothing is NaN.
#pragma once

#include <string>
#include <vector>

#include "roughscope/serialize/json.hpp"
#include "roughscope/simulation/kirchhoff.hpp"

namespace roughscope::serialize {

// One geometry. Keys, in order: theta_i_deg, theta_s_deg, phi_s_deg, g, T_vxy, F2, diffuse,
// diffuse_stderr, coherent, coherent_stderr, series_diffuse, series_coherent, diffuse_deviation
// ((diffuse − series_diffuse)/diffuse_stderr; null when the standard error is 0), n, dx_um,
// patch_um (n·dx), area_um2, realisations, layout, lattice_index.
Json to_json(const simulation::ScatterResult& result);

// The run: options (correlation, sigma_um, T_um, wavelength_um, factor, n (null = chosen),
// dx_um (null = chosen), patch_over_T, realisations, seed, layout) and results (to_json of each).
Json to_json(const std::vector<simulation::ScatterResult>& results,
             const simulation::ScatterOptions& options);

// CSV: the keys of to_json(ScatterResult) as the header, one row per geometry.
std::string scatter_csv(const std::vector<simulation::ScatterResult>& results);

// An aligned table for a person.
std::string to_text(const std::vector<simulation::ScatterResult>& results,
                    const simulation::ScatterOptions& options);

}  // namespace roughscope::serialize
