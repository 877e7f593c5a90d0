// Huge-page hints for large buffers (core/memory.hpp).
#include "roughscope/core/memory.hpp"

#include <cstdint>

#if defined(__linux__)
#include <sys/mman.h>
#endif

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

}  // namespace roughscope
