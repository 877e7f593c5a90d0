// The output sink (output_file.hpp): atomic replace of regular files, direct writes to devices,
// FIFOs and standard output, and the signal-time cleanup of temporary files.
#include "roughscope/io/output_file.hpp"

#include <array>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <random>
#include <utility>

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

#include "roughscope/core/errors.hpp"

namespace roughscope::io {
namespace {

namespace fs = std::filesystem;

constexpr std::size_t kFlushBytes = std::size_t{1} << 20;  // write out once 1 MiB is pending
// A chunk of at least this size arriving with nothing pending is written out as it is.
constexpr std::size_t kWriteThroughBytes = std::size_t{64} << 10;
constexpr int kMaxSymlinks = 40;  // as the kernel's ELOOP limit

// ---------------------------------------------------------------------------------------------
// Pending temporary files, removed by the signal handler. Each slot holds a malloc'ed C string
// or null; the handler only loads the pointers and calls unlink (async-signal-safe).

constexpr std::size_t kCleanupSlots = 64;
std::array<std::atomic<char*>, kCleanupSlots> g_pending{};

int register_in(std::array<std::atomic<char*>, kCleanupSlots>& registry, const std::string& path);

// A full registry leaves the file to be removed on errors, not on signals.
int register_pending(const std::string& path) { return register_in(g_pending, path); }

void unregister_pending(int slot) {
    if (slot < 0) return;
    std::free(g_pending[static_cast<std::size_t>(slot)].exchange(nullptr));
}

// Folders created by an OutputDirectory and not yet kept: removed (rmdir: only when empty) after
// the temporary files, innermost first.
std::array<std::atomic<char*>, kCleanupSlots> g_pending_dirs{};
// The helper process to kill on a signal (ChildProcessGuard), or 0.
std::atomic<pid_t> g_child{0};

int register_in(std::array<std::atomic<char*>, kCleanupSlots>& registry, const std::string& path) {
    char* copy = static_cast<char*>(std::malloc(path.size() + 1));
    if (copy == nullptr) return -1;
    std::memcpy(copy, path.c_str(), path.size() + 1);
    for (std::size_t k = 0; k < kCleanupSlots; ++k) {
        char* expected = nullptr;
        if (registry[k].compare_exchange_strong(expected, copy)) return static_cast<int>(k);
    }
    std::free(copy);
    return -1;
}

extern "C" void remove_pending_and_reraise(int signal_number) {
    const int saved_errno = errno;
    if (const pid_t child = g_child.load(); child > 0) ::kill(child, SIGKILL);
    for (auto& slot : g_pending) {
        const char* path = slot.load();
        if (path != nullptr) ::unlink(path);
    }
    for (std::size_t k = kCleanupSlots; k-- > 0;) {
        const char* path = g_pending_dirs[k].load();
        if (path != nullptr) ::rmdir(path);
    }
    errno = saved_errno;
    // SA_RESETHAND restored the default action; the re-raised signal is delivered on return.
    ::raise(signal_number);
}

// ---------------------------------------------------------------------------------------------
// Files

std::string errno_text(int error) { return std::strerror(error); }

// Writes all of `data` to `fd`; returns 0 or the errno of the failure.
int write_all(int fd, std::string_view data) {
    while (!data.empty()) {
        const ssize_t n = ::write(fd, data.data(), data.size());
        if (n < 0) {
            if (errno == EINTR) continue;
            return errno;
        }
        data.remove_prefix(static_cast<std::size_t>(n));
    }
    return 0;
}

std::string parent_of(const std::string& path) {
    const fs::path p(path);
    return p.has_parent_path() ? p.parent_path().string() : std::string(".");
}

// Follows a chain of symbolic links to the path that is finally written (which may not exist
// yet: a dangling link creates its target). Throws via `fail` on a loop.
template <class Fail>
std::string resolve_links(const std::string& path, struct stat& st, bool& exists, Fail fail) {
    std::string current = path;
    for (int hops = 0;; ++hops) {
        if (::lstat(current.c_str(), &st) != 0) {
            if (errno != ENOENT) fail(errno_text(errno));
            exists = false;
            return current;
        }
        if (!S_ISLNK(st.st_mode)) {
            exists = true;
            return current;
        }
        if (hops >= kMaxSymlinks) fail("too many levels of symbolic links");
        std::string link(static_cast<std::size_t>(st.st_size > 0 ? st.st_size : 255) + 1, '\0');
        const ssize_t n = ::readlink(current.c_str(), link.data(), link.size());
        if (n < 0) fail(errno_text(errno));
        link.resize(static_cast<std::size_t>(n));
        const fs::path target(link);
        current = target.is_absolute() ? link : (fs::path(parent_of(current)) / target).string();
    }
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// OutputFile

OutputFile::OutputFile(const fs::path& path) : name_(path.string()) {
    const auto fail_open = [&](const std::string& reason) -> void {
        throw DataError("cannot write " + name_ + ": " + reason);
    };
    if (name_ == "-") {
        mode_ = Mode::Stdout;
        return;
    }
    if (name_.empty()) fail_open("empty file name");
    if (path.filename().empty() || path.filename() == "." || path.filename() == "..")
        fail_open("not a file name");

    struct stat st {};
    bool exists = false;
    const std::string target = resolve_links(name_, st, exists, fail_open);
    if (exists && S_ISDIR(st.st_mode)) fail_open("is a directory");

    if (exists && (S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode) || S_ISFIFO(st.st_mode) ||
                   S_ISSOCK(st.st_mode))) {
        if (S_ISSOCK(st.st_mode)) fail_open("is a socket");
        // Opening a FIFO waits for its reader, as a shell redirection does.
        int fd = -1;
        do {
            fd = ::open(target.c_str(), O_WRONLY | O_NOCTTY | O_CLOEXEC);
        } while (fd < 0 && errno == EINTR);
        if (fd < 0) fail_open(errno_text(errno));
        fd_ = fd;
        mode_ = Mode::Direct;
        return;
    }

    const std::string dir = parent_of(target);
    struct stat dir_st {};
    if (::stat(dir.c_str(), &dir_st) != 0 || !S_ISDIR(dir_st.st_mode))
        fail_open("directory " + dir + " does not exist");
    if (exists) {
        // Never replace what the user could not have written in place.
        if (::faccessat(AT_FDCWD, target.c_str(), W_OK, AT_EACCESS) != 0) {
            const int error = errno;
            fail_open(error == EACCES || error == EPERM
                          ? "permission denied (the file is not writable by this user; it is left "
                            "unchanged)"
                          : errno_text(error));
        }
    }

    // A fresh temporary file beside the target: ".<name>.tmp-<pid>-<random>".
    std::random_device rd;
    const std::string base = fs::path(target).filename().string();
    int fd = -1;
    std::string temp;
    for (int attempt = 0; attempt < 100 && fd < 0; ++attempt) {
        std::string tmp_name(1, '.');  // appended (GCC 12 -Wrestrict on "." + std::string&&)
        tmp_name.append(base)
            .append(".tmp-")
            .append(std::to_string(::getpid()))
            .append("-")
            .append(std::to_string(rd()));
        temp = (fs::path(dir) / tmp_name).string();
        // 0666 minus the umask for a new file, as any program creating it would.
        fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, exists ? 0600 : 0666);
        if (fd < 0 && errno != EEXIST && errno != EINTR)
            fail_open("cannot create a temporary file in " + dir + ": " + errno_text(errno));
    }
    if (fd < 0) fail_open("cannot create a temporary file in " + dir);
    fd_ = fd;
    temp_ = temp;
    target_ = target;
    mode_ = Mode::Replace;
    cleanup_slot_ = register_pending(temp_);
    if (exists) {
        // Keep the owner (only root may give a file away) and then the permission bits (chown
        // clears set-id bits).
        if (::geteuid() == 0 && ::fchown(fd_, st.st_uid, st.st_gid) != 0)
            fail("cannot keep the owner: " + errno_text(errno));
        if (::fchmod(fd_, st.st_mode & 07777) != 0)
            fail("cannot keep the permissions: " + errno_text(errno));
    }
}

OutputFile OutputFile::standard_output() { return OutputFile(fs::path("-")); }

OutputFile::~OutputFile() { abort(); }

OutputFile::OutputFile(OutputFile&& other) noexcept
    : mode_(std::exchange(other.mode_, std::nullopt)),
      name_(std::move(other.name_)),
      target_(std::move(other.target_)),
      temp_(std::move(other.temp_)),
      fd_(std::exchange(other.fd_, -1)),
      cleanup_slot_(std::exchange(other.cleanup_slot_, -1)),
      buffer_(std::move(other.buffer_)) {}

OutputFile& OutputFile::operator=(OutputFile&& other) noexcept {
    if (this != &other) {
        abort();
        mode_ = std::exchange(other.mode_, std::nullopt);
        name_ = std::move(other.name_);
        target_ = std::move(other.target_);
        temp_ = std::move(other.temp_);
        fd_ = std::exchange(other.fd_, -1);
        cleanup_slot_ = std::exchange(other.cleanup_slot_, -1);
        buffer_ = std::move(other.buffer_);
    }
    return *this;
}

void OutputFile::abort() noexcept {
    if (!mode_) return;
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
    if (*mode_ == Mode::Replace) {
        ::unlink(temp_.c_str());
        unregister_pending(cleanup_slot_);
        cleanup_slot_ = -1;
    }
    buffer_.clear();
    mode_.reset();
}

void OutputFile::fail(const std::string& reason) {
    const bool to_stdout = mode_ == Mode::Stdout;
    abort();
    if (to_stdout) throw DataError("cannot write to standard output: " + reason);
    throw DataError("cannot write " + name_ + ": " + reason);
}

void OutputFile::write_out(std::string_view bytes) {
    if (*mode_ == Mode::Stdout) {
        std::cout.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
        if (!std::cout) fail("write error");
    } else if (const int error = write_all(fd_, bytes); error != 0) {
        fail(errno_text(error));
    }
}

void OutputFile::flush_buffer() {
    if (buffer_.empty()) return;
    write_out(buffer_);
    buffer_.clear();
}

void OutputFile::write(std::string_view chunk) {
    if (!mode_) throw DataError("cannot write " + name_ + ": the output is not open");
    if (buffer_.empty() && chunk.size() >= kWriteThroughBytes) {
        write_out(chunk);  // nothing gained by copying it into the buffer first
        return;
    }
    buffer_.append(chunk);
    if (buffer_.size() >= kFlushBytes) flush_buffer();
}

void OutputFile::flush() {
    if (!mode_) throw DataError("cannot write " + name_ + ": the output is not open");
    flush_buffer();
}

void OutputFile::commit() {
    if (!mode_) throw DataError("cannot write " + name_ + ": the output is not open");
    flush_buffer();
    switch (*mode_) {
        case Mode::Stdout:
            std::cout.flush();
            if (!std::cout) fail("write error");
            break;
        case Mode::Direct:
            if (::close(std::exchange(fd_, -1)) != 0) fail(errno_text(errno));
            break;
        case Mode::Replace:
            if (::close(std::exchange(fd_, -1)) != 0) fail(errno_text(errno));
            if (::rename(temp_.c_str(), target_.c_str()) != 0) fail(errno_text(errno));
            unregister_pending(cleanup_slot_);
            cleanup_slot_ = -1;
            break;
    }
    mode_.reset();
}

// ---------------------------------------------------------------------------------------------
// Whole-content helpers

void write_file_atomic(const fs::path& path, std::string_view content) {
    OutputFile out(path);
    out.write(content);
    out.commit();
}

OutputFile open_output(const std::optional<fs::path>& path) {
    return path ? OutputFile(*path) : OutputFile::standard_output();
}

void write_output(const std::optional<fs::path>& path, std::string_view content) {
    OutputFile out = open_output(path);
    out.write(content);
    out.commit();
}

// ---------------------------------------------------------------------------------------------
// OutputDirectory, ChildProcessGuard

OutputDirectory::OutputDirectory(const fs::path& path, const std::string& what) : path_(path) {
    const auto fail = [&](const std::string& reason) {
        remove_created();
        throw DataError("cannot write " + (what.empty() ? std::string() : what + " ") +
                        path.string() + ": " + reason);
    };
    if (path.empty()) fail("empty folder name");
    // The missing components, outermost first (stat follows symbolic links: a link to a folder
    // is written through).
    std::vector<fs::path> missing;
    for (fs::path p = path; !p.empty(); p = p.parent_path()) {
        struct stat st {};
        if (::stat(p.c_str(), &st) == 0) {
            if (!S_ISDIR(st.st_mode))
                fail(p == path ? std::string("is not a folder") : p.string() + " is not a folder");
            break;
        }
        if (errno != ENOENT) fail(errno_text(errno));
        missing.push_back(p);
        if (p == p.parent_path()) break;
    }
    for (auto it = missing.rbegin(); it != missing.rend(); ++it) {
        if (::mkdir(it->c_str(), 0777) != 0 && errno != EEXIST)
            fail("cannot create " + it->string() + ": " + errno_text(errno));
        created_.push_back(it->string());
        cleanup_slots_.push_back(register_in(g_pending_dirs, it->string()));
    }
}

OutputDirectory::~OutputDirectory() { remove_created(); }

OutputDirectory::OutputDirectory(OutputDirectory&& other) noexcept
    : path_(std::move(other.path_)),
      created_(std::exchange(other.created_, {})),
      cleanup_slots_(std::exchange(other.cleanup_slots_, {})) {}

OutputDirectory& OutputDirectory::operator=(OutputDirectory&& other) noexcept {
    if (this != &other) {
        remove_created();
        path_ = std::move(other.path_);
        created_ = std::exchange(other.created_, {});
        cleanup_slots_ = std::exchange(other.cleanup_slots_, {});
    }
    return *this;
}

void OutputDirectory::keep() noexcept {
    for (const int slot : cleanup_slots_)
        if (slot >= 0) std::free(g_pending_dirs[static_cast<std::size_t>(slot)].exchange(nullptr));
    cleanup_slots_.clear();
    created_.clear();
}

void OutputDirectory::remove_created() noexcept {
    for (auto it = created_.rbegin(); it != created_.rend(); ++it) ::rmdir(it->c_str());
    created_.clear();
    keep();
}

ChildProcessGuard::ChildProcessGuard(int pid) noexcept { g_child.store(pid); }
ChildProcessGuard::~ChildProcessGuard() { g_child.store(0); }

void install_output_cleanup_handlers() {
    for (const int signal_number : {SIGINT, SIGTERM, SIGHUP, SIGQUIT}) {
        struct sigaction old_action {};
        if (::sigaction(signal_number, nullptr, &old_action) != 0) continue;
        if (old_action.sa_handler == SIG_IGN) continue;  // e.g. nohup: keep ignoring
        struct sigaction action {};
        action.sa_handler = remove_pending_and_reraise;
        sigemptyset(&action.sa_mask);
        action.sa_flags = SA_RESETHAND;
        ::sigaction(signal_number, &action, nullptr);
    }
}

}  // namespace roughscope::io
