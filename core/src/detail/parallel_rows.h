#pragma once
// Internal (not installed): runs a function over contiguous blocks of [0, n) on fss::scanThreads()
// threads, the calling thread taking the first block. Deterministic by construction when each block
// writes only its own outputs and the caller merges per-block results in block order.
#include "fss/parallel.h"

#include <algorithm>
#include <exception>
#include <thread>
#include <vector>

namespace fss::detail {

/// Number of blocks parallelRows will use for \p n items with at least \p minPerBlock items per block.
inline int rowBlocks(int n, int minPerBlock) {
    if (n <= 0) return 1;
    const int byWork = std::max(1, n / std::max(1, minPerBlock));
    return std::clamp(std::min(scanThreads(), byWork), 1, n);
}

/// Calls body(block, begin, end) for `blocks` contiguous blocks covering [0, n) (block b covers
/// [n·b/blocks, n·(b+1)/blocks)), block 0 on the calling thread, the others on new threads. Waits for
/// all; rethrows the exception of the lowest-numbered block that threw.
template <class Body> void parallelRows(int n, int blocks, Body&& body) {
    if (blocks <= 1 || n <= 1) {
        body(0, 0, n);
        return;
    }
    std::vector<std::exception_ptr> errors(static_cast<std::size_t>(blocks));
    auto run = [&](int b) {
        const int begin = int((long long)n * b / blocks), end = int((long long)n * (b + 1) / blocks);
        try {
            body(b, begin, end);
        } catch (...) {
            errors[std::size_t(b)] = std::current_exception();
        }
    };
    std::vector<std::thread> threads;
    threads.reserve(std::size_t(blocks - 1));
    for (int b = 1; b < blocks; ++b)
        threads.emplace_back(run, b);
    run(0);
    for (std::thread& t : threads)
        t.join();
    for (const std::exception_ptr& e : errors)
        if (e) std::rethrow_exception(e);
}

} // namespace fss::detail
