// The memory budget (core/memory.hpp): half the physical memory unless ROUGHSCOPE_MEMORY_LIMIT_GB
// says otherwise, and check_memory's message.
#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <unistd.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/memory.hpp"

namespace {

using namespace roughscope;

// Sets the variable for the test's scope, restoring the previous value.
class ScopedEnv {
  public:
    ScopedEnv(const char* name, const char* value) : name_(name) {
        if (const char* old = std::getenv(name)) old_ = old;
        if (value != nullptr)
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
    ScopedEnv(const ScopedEnv&) = delete;
    ScopedEnv& operator=(const ScopedEnv&) = delete;

  private:
    const char* name_;
    std::optional<std::string> old_;
};

std::string message_of(double bytes) {
    try {
        check_memory(bytes, "the thing", "give less");
    } catch (const InvalidArgument& e) {
        return e.what();
    }
    return "no error";
}

TEST(MemoryBudget, DefaultIsHalfThePhysicalMemory) {
    const ScopedEnv env("ROUGHSCOPE_MEMORY_LIMIT_GB", nullptr);
    // Independently of sysconf: the kernel's MemTotal (kB), and a cgroup limit when lower.
    std::ifstream meminfo("/proc/meminfo");
    std::string key;
    double total_kb = 0.0;
    while (meminfo >> key) {
        if (key == "MemTotal:") {
            meminfo >> total_kb;
            break;
        }
        meminfo.ignore(1 << 10, '\n');
    }
    if (total_kb == 0.0) GTEST_SKIP() << "no /proc/meminfo";
    double physical = total_kb * 1024.0;
    std::ifstream cgroup("/sys/fs/cgroup/memory.max");
    std::string limit;
    if (cgroup >> limit && limit != "max") physical = std::min(physical, std::stod(limit));
    const MemoryBudget b = memory_budget();
    // MemTotal excludes the kernel's reserved memory: a few per cent below the pages sysconf
    // counts.
    EXPECT_NEAR(b.bytes, 0.5 * physical, 0.05 * physical);
    EXPECT_EQ(b.source, "half the physical memory");
}

TEST(MemoryBudget, TheVariableSetsIt) {
    const ScopedEnv env("ROUGHSCOPE_MEMORY_LIMIT_GB", "0.25");
    EXPECT_DOUBLE_EQ(memory_budget().bytes, 2.5e8);
    EXPECT_EQ(message_of(2.4e8), "no error");
    const std::string m = message_of(3.4e9);
    EXPECT_EQ(m,
              "the thing needs about 3.4 GB of memory, above the limit of 0.25 GB "
              "(ROUGHSCOPE_MEMORY_LIMIT_GB); give less");
}

TEST(MemoryBudget, ABadVariableIsNamed) {
    for (const char* bad : {"abc", "-1", "0", "nan", "inf", "1e400"}) {
        const ScopedEnv env("ROUGHSCOPE_MEMORY_LIMIT_GB", bad);
        try {
            (void)memory_budget();
            ADD_FAILURE() << bad << ": no error";
        } catch (const InvalidArgument& e) {
            EXPECT_NE(std::string(e.what()).find("ROUGHSCOPE_MEMORY_LIMIT_GB"), std::string::npos)
                << e.what();
        }
    }
}

TEST(MemoryBudget, GigabytesAreShownWithTheirDigits) {
    EXPECT_EQ(format_gigabytes(150e9), "150 GB");
    EXPECT_EQ(format_gigabytes(11.52e9), "11.5 GB");
    EXPECT_EQ(format_gigabytes(0.134e9), "0.134 GB");
    EXPECT_EQ(format_gigabytes(3.4e6), "0.0034 GB");
}

}  // namespace
