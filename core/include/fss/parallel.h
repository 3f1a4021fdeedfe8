#pragma once
/// \file parallel.h
/// How many threads the per-pixel stages of a scan use (sampling, lasso, quality mask, morphology and
/// triangulation in scan.h, mask.h, triangulate.h; ray casting in fishbone_scan.h). Each stage splits its
/// rows into contiguous blocks, one per thread, and merges the blocks' results in row order, so every
/// result is identical to the serial one whatever the thread count; only the wall-clock time changes.

namespace fss {

/// Sets the number of threads of those stages: 1 runs everything on the calling thread; 0 (the default)
/// means std::thread::hardware_concurrency() (at least 1). Applies to calls started afterwards; meant to
/// be set once at start-up (it is an atomic, so setting it while scans run is safe but racy in effect).
/// \throw InvalidInputError when \p threads is negative.
void setScanThreads(int threads);

/// The number of threads the stages will use now (≥ 1): the value of setScanThreads, or the hardware
/// concurrency when that is 0.
int scanThreads();

} // namespace fss
