// sampling_loop.h — the batch loop of the per-pixel samplers (PT, G-PT; pixel_sampling.h): a deterministic
// batch schedule (1, 2, 4, ... maxBatchSpp samples per pixel), stopping at --spp or when the
// time budget would be overrun, cancellation between batches, progress from completed GPU
// work, and the ray/path/NaN counters. A timed render re-estimates after every batch: the
// time spent so far, the time per sample, and the time reserved after sampling carried to the
// load measured on that batch (CPU devices; util/cpu_share.h). A timed render without checkpoints ends with a
// partial pass: once no whole sample per pixel fits the time left, one more sample for as many image rows
// (from the top) as fit, so the budget is not left unused. Every pixel's estimate stays unbiased; those rows
// just have one sample more. Sample s of pixel p always uses the random stream (p, s, seed) and the merge
// order depends only on spp and maxBatchSpp, so a render is bit-reproducible for a given scene, seed, spp,
// image size and device.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "gdpt_shared.h"
#include "integrator/render_options.h"
#include "util/timer.h"

namespace gdpt {

// Traces samples [first, first + count) of the pixels of the first `rows` image rows (all of
// them, except in a timed render's partial last pass), waits for them (calling onWait while
// the device works) and returns the counters of that batch.
using TraceBatchFn = std::function<gpu::Counters(std::uint32_t first, std::uint32_t count, std::uint32_t rows,
                                                 const std::function<void()>& onWait)>;

// Rows of a `height`-row image that one more sample per pixel can cover in `secondsLeft`, at
// `secondsPerSpp` for the whole image, with a 10 % margin (rows do not all cost the same).
std::uint32_t partialPassRows(double secondsLeft, double secondsPerSpp, std::uint32_t height);

// A timed render's next batch: `spp` samples per pixel (0: stop) over the first `rows` rows.
struct TimedBatch {
    std::uint32_t spp = 0;
    std::uint32_t rows = 0;
};
// The batch after one that took `secondsPerSpp` per sample per pixel, with `secondsLeft` for
// sampling and `scheduled` samples per pixel next in the schedule: whole samples per pixel
// for at most half of the time left (so that a machine growing twice as busy during the batch
// does not overrun the budget), else one partial pass (partialPassRows, if `partialPass`),
// else stop.
TimedBatch nextTimedBatch(double secondsLeft, double secondsPerSpp, std::uint32_t scheduled, bool partialPass,
                          std::uint32_t height);

// The reservations after sampling carried to load factor `load` (util/cpu_share.h atLoad;
// 0: as measured).
double reservedAtLoad(const std::vector<ReservedTime>& reserved, double load);

// Fills state.buffers and state.preview from the device (after the last batch's fence).
using SnapshotFn = std::function<void(SamplerState& state)>;

// Runs the loop; fills stats.spp, batches, samplingMs, raysTraced, pathsCompleted,
// nanSamples, cancelled and partialPassRows, and warns about NaN/Inf samples (unless quiet). `total` measures
// the whole render (for --time). With options.resume the schedule continues from it (the
// caller has uploaded its statistics); options.checkpoint receives snapshots.
void runBatchLoop(const RenderOptions& options, const char* label, const Timer& total, RenderStats& stats,
                  const TraceBatchFn& traceBatch, const SnapshotFn& snapshot);

}  // namespace gdpt
