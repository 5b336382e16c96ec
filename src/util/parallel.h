// parallel.h — the one way gdpt's host code spreads a loop over threads: indices (or ranges of
// them) handed out in order from an atomic counter to up to `threads` threads, the caller's
// included; the first exception is rethrown once every thread has stopped. Nothing depends on
// which thread ran what, so results are the same for any thread count.
//
// The helper threads come from a process-wide pool started on first use (one per hardware
// thread but the caller's), so that a loop does not pay a thread's start and join (about 40 µs
// each on a 2-core virtual machine; the space-time solver runs about 150 loops per CG
// iteration). A loop started while the pool is in use (by another thread, or from inside a
// loop) starts threads of its own instead, as before the pool: never a wait on the pool.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace gdpt {

// Threads to use when a caller asks for 0: the hardware's.
inline std::uint32_t defaultThreads(std::uint32_t threads = 0) {
    return threads > 0 ? threads : std::max(1u, std::thread::hardware_concurrency());
}

// Runs `work` on the caller and on up to `helpers` threads of the pool, returning when every
// run has returned; false (nothing run) if the pool is in use or has fewer threads. `work` must
// not throw.
bool runOnPool(std::uint32_t helpers, const std::function<void()>& work);

// fn(i) for i in [0, count).
template <class Fn>
void parallelFor(std::uint32_t threads, std::size_t count, const Fn& fn) {
    const auto workers = static_cast<std::uint32_t>(std::min<std::size_t>(defaultThreads(threads), count));
    if (workers <= 1) {
        for (std::size_t i = 0; i < count; ++i) fn(i);
        return;
    }
    std::atomic<std::size_t> next{0};
    std::atomic<bool> failed{false};
    std::exception_ptr error;
    std::mutex errorMutex;
    auto work = [&] {
        try {
            for (std::size_t i = next++; i < count && !failed.load(std::memory_order_relaxed); i = next++)
                fn(i);
        } catch (...) {
            std::lock_guard<std::mutex> lock(errorMutex);
            if (!error) error = std::current_exception();
            failed = true;
        }
    };
    if (!runOnPool(workers - 1, work)) {
        std::vector<std::thread> pool;
        pool.reserve(workers - 1);
        for (std::uint32_t w = 1; w < workers; ++w) pool.emplace_back(work);
        work();
        for (std::thread& t : pool) t.join();
    }
    if (error) std::rethrow_exception(error);
}

// fn(begin, end) over [0, count) in ranges of `grain` (the last one shorter).
template <class Fn>
void parallelRanges(std::uint32_t threads, std::size_t count, std::size_t grain, const Fn& fn) {
    grain = std::max<std::size_t>(grain, 1);
    const std::size_t ranges = (count + grain - 1) / grain;
    parallelFor(threads, ranges, [&](std::size_t r) { fn(r * grain, std::min(count, (r + 1) * grain)); });
}

}  // namespace gdpt
