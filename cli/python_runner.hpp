// Running a module of the roughscope Python package from the CLI (figures stay in Python).
#pragma once

#include <string>
#include <vector>

namespace roughscope::cli {

// The interpreter: $ROUGHSCOPE_PYTHON when set and non-empty, else /usr/bin/python3 when it
// exists (Debian's, which has numpy and matplotlib), else `python3` looked up on PATH.
std::string python_interpreter();

// Runs `<interpreter> -m <module> <args...>` directly (fork + execvp, no shell), with the package
// beside the executable (<bin>/../python) first on PYTHONPATH, and writes `input` to its standard
// input through a pipe. Its standard output and error are captured. On a non-zero exit (or a
// failure to start) throws roughscope::DataError "<what>: <the last line Python printed on
// stderr>"; on exit status 0 returns what it wrote on standard output. While it runs, a signal
// that ends the CLI (install_output_cleanup_handlers) kills it too (io::ChildProcessGuard).
std::string run_python_module(const std::string& module, const std::vector<std::string>& args,
                              const std::string& input, const std::string& what);

}  // namespace roughscope::cli
