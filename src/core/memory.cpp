// Huge-page hints for large buffers and the memory budget (core/memory.hpp).
#include "roughscope/core/memory.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <string>

#include <unistd.h>

#if defined(__linux__)
#include <sys/mman.h>
#endif

#include "roughscope/core/errors.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/core/text.hpp"

namespace roughscope {

void advise_huge_pages(void* data, std::size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    if (data == nullptr || bytes < kHugePageHintBytes) return;
    constexpr std::size_t kHugePage = std::size_t{2} << 20;
    auto* base = static_cast<char*>(data);
    const std::size_t misalign = reinterpret_cast<std::uintptr_t>(base) % kHugePage;
    const std::size_t skip = misalign == 0 ? 0 : kHugePage - misalign;
    if (bytes > skip + kHugePage)
        (void)madvise(base + skip, (bytes - skip) / kHugePage * kHugePage, MADV_HUGEPAGE);
#else
    (void)data;
    (void)bytes;
#endif
}

namespace {

constexpr const char* kLimitVariable = "ROUGHSCOPE_MEMORY_LIMIT_GB";

// The cgroup (v2) memory limit of this process in bytes, or 0 when there is none or it cannot be
// read ("max").
double cgroup_limit_bytes() {
    std::ifstream in("/sys/fs/cgroup/memory.max");
    std::string text;
    if (!(in >> text) || text == "max") return 0.0;
    char* end = nullptr;
    const double value = std::strtod(text.c_str(), &end);
    return end != nullptr && *end == '\0' && value > 0.0 ? value : 0.0;
}

}  // namespace

MemoryBudget memory_budget() {
    if (const char* text = std::getenv(kLimitVariable); text != nullptr && *text != '\0') {
        std::string reason;
        const std::optional<double> gb = try_parse_number(text, reason);
        if (!gb || !(*gb > 0.0) || !std::isfinite(*gb))
            throw InvalidArgument(concat(kLimitVariable, " = ", quote_input(text),
                                         " is not a memory limit: it must be a number of GB > 0"));
        return {*gb * 1e9, kLimitVariable};
    }
    const long pages = ::sysconf(_SC_PHYS_PAGES);
    const long page = ::sysconf(_SC_PAGESIZE);
    double physical =
        pages > 0 && page > 0 ? static_cast<double>(pages) * static_cast<double>(page) : 0.0;
    const double cgroup = cgroup_limit_bytes();
    if (cgroup > 0.0 && (physical == 0.0 || cgroup < physical)) physical = cgroup;
    if (physical == 0.0) physical = 8e9;  // unknown: as a small machine
    return {0.5 * physical, "half the physical memory"};
}

std::string format_gigabytes(double bytes) {
    const double gb = bytes / 1e9;
    char text[32];
    std::snprintf(text, sizeof text, gb >= 100.0 ? "%.0f GB" : "%.3g GB", gb);
    return text;
}

void check_memory(double bytes, std::string_view what, std::string_view valid) {
    const MemoryBudget budget = memory_budget();
    if (bytes <= budget.bytes) return;
    throw InvalidArgument(
        concat(what, " needs about ", format_gigabytes(bytes), " of memory, above the limit of ",
               format_gigabytes(budget.bytes), " (", budget.source,
               budget.source == kLimitVariable
                   ? ""
                   : "; the environment variable ROUGHSCOPE_MEMORY_LIMIT_GB sets it",
               "); ", valid));
}

}  // namespace roughscope
