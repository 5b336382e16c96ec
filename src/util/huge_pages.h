// huge_pages.h — asks Linux for transparent huge pages on a large, freshly allocated buffer
// (madvise MADV_HUGEPAGE over the 2 MiB-aligned part of it), where the system leaves them to
// the program ("madvise" mode, Debian's default). A buffer first touched page by page costs one
// page fault per 4 KiB; the BVH builder's arrays of tens of MiB spent a sixth of their build
// time in those faults. A hint only: nothing changes where huge pages are off or unknown.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace gdpt {

inline void adviseHugePages(void* data, std::size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    constexpr std::uintptr_t kHuge = std::uintptr_t{2} << 20;
    const auto begin = reinterpret_cast<std::uintptr_t>(data);
    const std::uintptr_t first = (begin + kHuge - 1) & ~(kHuge - 1);
    const std::uintptr_t last = (begin + bytes) & ~(kHuge - 1);
    if (last > first) (void)madvise(reinterpret_cast<void*>(first), last - first, MADV_HUGEPAGE);
#else
    (void)data;
    (void)bytes;
#endif
}

// v.reserve(n), the new buffer advised for huge pages before anything touches it.
template <class T>
void reserveHuge(std::vector<T>& v, std::size_t n) {
    v.reserve(n);
    adviseHugePages(v.data(), v.capacity() * sizeof(T));
}

// std::vector<T>(n, value) whose buffer is advised for huge pages before it is filled.
template <class T>
std::vector<T> hugeVector(std::size_t n, const T& value = T()) {
    std::vector<T> v;
    reserveHuge(v, n);
    v.assign(n, value);
    return v;
}

}  // namespace gdpt
