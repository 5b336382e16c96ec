// stats_merge.h — merging the per-pixel statistics of renders of disjoint samples (the parts of
// a distributed render, sample_share.h) into the statistics of all their samples: Chan, Golub
// and LeVeque's pairwise update (1979, eq. 2.1), the very function the kernels merge their
// batches with (shaders/lib/pixel_stats.glsl, chanMerge). Exact in real arithmetic; in float32
// the result depends on the merge order, so parts are always merged in part order (0, 1, ...),
// which makes a split render bit-reproducible for a given number of parts. Against a
// single-process render (which folds the samples one batch after another) the means and M2
// differ by float32 rounding: docs/distributed.md states the bound and tests/ check it.
#pragma once

#include <cstddef>
#include <vector>

#include "gdpt_shared.h"
#include "integrator/sampler_state.h"

namespace gdpt {

// acc[i] ← the statistics of the samples of acc[i] and next[i], for every pixel i.
void mergeStatsInto(std::vector<gpu::PixelStats>& acc, const gpu::PixelStats* next, std::size_t count);

// Merges every statistics buffer of `next` into `acc` (same buffers, same image size; throws
// gdpt::Error otherwise) and adds its samples to acc.spp. The schedule position (nextBatch,
// batches) and the preview of acc are kept.
void mergeStateInto(SamplerState& acc, const SamplerState& next);

}  // namespace gdpt
