// Large buffers: a hint to back them with transparent huge pages before they are first touched.
// Filling 100 MB of 4 kB pages costs more in page faults than most of the arithmetic done on
// them (a 24-MP float image, a 4096² FFT buffer); with 2 MB pages the kernel takes 512 times
// fewer faults. A hint only (Linux madvise(MADV_HUGEPAGE); nothing elsewhere, or when the kernel
// says no), so results never depend on it.
#pragma once

#include <cstddef>
#include <memory>
#include <new>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

namespace roughscope {

// ---- The memory budget (docs/cli.md, "Memory limit") ----------------------------------------
// Options that set a size (a grid's side, a number of threads, bins, realisations) are checked
// against the memory they imply before anything is allocated, so that a typing slip is a named
// error instead of a machine brought down by swapping or a bad_alloc from deep inside.

// The memory one computation may ask for: ROUGHSCOPE_MEMORY_LIMIT_GB when it is set (a number
// > 0; GB = 1e9 bytes), else half the physical memory (of the cgroup's memory.max when that is
// lower). InvalidArgument naming the variable for a value that is not a number > 0.
struct MemoryBudget {
    double bytes = 0.0;
    std::string source;  // "ROUGHSCOPE_MEMORY_LIMIT_GB" or "half the physical memory"
};
MemoryBudget memory_budget();

// `bytes` as "N GB" with two significant digits at least (0.0034 GB, 1.5 GB, 150 GB).
std::string format_gigabytes(double bytes);

// Throws InvalidArgument "<what> needs about N GB of memory, above the limit of M GB (<source>;
// ROUGHSCOPE_MEMORY_LIMIT_GB sets it); <valid>" when `bytes` exceed memory_budget().
void check_memory(double bytes, std::string_view what, std::string_view valid);

// Buffers smaller than this are left alone (a few huge pages at most).
inline constexpr std::size_t kHugePageHintBytes = std::size_t{8} << 20;

// Advises the whole 2 MB pages inside [data, data + bytes) (not yet touched, for the hint to
// matter) when bytes >= kHugePageHintBytes.
void advise_huge_pages(void* data, std::size_t bytes);

// v = n copies of `fill`, the storage advised for huge pages before it is written (v's previous
// contents are dropped).
template <class T, class Allocator>
void assign_large(std::vector<T, Allocator>& v, std::size_t n, const T& fill) {
    v.clear();
    if (n * sizeof(T) >= kHugePageHintBytes) {
        v.shrink_to_fit();
        v.reserve(n);
        advise_huge_pages(v.data(), n * sizeof(T));
    }
    v.assign(n, fill);
}

// An allocator whose value-less construct() default-initialises: resize(n) of a vector of floats
// leaves them as the memory was (fresh pages of a large buffer are the kernel's zeros), for a
// buffer that is written in full before it is read (a decoded image) — not a second pass over
// 100 MB that the decoder overwrites anyway. Everything else as std::allocator.
template <class T>
struct DefaultInitAllocator : std::allocator<T> {
    using std::allocator<T>::allocator;  // (rebinding: allocator_traits, from the template)
    template <class U>
    void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
        ::new (static_cast<void*>(p)) U;
    }
    template <class U, class... Args>
    void construct(U* p, Args&&... args) {
        ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }
};

// n elements left uninitialised (DefaultInitAllocator), the storage advised for huge pages;
// the caller writes every one before any is read.
template <class T>
void resize_large_uninitialised(std::vector<T, DefaultInitAllocator<T>>& v, std::size_t n) {
    v.clear();
    if (n * sizeof(T) >= kHugePageHintBytes) {
        v.shrink_to_fit();
        v.reserve(n);
        advise_huge_pages(v.data(), n * sizeof(T));
    }
    v.resize(n);
}

}  // namespace roughscope
