// JSON schema of the model outputs of `roughscope model` (docs/cli.md): the B–K mean scattered
// power of Eq. 1–5.
#pragma once

#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/serialize/json.hpp"

namespace roughscope::serialize {

// brightness, coherent (ρ0² e^{−g}), diffuse (D), total (P, Eq. 1), g, regime (the one used,
// never "auto"), roughness_class, method (how D was evaluated: "closed_form", "summation",
// "large_g_expansion") and relative_error_bound (0 for a closed form asked for by name).
Json to_json(const ScatteredPower& power);

}  // namespace roughscope::serialize
