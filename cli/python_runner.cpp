// Running a module of the roughscope Python package (python_runner.hpp).
#include "python_runner.hpp"

#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include "roughscope/core/errors.hpp"

namespace roughscope::cli {
namespace {

namespace fs = std::filesystem;

std::optional<fs::path> package_dir_beside_executable() {
    std::error_code ec;
    const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    if (ec) return std::nullopt;
    for (const fs::path& candidate :
         {exe.parent_path().parent_path() / "python",
          exe.parent_path().parent_path() / "lib" / "roughscope" / "python",
          // <prefix>/bin/roughscope of the .deb (or a copy of its files in a scratch root)
          exe.parent_path().parent_path() / "lib" / "python3" / "dist-packages"}) {
        if (fs::exists(candidate / "roughscope" / "plot.py", ec)) return candidate;
    }
    return std::nullopt;
}

// The last non-empty line of `text` (Python's error message comes last).
std::string last_line(const std::string& text) {
    std::string last, line;
    for (char ch : text + "\n") {
        if (ch == '\n') {
            if (line.find_first_not_of(" \t\r") != std::string::npos) last = line;
            line.clear();
        } else {
            line += ch;
        }
    }
    return last;
}

struct Pipe {
    int fd[2] = {-1, -1};
    Pipe() {
        if (::pipe(fd) != 0)
            throw DataError(std::string("cannot create a pipe: ") + std::strerror(errno));
    }
    ~Pipe() {
        for (int f : fd)
            if (f >= 0) ::close(f);
    }
    void close(int k) {
        if (fd[k] >= 0) ::close(fd[k]);
        fd[k] = -1;
    }
};

}  // namespace

std::string python_interpreter() {
    if (const char* p = std::getenv("ROUGHSCOPE_PYTHON"); p && *p) return p;
    std::error_code ec;
    if (fs::exists("/usr/bin/python3", ec)) return "/usr/bin/python3";
    return "python3";
}

void run_python_module(const std::string& module, const std::vector<std::string>& args,
                       const std::string& input, const std::string& what) {
    const std::string interpreter = python_interpreter();
    std::vector<std::string> argv_text{interpreter, "-m", module};
    argv_text.insert(argv_text.end(), args.begin(), args.end());
    std::vector<char*> argv;
    argv.reserve(argv_text.size() + 1);
    for (auto& s : argv_text) argv.push_back(s.data());
    argv.push_back(nullptr);
    std::string pythonpath;
    if (const auto pkg = package_dir_beside_executable()) {
        const char* old = std::getenv("PYTHONPATH");
        pythonpath = pkg->string();
        if (old && *old) {  // appended piecewise: GCC 12's -Wrestrict misfires on
                            // ":" + string
            pythonpath += ':';
            pythonpath += old;
        }
    }

    Pipe in, err;
    const pid_t pid = ::fork();
    if (pid < 0) throw DataError(what + ": cannot start " + interpreter + ": fork failed");
    if (pid == 0) {  // child: only async-signal-safe calls until exec
        ::dup2(in.fd[0], STDIN_FILENO);
        ::dup2(err.fd[1], STDOUT_FILENO);
        ::dup2(err.fd[1], STDERR_FILENO);
        ::close(in.fd[0]);
        ::close(in.fd[1]);
        ::close(err.fd[0]);
        ::close(err.fd[1]);
        if (!pythonpath.empty()) ::setenv("PYTHONPATH", pythonpath.c_str(), 1);
        ::execvp(argv[0], argv.data());
        const std::string msg = "cannot run the Python interpreter '" + interpreter +
                                "': " + std::strerror(errno) + " (set ROUGHSCOPE_PYTHON)\n";
        [[maybe_unused]] const ssize_t n = ::write(STDERR_FILENO, msg.data(), msg.size());
        ::_exit(127);
    }
    in.close(0);
    err.close(1);

    // Feed the document; a child that exits early closes the pipe (EPIPE, not
    // SIGPIPE).
    struct sigaction ignore {
    }, previous{};
    ignore.sa_handler = SIG_IGN;
    ::sigaction(SIGPIPE, &ignore, &previous);
    std::size_t written = 0;
    while (written < input.size()) {
        const ssize_t n = ::write(in.fd[1], input.data() + written, input.size() - written);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) break;
        written += static_cast<std::size_t>(n);
    }
    in.close(1);
    ::sigaction(SIGPIPE, &previous, nullptr);

    std::string output;
    char buf[4096];
    for (;;) {
        const ssize_t n = ::read(err.fd[0], buf, sizeof buf);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) break;
        output.append(buf, static_cast<std::size_t>(n));
    }
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    const bool ok = WIFEXITED(status) && WEXITSTATUS(status) == 0;
    if (ok) return;
    std::string message = last_line(output);
    if (message.empty())
        message = WIFSIGNALED(status) ? "the Python process was killed by signal " +
                                            std::to_string(WTERMSIG(status))
                                      : "the Python process exited with status " +
                                            std::to_string(WEXITSTATUS(status)) + " and no message";
    throw DataError(what + ": " + message);
}

}  // namespace roughscope::cli
