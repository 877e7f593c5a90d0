// `roughscope simulate capture`: synthetic camera captures (placeholder until the capture renderer
// lands; registers nothing).
#include "simulate.hpp"

namespace roughscope::cli {

void add_simulate_capture(CLI::App& /*simulate*/) {}

}  // namespace roughscope::cli
