#include "integrator/sampling_loop.h"

#include <algorithm>
#include <cstdio>
#include <string>

#include "util/cpu_share.h"
#include "util/progress.h"

namespace gdpt {

std::uint32_t partialPassRows(double secondsLeft, double secondsPerSpp, std::uint32_t height) {
    if (!(secondsLeft > 0.0) || !(secondsPerSpp > 0.0)) return 0;
    const double rows = 0.9 * secondsLeft / secondsPerSpp * static_cast<double>(height);
    return rows >= static_cast<double>(height) ? height : static_cast<std::uint32_t>(rows);
}

TimedBatch nextTimedBatch(double secondsLeft, double secondsPerSpp, std::uint32_t scheduled, bool partialPass,
                          std::uint32_t height) {
    const auto fits = static_cast<std::uint32_t>(std::max(0.0, secondsLeft / std::max(secondsPerSpp, 1e-9)));
    if (fits > 0) return {std::min(scheduled, std::max(1u, fits / 2)), height};
    const std::uint32_t rows = partialPass ? partialPassRows(secondsLeft, secondsPerSpp, height) : 0;
    if (rows == 0 || rows >= height) return {0, 0};
    return {1, rows};
}

double reservedAtLoad(const std::vector<ReservedTime>& reserved, double load) {
    double seconds = 0.0;
    for (const ReservedTime& r : reserved) seconds += atLoad(r.seconds, r.load, load);
    return seconds;
}

void runBatchLoop(const RenderOptions& options, const char* label, const Timer& total, RenderStats& stats,
                  const TraceBatchFn& traceBatch, const SnapshotFn& snapshot) {
    const bool timed = options.timeBudget > 0.0;
    const double budget = options.timeBudget - options.elapsedBefore;
    stats.setupSeconds = options.elapsedBefore + total.seconds();
    // The reservations after sampling, carried to the load of the last batch: what they add
    // to (or take from) what timeBudget already leaves for them.
    const double reserved = reservedAtLoad(options.reservedAfterSampling, 0.0);
    double load = 0.0;  // load factor of the last batch; 0 until one is measured
    const auto reserveChange = [&] {
        const double now = reservedAtLoad(options.reservedAfterSampling, load);
        stats.reserveScale = reserved > 0.0 ? now / reserved : 1.0;
        return now - reserved;
    };
    CpuShareMeter samplingShare;
    Progress progress(label, timed ? budget : static_cast<double>(options.spp), options.quiet);
    Timer phase;
    std::uint32_t done = 0;
    std::uint32_t batch = 1;
    if (options.resume) {
        // Same schedule position as the run that wrote the state, so that the merge order
        // (and hence every bit) matches a run that was never interrupted.
        done = options.resume->spp;
        batch = std::clamp(options.resume->nextBatch, 1u, options.maxBatchSpp);
        stats.batches = options.resume->batches;
    }
    const auto emitCheckpoint = [&] {
        SamplerState state;
        state.spp = done;
        state.nextBatch = batch;
        state.batches = stats.batches;
        snapshot(state);
        options.checkpoint(state);
    };
    Timer sinceCheckpoint;
    double secondsPerSpp = 0.0;  // measured on the last batch
    const std::uint32_t height = static_cast<std::uint32_t>(options.scene.height);
    // A partial pass leaves rows with different sample counts: not in a checkpoint (whose
    // state is one sample count), nor in a share of a split render (a shard is one).
    const bool partialPass = timed && options.partialPass && !options.checkpoint && !options.share.split();
    std::uint32_t rows = height;
    while (true) {
        if (options.cancel && options.cancel->load()) {
            stats.cancelled = true;
            break;
        }
        std::uint32_t n = batch;
        if (!timed) {
            if (done >= options.spp) break;
            n = std::min(batch, options.spp - done);
        } else if (done > 0) {
            // At least one batch always runs, however little the fixed costs before it left.
            const TimedBatch next = nextTimedBatch(budget - total.seconds() - reserveChange(), secondsPerSpp,
                                                   n, partialPass, height);
            if (next.spp == 0) break;
            n = next.spp;
            rows = next.rows;
        }
        // A batch ends at the next stop, if one comes before it would.
        const auto stop = std::upper_bound(options.batchStops.begin(), options.batchStops.end(), done);
        if (stop != options.batchStops.end()) n = std::min(n, *stop - done);
        Timer batchTimer;
        CpuShareMeter batchShare;
        const gpu::Counters c = traceBatch(done, n, rows, [&] {
            if (timed) progress.update(total.seconds());
        });
        stats.raysTraced += c.raysTraced;
        stats.pathsCompleted += c.pathsCompleted;
        stats.nanSamples += c.nanSamples;
        stats.shiftPairs += c.shiftPairs;
        stats.shiftFailures += c.shiftFailures;
        ++stats.batches;
        if (rows < height) {
            stats.partialPassRows = rows;  // the last batch: one sample more in these rows
            break;
        }
        done += n;
        secondsPerSpp = batchTimer.seconds() / n;
        if (stats.firstBatchSeconds == 0.0) stats.firstBatchSeconds = batchTimer.seconds();
        if (options.measureLoad) load = loadFactor(batchShare.share());
        const double mraysPerS =
            static_cast<double>(stats.raysTraced) / std::max(1e-9, phase.seconds()) * 1e-6;
        char rate[64];
        std::snprintf(rate, sizeof rate, "%u spp, %.2f Mrays/s", done, mraysPerS);
        progress.update(timed ? total.seconds() : static_cast<double>(done), rate);
        batch = std::min(batch * 2, options.maxBatchSpp);
        if (options.checkpoint && options.checkpointEvery > 0.0 &&
            sinceCheckpoint.seconds() >= options.checkpointEvery) {
            emitCheckpoint();
            sinceCheckpoint.restart();
        }
    }
    if (options.checkpoint) emitCheckpoint();
    stats.samplingMs = phase.ms();
    if (options.measureLoad) stats.samplingLoad = loadFactor(samplingShare.share());
    stats.spp = done;
    progress.finish(std::to_string(done) + " spp");
    if (stats.nanSamples > 0 && !options.quiet)
        std::fprintf(stderr, "gdpt: warning: %s: %llu samples were NaN/Inf and were counted as zero\n", label,
                     static_cast<unsigned long long>(stats.nanSamples));
}

}  // namespace gdpt
