// parallelFor / parallelRanges (util/parallel.h) with its pool of helper threads: every index
// runs exactly once for any thread count; sums taken per range are the same bits for any thread
// count; an exception reaches the caller and leaves the pool usable; loops inside loops and loops
// started from two threads at once (one of them without the pool) finish with the right result.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <stdexcept>
#include <thread>
#include <vector>

#include "util/parallel.h"

namespace gdpt {
namespace {

// Σ sin(i) over [0, n), summed per range of 1000 and the ranges added in order.
double rangedSum(std::uint32_t threads, std::size_t n) {
    const std::size_t grain = 1000;
    std::vector<double> partial((n + grain - 1) / grain, 0.0);
    parallelRanges(threads, n, grain, [&](std::size_t begin, std::size_t end) {
        double s = 0.0;
        for (std::size_t i = begin; i < end; ++i) s += std::sin(double(i));
        partial[begin / grain] = s;
    });
    double total = 0.0;
    for (double p : partial) total += p;
    return total;
}

TEST(Parallel, EveryIndexOnceForAnyThreadCount) {
    for (const std::uint32_t threads : {1u, 2u, 3u, 8u})
        for (const std::size_t count : {std::size_t{0}, std::size_t{1}, std::size_t{7}, std::size_t{10000}}) {
            std::vector<std::atomic<int>> seen(count);
            parallelFor(threads, count, [&](std::size_t i) { seen[i]++; });
            for (std::size_t i = 0; i < count; ++i)
                ASSERT_EQ(seen[i].load(), 1) << "threads " << threads << ", index " << i << " of " << count;
        }
}

TEST(Parallel, RangedSumsAreTheSameBitsForAnyThreadCount) {
    const double one = rangedSum(1, 123457);
    for (const std::uint32_t threads : {0u, 2u, 5u}) EXPECT_EQ(rangedSum(threads, 123457), one) << threads;
}

TEST(Parallel, AnExceptionReachesTheCallerAndThePoolStaysUsable) {
    EXPECT_THROW(parallelFor(2, 1000,
                             [](std::size_t i) {
                                 if (i == 500) throw std::runtime_error("index 500");
                             }),
                 std::runtime_error);
    // Many short loops after it: each one finishes, with every index run.
    for (int round = 0; round < 2000; ++round) {
        std::atomic<std::size_t> sum{0};
        parallelFor(2, 64, [&](std::size_t i) { sum += i; });
        ASSERT_EQ(sum.load(), 64u * 63u / 2u) << "round " << round;
    }
}

TEST(Parallel, LoopsInsideLoopsAndFromTwoThreadsAtOnce) {
    std::atomic<std::size_t> inner{0};
    parallelFor(2, 16, [&](std::size_t) { parallelFor(2, 100, [&](std::size_t i) { inner += i; }); });
    EXPECT_EQ(inner.load(), 16u * (100u * 99u / 2u));
    std::vector<double> results(4, 0.0);
    std::vector<std::thread> callers;
    for (std::size_t t = 0; t < results.size(); ++t)
        callers.emplace_back([&, t] {
            for (int k = 0; k < 20; ++k) results[t] = rangedSum(2, 50000);
        });
    for (std::thread& c : callers) c.join();
    const double one = rangedSum(1, 50000);
    for (double r : results) EXPECT_EQ(r, one);
}

}  // namespace
}  // namespace gdpt
