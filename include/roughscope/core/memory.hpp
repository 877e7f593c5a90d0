// Large buffers: a hint to back them with transparent huge pages before they are first touched.
// Filling 100 MB of 4 kB pages costs more in page faults than most of the arithmetic done on
// them (a 24-MP float image, a 4096² FFT buffer); with 2 MB pages the kernel takes 512 times
// fewer faults. A hint only (Linux madvise(MADV_HUGEPAGE); nothing elsewhere, or when the kernel
// says no), so results never depend on it.
#pragma once

#include <cstddef>
#include <vector>

namespace roughscope {

// Buffers smaller than this are left alone (a few huge pages at most).
inline constexpr std::size_t kHugePageHintBytes = std::size_t{8} << 20;

// Advises the whole 2 MB pages inside [data, data + bytes) (not yet touched, for the hint to
// matter) when bytes >= kHugePageHintBytes.
void advise_huge_pages(void* data, std::size_t bytes);

// v = n copies of `fill`, the storage advised for huge pages before it is written (v's previous
// contents are dropped).
template <class T>
void assign_large(std::vector<T>& v, std::size_t n, const T& fill) {
    v.clear();
    if (n * sizeof(T) >= kHugePageHintBytes) {
        v.shrink_to_fit();
        v.reserve(n);
        advise_huge_pages(v.data(), n * sizeof(T));
    }
    v.assign(n, fill);
}

}  // namespace roughscope
