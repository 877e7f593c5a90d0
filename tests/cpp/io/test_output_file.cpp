// The output sink (roughscope/io/output_file.hpp): what each kind of destination becomes.
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <unistd.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/io/output_file.hpp"
#include "test_files.hpp"

using namespace roughscope;
namespace fs = std::filesystem;

namespace {

using roughscope::testing::fresh_dir;
using roughscope::testing::slurp;

void put(const fs::path& p, const std::string& text) { std::ofstream(p, std::ios::binary) << text; }

std::size_t entries(const fs::path& d) {
    std::size_t n = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(d)) ++n;
    return n;
}

mode_t mode_of(const fs::path& p) {
    struct stat st {};
    EXPECT_EQ(::lstat(p.c_str(), &st), 0);
    return st.st_mode;
}

}  // namespace

TEST(OutputSink, ReplacesARegularFileKeepingItsMode) {
    const fs::path d = fresh_dir("mode");
    const fs::path f = d / "out.csv";
    put(f, "old\n");
    ASSERT_EQ(::chmod(f.c_str(), 0600), 0);
    io::write_file_atomic(f, "new\n");
    EXPECT_EQ(slurp(f), "new\n");
    EXPECT_EQ(mode_of(f) & 07777, 0600u);
    EXPECT_TRUE(S_ISREG(mode_of(f)));
    EXPECT_EQ(entries(d), 1u);  // no temporary left
    fs::remove_all(d);
}

// Chunks of 64 KiB or more with nothing pending go out without the buffer; mixed with small
// ones (pending, then flushed first) the bytes stay in order.
TEST(OutputSink, LargeAndSmallChunksKeepTheirOrder) {
    const fs::path d = fresh_dir("order");
    const fs::path f = d / "mixed.txt";
    std::string expected;
    {
        io::OutputFile out(f);
        char letter = 'a';
        for (const std::size_t size : {10U, 70000U, 70000U, 5U, 200000U, 65536U, 3U, 2000000U}) {
            const std::string chunk(size, letter++);
            out.write(chunk);
            expected += chunk;
        }
        out.commit();
    }
    EXPECT_EQ(slurp(f), expected);
    fs::remove_all(d);
}

TEST(OutputSink, NewFileGetsTheUmaskMode) {
    const fs::path d = fresh_dir("umask");
    const mode_t mask = ::umask(022);
    io::write_file_atomic(d / "a.txt", "x");
    ::umask(mask);
    EXPECT_EQ(mode_of(d / "a.txt") & 07777, 0644u);
    fs::remove_all(d);
}

TEST(OutputSink, StreamsChunksAndChangesNothingBeforeCommit) {
    const fs::path d = fresh_dir("stream");
    const fs::path f = d / "big.txt";
    put(f, "old");
    const std::string chunk(4096, 'x');
    {
        io::OutputFile out(f);
        EXPECT_EQ(out.mode(), io::OutputFile::Mode::Replace);
        for (int k = 0; k < 1000; ++k) out.write(chunk);  // 4 MB: written out as it grows
        EXPECT_EQ(slurp(f), "old");
        EXPECT_EQ(entries(d), 2u);  // the target and the temporary file
        out.commit();
    }
    EXPECT_EQ(fs::file_size(f), 4096u * 1000u);
    EXPECT_EQ(entries(d), 1u);
    fs::remove_all(d);
}

TEST(OutputSink, AbortLeavesTheOldFileByteIdentical) {
    const fs::path d = fresh_dir("abort");
    const fs::path f = d / "out.json";
    put(f, "precious");
    {
        io::OutputFile out(f);
        out.write(std::string(3u << 20, 'y'));  // more than the buffer: partly on disk
    }                                           // destroyed without commit
    EXPECT_EQ(slurp(f), "precious");
    EXPECT_EQ(entries(d), 1u);
    fs::remove_all(d);
}

TEST(OutputSink, WritesThroughSymlinkChains) {
    const fs::path d = fresh_dir("links");
    fs::create_directories(d / "real");
    put(d / "real" / "target.txt", "old");
    ASSERT_EQ(::chmod((d / "real" / "target.txt").c_str(), 0640), 0);
    fs::create_symlink("real/target.txt", d / "link1");  // relative
    fs::create_symlink(d / "link1", d / "link2");        // absolute, to a link
    io::write_file_atomic(d / "link2", "new");
    EXPECT_TRUE(fs::is_symlink(d / "link1"));
    EXPECT_TRUE(fs::is_symlink(d / "link2"));
    EXPECT_EQ(slurp(d / "real" / "target.txt"), "new");
    EXPECT_EQ(mode_of(d / "real" / "target.txt") & 07777, 0640u);
    EXPECT_EQ(entries(d / "real"), 1u);
    // A dangling link creates its target.
    fs::create_symlink("real/created.txt", d / "dangling");
    io::write_file_atomic(d / "dangling", "made");
    EXPECT_TRUE(fs::is_symlink(d / "dangling"));
    EXPECT_EQ(slurp(d / "real" / "created.txt"), "made");
    fs::remove_all(d);
}

