// Atomic output files and the reference-data locator (io/output_file.hpp, io/data_locator.hpp).
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/io/data_locator.hpp"
#include "roughscope/io/output_file.hpp"
#include "shared_data.hpp"
#include "test_files.hpp"

using namespace roughscope;
namespace fs = std::filesystem;

namespace {

using roughscope::testing::fresh_dir;
using roughscope::testing::slurp;

// Sets an environment variable for one scope, restoring the previous value.
class ScopedEnv {
  public:
    ScopedEnv(const char* name, const char* value) : name_(name) {
        if (const char* old = std::getenv(name)) old_ = old;
        if (value)
            ::setenv(name, value, 1);
        else
            ::unsetenv(name);
    }
    ~ScopedEnv() {
        if (old_)
            ::setenv(name_, old_->c_str(), 1);
        else
            ::unsetenv(name_);
    }

  private:
    const char* name_;
    std::optional<std::string> old_;
};

// Sets the current directory for one scope.
class ScopedCwd {
  public:
    explicit ScopedCwd(const fs::path& dir) : old_(fs::current_path()) { fs::current_path(dir); }
    ~ScopedCwd() { fs::current_path(old_); }

  private:
    fs::path old_;
};

}  // namespace

TEST(OutputFile, WritesAtomicallyAndReplaces) {
    const fs::path d = fresh_dir("out");
    io::write_file_atomic(d / "a.txt", "one");
    io::write_file_atomic(d / "a.txt", "two\n");
    EXPECT_EQ(slurp(d / "a.txt"), "two\n");
    std::size_t files = 0;
    for (const auto& e : fs::directory_iterator(d)) files += e.is_regular_file();
    EXPECT_EQ(files, 1u);  // no temporary left
    fs::remove_all(d);
}

TEST(OutputFile, FailuresLeaveNothingAndNameThePath) {
    const fs::path d = fresh_dir("out_fail");
    try {
        io::write_file_atomic(d / "missing" / "a.txt", "x");
        FAIL() << "no exception";
    } catch (const DataError& e) {
        EXPECT_NE(std::string(e.what()).find("does not exist"), std::string::npos) << e.what();
    }
    EXPECT_THROW(io::write_file_atomic(d, "x"), DataError);  // a directory
    EXPECT_THROW(io::write_file_atomic("", "x"), DataError);
    EXPECT_TRUE(fs::is_empty(d));
    fs::remove_all(d);
}

TEST(DataLocator, EnvironmentVariableWinsAndIsTheOnlyPlace) {
    const fs::path shared = fresh_dir("shared_env");
    fs::create_directories(shared / "reference");
    std::ofstream(shared / "reference" / "paper-tables.json") << "{}";
    fs::create_directories(shared / "data" / "curet");
    std::ofstream(shared / "data" / "curet" / "table.txt") << "";
    {
        ScopedEnv env(io::kSharedDirEnv, shared.c_str());
        EXPECT_EQ(io::shared_dir_candidates(), std::vector<fs::path>{shared});
        EXPECT_EQ(io::paper_tables_path(), shared / "reference" / "paper-tables.json");
        EXPECT_FALSE(io::curet_data_dir().has_value());  // abrdf.dat missing
        std::ofstream(shared / "data" / "curet" / "abrdf.dat") << "";
        EXPECT_EQ(io::curet_data_dir(), shared / "data" / "curet");
        EXPECT_NE(io::shared_search_description("x").find(shared.string()), std::string::npos);
    }
    {
        ScopedEnv env(io::kSharedDirEnv, (shared / "nowhere").c_str());
        EXPECT_FALSE(io::paper_tables_path().has_value());
        EXPECT_FALSE(io::find_shared("reference").has_value());
    }
    fs::remove_all(shared);
}

TEST(DataLocator, SearchesDotDotSharedUpward) {
    ScopedEnv env(io::kSharedDirEnv, nullptr);
    const fs::path root = fresh_dir("upward");
    fs::create_directories(root / "shared" / "reference");
    std::ofstream(root / "shared" / "reference" / "paper-tables.json") << "{}";
    fs::create_directories(root / "project" / "build" / "deep");
    {
        ScopedCwd cwd(root / "project" / "build" / "deep");
        const auto found = io::paper_tables_path();
        ASSERT_TRUE(found.has_value());
        EXPECT_TRUE(fs::equivalent(*found, root / "shared" / "reference" / "paper-tables.json"));
    }
    {
        ScopedCwd cwd(fs::temp_directory_path());  // not found from here...
        const auto none = io::find_shared("reference/no-such-file.json");
        EXPECT_FALSE(none.has_value());
        // ...but from an extra start (the tests' source tree)
        const auto found = io::paper_tables_path({root / "project"});
        ASSERT_TRUE(found.has_value());
    }
    fs::remove_all(root);
}

TEST(DataLocator, RequireFlag) {
    {
        ScopedEnv env(io::kRequireSharedDataEnv, "1");
        EXPECT_TRUE(io::shared_data_required());
    }
    {
        ScopedEnv env(io::kRequireSharedDataEnv, "0");
        EXPECT_FALSE(io::shared_data_required());
    }
    {
        ScopedEnv env(io::kRequireSharedDataEnv, nullptr);
        EXPECT_FALSE(io::shared_data_required());
    }
}

// The project's own reference data, under the tests' rule (skips when absent).
TEST(DataLocator, FindsTheProjectsReferenceData) {
    const auto tables = roughscope::testing::paper_tables();
    ROUGHSCOPE_NEED_SHARED(tables, io::kPaperTablesRelative);
    EXPECT_TRUE(fs::is_regular_file(*tables));
}
