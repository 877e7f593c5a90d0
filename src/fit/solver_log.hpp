// Ceres' own log lines (glog): kept off the terminal and put in a fit's message instead. Internal
// to the fit topic (src/fit/engine.cpp).
//
// Ceres writes through glog whatever the solver options say (e.g. "Terminating: Residual and
// Jacobian evaluation failed." at ERROR). Before glog is initialised every such line goes to
// stderr, so on the first solve, if the host program has not initialised glog itself, the library
// does: no log files, nothing on stderr below FATAL (the environment's GLOG_* settings still
// apply). A host that initialised glog keeps its own configuration. Either way one process-wide
// sink copies each line logged by a thread inside solve_least_squares into that solve's capture.
#pragma once

#include <string>
#include <vector>

namespace roughscope::detail {

// Collects the lines Ceres logs on this thread while alive.
class SolverLogCapture {
  public:
    SolverLogCapture();
    ~SolverLogCapture();
    SolverLogCapture(const SolverLogCapture&) = delete;
    SolverLogCapture& operator=(const SolverLogCapture&) = delete;

    // "; solver log: <line> (N times); <line>" with each distinct line once, in order; empty
    // when nothing was logged.
    std::string summary() const;

  private:
    std::vector<std::string> lines_;
    std::vector<std::string>* previous_;
};

}  // namespace roughscope::detail