TEST(OutputSink, SymlinkLoopIsADataError) {
    const fs::path d = fresh_dir("loop");
    fs::create_symlink("b", d / "a");
    fs::create_symlink("a", d / "b");
    try {
        io::write_file_atomic(d / "a", "x");
        FAIL() << "no exception";
    } catch (const DataError& e) {
        EXPECT_NE(std::string(e.what()).find("symbolic links"), std::string::npos) << e.what();
    }
    EXPECT_TRUE(fs::is_symlink(d / "a"));
    EXPECT_EQ(entries(d), 2u);
    fs::remove_all(d);
}

TEST(OutputSink, WritesAFifoDirectly) {
    const fs::path d = fresh_dir("fifo");
    const fs::path fifo = d / "pipe";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    std::string received;
    std::thread reader([&] { received = slurp(fifo); });
    {
        io::OutputFile out(fifo);  // waits for the reader to open its end
        EXPECT_EQ(out.mode(), io::OutputFile::Mode::Direct);
        out.write("through the pipe\n");
        out.commit();
    }
    reader.join();
    EXPECT_EQ(received, "through the pipe\n");
    EXPECT_TRUE(S_ISFIFO(mode_of(fifo)));
    EXPECT_EQ(entries(d), 1u);
    fs::remove_all(d);
}

TEST(OutputSink, CharacterDeviceStaysADevice) {
    if (::geteuid() != 0) GTEST_SKIP() << "mknod of a character device needs root";
    const fs::path d = fresh_dir("device");
    const fs::path dev = d / "null";
    ASSERT_EQ(::mknod(dev.c_str(), S_IFCHR | 0666, makedev(1, 3)), 0);  // a copy of /dev/null
    io::write_file_atomic(dev, "discarded");
    EXPECT_TRUE(S_ISCHR(mode_of(dev)));
    EXPECT_EQ(entries(d), 1u);
    fs::remove_all(d);
}

TEST(OutputSink, DashIsStandardOutput) {
    io::OutputFile out(fs::path("-"));
    EXPECT_EQ(out.mode(), io::OutputFile::Mode::Stdout);
    ::testing::internal::CaptureStdout();
    out.write("to stdout\n");
    out.commit();
    EXPECT_EQ(::testing::internal::GetCapturedStdout(), "to stdout\n");
}

TEST(OutputSink, ReadOnlyFileOfAnotherUserIsRefused) {
    if (::geteuid() == 0) GTEST_SKIP() << "root may write any file (the CLI test runs as nobody)";
    const fs::path d = fresh_dir("readonly");
    const fs::path f = d / "ro.txt";
    put(f, "keep");
    ASSERT_EQ(::chmod(f.c_str(), 0444), 0);
    try {
        io::write_file_atomic(f, "clobbered");
        FAIL() << "no exception";
    } catch (const DataError& e) {
        EXPECT_NE(std::string(e.what()).find("permission denied"), std::string::npos) << e.what();
    }
    EXPECT_EQ(slurp(f), "keep");
    EXPECT_EQ(mode_of(f) & 07777, 0444u);
    EXPECT_EQ(entries(d), 1u);
    fs::remove_all(d);
}

TEST(OutputSink, DirectoriesAndMissingFoldersAreDataErrors) {
    const fs::path d = fresh_dir("errors");
    EXPECT_THROW(io::OutputFile{d}, DataError);
    EXPECT_THROW(io::OutputFile(d / "no" / "such.txt"), DataError);
    EXPECT_THROW(io::OutputFile(fs::path("")), DataError);
    io::OutputFile closed;
    EXPECT_FALSE(closed.is_open());
    EXPECT_THROW(closed.write("x"), DataError);
    EXPECT_TRUE(fs::is_empty(d));
    fs::remove_all(d);
}

TEST(OutputSink, SignalRemovesThePendingTemporaryFile) {
    const fs::path d = fresh_dir("signal");
    const fs::path f = d / "out.txt";
    put(f, "old");
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
        io::install_output_cleanup_handlers();
        io::OutputFile out(f);
        out.write(std::string(2u << 20, 'z'));
        ::raise(SIGTERM);
        ::_exit(0);  // not reached: the handler re-raises with the default action
    }
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFSIGNALED(status)) << "status " << status;
    EXPECT_EQ(WTERMSIG(status), SIGTERM);
    EXPECT_EQ(slurp(f), "old");
    EXPECT_EQ(entries(d), 1u);  // the temporary file is gone
    fs::remove_all(d);
}

