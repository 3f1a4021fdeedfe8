#include "fss/parallel.h"

#include "fss/error.h"

#include <atomic>
#include <string>
#include <thread>

namespace fss {
namespace {
std::atomic<int> configuredThreads{0};
} // namespace

void setScanThreads(int threads) {
    if (threads < 0)
        throw InvalidInputError("The number of scan threads " + std::to_string(threads) + " is negative.");
    configuredThreads.store(threads, std::memory_order_relaxed);
}

int scanThreads() {
    const int configured = configuredThreads.load(std::memory_order_relaxed);
    if (configured > 0) return configured;
    const unsigned hardware = std::thread::hardware_concurrency();
    return hardware > 0 ? int(hardware) : 1;
}

} // namespace fss
