#include "integrator/stats_merge.h"

#include <algorithm>
#include <string>
#include <thread>

#include "lib/pixel_stats.glsl"
#include "util/error.h"

namespace gdpt {

void mergeStatsInto(std::vector<gpu::PixelStats>& acc, const gpu::PixelStats* next, std::size_t count) {
    if (count != acc.size())
        throw Error("cannot merge statistics of " + std::to_string(count) + " pixels into " +
                    std::to_string(acc.size()));
    const auto mergeRange = [&acc, next](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) {
            // A PixelStats is a Welford accumulator with its count: merge it as a batch.
            gpu::Welford batch;
            batch.mean = next[i].mean;
            batch.m2 = next[i].m2;
            acc[i] = gpu::chanMerge(acc[i], batch, next[i].count);
        }
    };
    // Pixels are independent: large images merge on every core (the same bits).
    const std::size_t threads = count < (std::size_t(1) << 18)
                                    ? 1
                                    : std::clamp<std::size_t>(std::thread::hardware_concurrency(), 1, 8);
    std::vector<std::thread> workers;
    const std::size_t step = (count + threads - 1) / threads;
    for (std::size_t t = 1; t < threads; ++t)
        workers.emplace_back(mergeRange, std::min(count, t * step), std::min(count, (t + 1) * step));
    mergeRange(0, std::min(count, step));
    for (std::thread& w : workers) w.join();
}

void mergeStateInto(SamplerState& acc, const SamplerState& next) {
    if (next.buffers.size() != acc.buffers.size())
        throw Error("cannot merge " + std::to_string(next.buffers.size()) + " statistics buffers into " +
                    std::to_string(acc.buffers.size()));
    for (std::size_t k = 0; k < acc.buffers.size(); ++k)
        mergeStatsInto(acc.buffers[k], next.buffers[k].data(), next.buffers[k].size());
    acc.spp += next.spp;
}

}  // namespace gdpt
