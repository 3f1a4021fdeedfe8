#pragma once
// Internal (not installed): asks the kernel to back a large, not yet touched buffer with transparent huge
// pages. A fresh buffer of the size of a 1024² sample grid (88 MB) costs about 1 ms per MB in 4 KiB page
// faults (each page is faulted in and cleared on its first touch); with 2 MiB pages the same memory costs
// a tenth of that (bench/scan_bench.cpp, counter `faults`). Linux only; elsewhere, and where the system
// disables transparent huge pages, it changes nothing.
#include <cstddef>
#include <vector>

namespace fss::detail {

/// Advises huge pages for the whole 2 MiB-aligned pages inside [p, p + bytes) when bytes is at least
/// kHugePageAdviceBytes; never fails (the advice is only a hint).
void adviseHugePages(const void* p, std::size_t bytes);

/// Buffers below this size are left alone (malloc serves them from memory it already has).
inline constexpr std::size_t kHugePageAdviceBytes = std::size_t(8) << 20;

/// Resizes \p v to \p n elements (when it must grow, its old elements are dropped and all n are
/// value-initialised; otherwise the caller overwrites them), advising huge pages for its memory
/// before the elements are written.
template <class T> void resizeWithHugePages(std::vector<T>& v, std::size_t n) {
    if (v.capacity() < n) {
        std::vector<T>().swap(v);
        v.reserve(n);
        adviseHugePages(v.data(), n * sizeof(T));
    }
    v.resize(n);
}

} // namespace fss::detail
