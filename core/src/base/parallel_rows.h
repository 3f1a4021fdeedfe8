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

namespace fss::detail {

/// Calls body(i) for every i in [0, n) on up to fss::scanThreads() threads (at most one per
/// \p minPerThread items), thread t taking items t, t + T, t + 2T, … (interleaved, so items of uneven
/// cost — streamlines of different lengths — spread evenly). Waits for all; rethrows the exception of the
/// lowest-numbered thread that threw. Deterministic when body(i) writes only the outputs of item i.
template <class Body> void parallelItems(std::size_t n, std::size_t minPerThread, Body&& body) {
    const std::size_t byWork = std::max<std::size_t>(1, n / std::max<std::size_t>(1, minPerThread));
    const int threads = int(std::min<std::size_t>(std::size_t(scanThreads()), byWork));
    parallelRows(threads, threads, [&](int t, int, int) {
        for (std::size_t i = std::size_t(t); i < n; i += std::size_t(threads))
            body(i);
    });
}

} // namespace fss::detail
