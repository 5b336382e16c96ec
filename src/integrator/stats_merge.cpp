#include "integrator/stats_merge.h"

#include <string>

#include "lib/pixel_stats.glsl"
#include "util/error.h"

namespace gdpt {

void mergeStatsInto(std::vector<gpu::PixelStats>& acc, const gpu::PixelStats* next, std::size_t count) {
    if (count != acc.size())
        throw Error("cannot merge statistics of " + std::to_string(count) + " pixels into " +
                    std::to_string(acc.size()));
    for (std::size_t i = 0; i < count; ++i) {
        // A PixelStats is a Welford accumulator with its count: merge it as a batch.
        gpu::Welford batch;
        batch.mean = next[i].mean;
        batch.m2 = next[i].m2;
        acc[i] = gpu::chanMerge(acc[i], batch, next[i].count);
    }
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
