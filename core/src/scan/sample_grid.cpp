#include "fss/sample_grid.h"

#include "base/huge_pages.h"

#include <cstdint>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace fss {

namespace detail {

void adviseHugePages(const void* p, std::size_t bytes) {
#if defined(MADV_HUGEPAGE)
    if (!p || bytes < kHugePageAdviceBytes) return;
    constexpr std::uintptr_t page = std::uintptr_t(2) << 20;
    const auto begin = (reinterpret_cast<std::uintptr_t>(p) + page - 1) & ~(page - 1);
    const auto end = (reinterpret_cast<std::uintptr_t>(p) + bytes) & ~(page - 1);
    if (end > begin) (void)madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#else
    (void)p;
    (void)bytes;
#endif
}

} // namespace detail

SampleGrid::SampleGrid(int rows_, int cols_) : rows(rows_), cols(cols_) {
    detail::resizeWithHugePages(samples, std::size_t(rows_) * std::size_t(cols_));
}

} // namespace fss
