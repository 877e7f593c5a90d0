// Running a module of the roughscope Python package (python_runner.hpp).
#include "python_runner.hpp"

#include <array>
#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <fcntl.h>
#include <poll.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/io/output_file.hpp"

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

namespace {

// Writes `input` to `to_child` and reads `from_out` and `from_err` until both close, with poll()
// so that neither pipe can fill up and stall the child. Returns {stdout, stderr}.
std::pair<std::string, std::string> exchange_with_child(int to_child, int from_out, int from_err,
                                                        const std::string& input) {
    std::string out, err;
    std::size_t written = 0;
    if (input.empty()) {
        ::close(to_child);
        to_child = -1;
    } else {
        ::fcntl(to_child, F_SETFL, ::fcntl(to_child, F_GETFL) | O_NONBLOCK);
    }
    char buf[65536];
    while (from_out >= 0 || from_err >= 0) {
        std::array<pollfd, 3> fds{};
        nfds_t n = 0;
        if (to_child >= 0) fds[n++] = {to_child, POLLOUT, 0};
        if (from_out >= 0) fds[n++] = {from_out, POLLIN, 0};
        if (from_err >= 0) fds[n++] = {from_err, POLLIN, 0};
        if (::poll(fds.data(), n, -1) < 0) {
            if (errno == EINTR) continue;
            break;
        }
        for (nfds_t k = 0; k < n; ++k) {
            const pollfd& p = fds[k];
            if (p.revents == 0) continue;
            if (p.fd == to_child) {
                const ssize_t w = ::write(to_child, input.data() + written, input.size() - written);
                if (w > 0) written += static_cast<std::size_t>(w);
                // A child that exits early closes the pipe (EPIPE: SIGPIPE is ignored here).
                if ((w < 0 && errno != EINTR && errno != EAGAIN) || written == input.size()) {
                    ::close(to_child);
                    to_child = -1;
                }
                continue;
            }
            const ssize_t r = ::read(p.fd, buf, sizeof buf);
            if (r < 0 && (errno == EINTR || errno == EAGAIN)) continue;
            if (r <= 0) {
                ::close(p.fd);
                (p.fd == from_out ? from_out : from_err) = -1;
                continue;
            }
            (p.fd == from_out ? out : err).append(buf, static_cast<std::size_t>(r));
        }
    }
    if (to_child >= 0) ::close(to_child);
    return {std::move(out), std::move(err)};
}

}  // namespace

std::string run_python_module(const std::string& module, const std::vector<std::string>& args,
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

    Pipe in, out, err;
    const pid_t pid = ::fork();
    if (pid < 0) throw DataError(what + ": cannot start " + interpreter + ": fork failed");
    if (pid == 0) {  // child: only async-signal-safe calls until exec
        ::dup2(in.fd[0], STDIN_FILENO);
        ::dup2(out.fd[1], STDOUT_FILENO);
        ::dup2(err.fd[1], STDERR_FILENO);
        for (int f : {in.fd[0], in.fd[1], out.fd[0], out.fd[1], err.fd[0], err.fd[1]}) ::close(f);
        if (!pythonpath.empty()) ::setenv("PYTHONPATH", pythonpath.c_str(), 1);
        ::execvp(argv[0], argv.data());
        const std::string msg = "cannot run the Python interpreter '" + interpreter +
                                "': " + std::strerror(errno) + " (set ROUGHSCOPE_PYTHON)\n";
        [[maybe_unused]] const ssize_t n = ::write(STDERR_FILENO, msg.data(), msg.size());
        ::_exit(127);
    }
    const io::ChildProcessGuard guard(pid);
    in.close(0);
    out.close(1);
    err.close(1);

    struct sigaction ignore {
    }, previous{};
    ignore.sa_handler = SIG_IGN;
    ::sigaction(SIGPIPE, &ignore, &previous);
    auto [output, errors] =
        exchange_with_child(std::exchange(in.fd[1], -1), std::exchange(out.fd[0], -1),
                            std::exchange(err.fd[0], -1), input);
    ::sigaction(SIGPIPE, &previous, nullptr);

    int status = 0;
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    const bool ok = WIFEXITED(status) && WEXITSTATUS(status) == 0;
    if (ok) return std::move(output);
    std::string message = last_line(errors);
    if (message.empty())
        message = WIFSIGNALED(status) ? "the Python process was killed by signal " +
                                            std::to_string(WTERMSIG(status))
                                      : "the Python process exited with status " +
                                            std::to_string(WEXITSTATUS(status)) + " and no message";
    throw DataError(what + ": " + message);
}

}  // namespace roughscope::cli
