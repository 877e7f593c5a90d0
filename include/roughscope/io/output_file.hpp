// Writing outputs without clobbering anything (DEVELOPERS.md: "nothing written half-way").
//
// OutputFile is the one output sink of the project: open it on a path (or "-" for standard
// output), write() chunks as they are produced, then commit(). What happens depends on what the
// path names:
//  * a regular file, existing or new: the chunks go to a temporary file in the target's
//    directory, which commit() renames over the target. The existing file's permission bits are
//    kept (and its owner when running as root); a new file gets 0666 minus the umask. On any
//    failure, or when the OutputFile is destroyed without commit(), the temporary file is removed
//    and the target is untouched;
//  * a symbolic link: the link chain is followed and its final target is replaced as above (the
//    link stays a link);
//  * a character or block device, a FIFO, or "-" (standard output): written directly, no
//    temporary file and no rename (a device stays a device; a FIFO's reader gets the data);
//  * an existing file that the calling user may not write (e.g. mode 0444 for a non-root user),
//    a directory, or a missing directory: DataError "cannot write <path>: <reason>" and nothing
//    changed.
// Temporary files are registered for install_output_cleanup_handlers(): a program that installs
// them (the CLI does) removes its pending temporary files when killed by SIGINT, SIGTERM, SIGHUP
// or SIGQUIT, then dies of the signal as usual. The same handlers remove the folders an
// OutputDirectory created and not yet kept (when empty) and kill the helper process registered
// with ChildProcessGuard, so that a signal leaves nothing new behind.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace roughscope::io {

class OutputFile {
  public:
    // How the output reaches its destination.
    enum class Mode {
        Replace,  // temporary file renamed over the (final) target on commit
        Direct,   // device or FIFO, opened and written in place
        Stdout,   // standard output
    };

    OutputFile() = default;  // not open
    // Opens `path` ("-" for standard output) as described above. Throws DataError
    // "cannot write <path>: <reason>" when the destination cannot be written.
    explicit OutputFile(const std::filesystem::path& path);
    // Standard output.
    static OutputFile standard_output();

    // Aborts (see abort()) unless commit() was called.
    ~OutputFile();
    OutputFile(OutputFile&& other) noexcept;
    OutputFile& operator=(OutputFile&& other) noexcept;
    OutputFile(const OutputFile&) = delete;
    OutputFile& operator=(const OutputFile&) = delete;

    // Appends `chunk` (buffered; large outputs are written out as they grow, and a chunk of
    // 64 KiB or more with nothing pending goes out without a copy). Throws DataError on a write
    // error (the output is then aborted).
    void write(std::string_view chunk);
    // Writes out everything and makes the output visible (rename for Mode::Replace). Throws
    // DataError on failure, after removing the temporary file.
    void commit();
    // Writes out what is pending without committing: the content so far can be read back from
    // temporary_path() (Mode::Replace), e.g. by a helper process, before it is made visible.
    void flush();
    // Mode::Replace: the temporary file the content goes to until commit(); else empty.
    const std::string& temporary_path() const { return temp_; }
    // Discards the output: removes the temporary file (Mode::Replace) or stops writing (Direct,
    // Stdout; what was already written stays). Never throws.
    void abort() noexcept;

    bool is_open() const { return mode_.has_value(); }
    std::optional<Mode> mode() const { return mode_; }
    // The path as given ("-" or "standard output" for stdout).
    const std::string& name() const { return name_; }

  private:
    void flush_buffer();
    void write_out(std::string_view bytes);  // to the destination, unbuffered
    [[noreturn]] void fail(const std::string& reason);

    std::optional<Mode> mode_;
    std::string name_;       // as given, for messages
    std::string target_;     // Mode::Replace: the final target (symlinks resolved)
    std::string temp_;       // Mode::Replace: the temporary file
    int fd_ = -1;            // Replace, Direct: the open descriptor
    int cleanup_slot_ = -1;  // Replace: slot in the signal-cleanup registry
    std::string buffer_;     // pending bytes
};

// Writes `content` to `path` through OutputFile (atomic replace of a regular file, direct write
// to a device/FIFO/"-"). Throws DataError("cannot write <path>: <reason>") with nothing changed.
void write_file_atomic(const std::filesystem::path& path, std::string_view content);

// Writes `content` to `path` when given (write_file_atomic), else to standard output (DataError
// "cannot write to standard output" if that fails).
void write_output(const std::optional<std::filesystem::path>& path, std::string_view content);

// Opens `path` when given, else standard output.
OutputFile open_output(const std::optional<std::filesystem::path>& path);

// The folder outputs go into, created (with its missing parents) when it does not exist. The
// folders it created are removed again (only while empty: never a file or folder it did not
// create) when it is destroyed without keep(), or when the program is killed by a signal handled
// by install_output_cleanup_handlers(). An existing folder (or a symbolic link to one) is used as
// it is; a path that exists and is not a folder is DataError "cannot write <what> <path>: is not a
// folder", as is a folder that cannot be created. `what` names the output in messages (e.g.
// "--maps").
class OutputDirectory {
  public:
    OutputDirectory() = default;
    OutputDirectory(const std::filesystem::path& path, const std::string& what);
    ~OutputDirectory();
    OutputDirectory(OutputDirectory&& other) noexcept;
    OutputDirectory& operator=(OutputDirectory&& other) noexcept;
    OutputDirectory(const OutputDirectory&) = delete;
    OutputDirectory& operator=(const OutputDirectory&) = delete;

    // The folders created stay (the outputs in them were committed).
    void keep() noexcept;
    const std::filesystem::path& path() const { return path_; }

  private:
    void remove_created() noexcept;
    std::filesystem::path path_;
    std::vector<std::string> created_;  // outermost first
    std::vector<int> cleanup_slots_;
};

// While alive, a signal handled by install_output_cleanup_handlers() also kills (SIGKILL) the
// process `pid` (a helper the program started and waits for), before the program dies itself.
class ChildProcessGuard {
  public:
    explicit ChildProcessGuard(int pid) noexcept;
    ~ChildProcessGuard();
    ChildProcessGuard(const ChildProcessGuard&) = delete;
    ChildProcessGuard& operator=(const ChildProcessGuard&) = delete;
};

// Installs handlers for SIGINT, SIGTERM, SIGHUP and SIGQUIT (those not ignored) that remove the
// pending temporary files of every open OutputFile (async-signal-safe: unlink only), restore the
// default action and re-raise the signal. For programs (the CLI's main), not for libraries.
void install_output_cleanup_handlers();

}  // namespace roughscope::io
