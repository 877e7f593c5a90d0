// Large buffers: a hint to back them with transparent huge pages before they are first touched.
// Filling 100 MB of 4 kB pages costs more in page faults than most of the arithmetic done on
// them (a 24-MP float image, a 4096² FFT buffer); with 2 MB pages the kernel takes 512 times
// fewer faults. A hint only (Linux madvise(MADV_HUGEPAGE); nothing elsewhere, or when the kernel
// says no), so results never depend on it.
#pragma once

#include <cstddef>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

namespace roughscope {

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