TEST(OutputSink, WithoutTheHandlerASignalLeavesTheTemporaryFile) {
    // The failure twin of the test above: the cleanup is the handler's doing.
    const fs::path d = fresh_dir("nosignal");
    const fs::path f = d / "out.txt";
    put(f, "old");
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
        ::signal(SIGTERM, SIG_DFL);
        io::OutputFile out(f);
        out.write(std::string(2u << 20, 'z'));
        ::raise(SIGTERM);
        ::_exit(0);
    }
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFSIGNALED(status));
    EXPECT_EQ(slurp(f), "old");
    EXPECT_EQ(entries(d), 2u);
    fs::remove_all(d);
}

// ---------------------------------------------------------------------------------------------
// OutputDirectory: the folders it makes go again unless kept; what was there is never touched.

TEST(OutputFolder, CreatedFoldersAreRemovedUnlessKept) {
    const fs::path d = fresh_dir("folder");
    {
        io::OutputDirectory out(d / "a" / "b" / "c", "--maps");
        EXPECT_TRUE(fs::is_directory(d / "a" / "b" / "c"));
    }
    EXPECT_EQ(entries(d), 0u);
    {
        io::OutputDirectory out(d / "a" / "b", "--maps");
        out.keep();
    }
    EXPECT_TRUE(fs::is_directory(d / "a" / "b"));
    fs::remove_all(d);
}

TEST(OutputFolder, AnExistingFolderAndItsFilesAreLeftAsTheyWere) {
    const fs::path d = fresh_dir("folder_existing");
    put(d / "photo.png", "keep");
    fs::create_directory(d / "sub");
    { io::OutputDirectory out(d, "--report"); }  // not kept: still nothing removed
    EXPECT_EQ(slurp(d / "photo.png"), "keep");
    EXPECT_TRUE(fs::is_directory(d / "sub"));
    // A created folder that is no longer empty stays (only empty folders are removed).
    {
        io::OutputDirectory out(d / "new", "--report");
        put(d / "new" / "user.txt", "x");
    }
    EXPECT_EQ(slurp(d / "new" / "user.txt"), "x");
    fs::remove_all(d);
}

TEST(OutputFolder, ASymlinkToAFolderIsWrittenThroughAndAFileIsRefused) {
    const fs::path d = fresh_dir("folder_link");
    fs::create_directory(d / "real");
    fs::create_directory_symlink(d / "real", d / "link");
    {
        io::OutputDirectory out(d / "link", "--report");
        out.keep();
    }
    EXPECT_TRUE(fs::is_symlink(d / "link"));
    put(d / "file", "keep");
    try {
        io::OutputDirectory out(d / "file", "--report");
        FAIL() << "a file accepted as a folder";
    } catch (const DataError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("--report"), std::string::npos) << what;
        EXPECT_NE(what.find((d / "file").string()), std::string::npos) << what;
        EXPECT_NE(what.find("not a folder"), std::string::npos) << what;
    }
    EXPECT_THROW(io::OutputDirectory(d / "file" / "sub", "--maps"), DataError);
    EXPECT_EQ(slurp(d / "file"), "keep");
    fs::remove_all(d);
}

TEST(OutputFolder, ASignalRemovesTheCreatedFoldersAndKillsTheHelperProcess) {
    const fs::path d = fresh_dir("folder_signal");
    int ready[2];
    ASSERT_EQ(::pipe(ready), 0);
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
        io::install_output_cleanup_handlers();
        io::OutputDirectory folder(d / "x" / "y", "--maps");
        io::OutputFile out(d / "x" / "y" / "layer.npy");
        out.write("data");
        const pid_t helper = ::fork();
        if (helper == 0) {
            ::pause();
            ::_exit(0);
        }
        const io::ChildProcessGuard guard(helper);
        [[maybe_unused]] const ssize_t n = ::write(ready[1], &helper, sizeof helper);
        ::pause();  // SIGTERM from the test
        ::_exit(0);
    }
    ::close(ready[1]);
    pid_t helper = 0;
    ASSERT_EQ(::read(ready[0], &helper, sizeof helper), static_cast<ssize_t>(sizeof helper));
    ::close(ready[0]);
    ASSERT_EQ(::kill(child, SIGTERM), 0);
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFSIGNALED(status));
    EXPECT_EQ(entries(d), 0u);  // the temporary file and both folders are gone
    // The helper (now a child of init) was killed: it is gone or a zombie.
    bool gone = false;
    for (int k = 0; k < 200 && !gone; ++k) {
        std::ifstream stat_file("/proc/" + std::to_string(helper) + "/stat");
        std::string text;
        std::getline(stat_file, text);
        gone = !stat_file || text.find(") Z") != std::string::npos;
        if (!gone) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    EXPECT_TRUE(gone);
    if (!gone) ::kill(helper, SIGKILL);
    fs::remove_all(d);
}
