#include "render/renderer.h"

#include <algorithm>
#include <memory>
#include <cstdio>

#include "render/wavefront_pass.h"
#include "util/progress.h"
#include "util/timer.h"
#include "vk/commands.h"
#include "vk/context.h"

namespace gdpt {

RenderResult renderPt(const vk::Context& ctx, const Scene& scene, const RenderOptions& options) {
    RenderResult result;
    RenderStats& stats = result.stats;
    Timer total;
    Timer phase;
    SceneGpu sceneGpu(ctx, scene, options.scene);
    stats.bvhBuildMs = sceneGpu.bvhInfo().buildMs;
    stats.features = sceneGpu.features();
    PtPass pass(ctx, sceneGpu, options.workgroup);
    std::unique_ptr<WavefrontPass> wavefront;
    if (options.schedule == Schedule::Wavefront)
        wavefront = std::make_unique<WavefrontPass>(ctx, sceneGpu, pass, options.workgroup);
    vk::GpuTimer timer(ctx);
    vk::CommandStream stream(ctx, "pt");
    stats.uploadMs = phase.ms() - stats.bvhBuildMs;

    const bool timed = options.timeBudget > 0.0;
    const double budget = options.timeBudget - options.elapsedBefore;
    Progress progress("render", timed ? budget : static_cast<double>(options.spp), options.quiet);
    phase.restart();
    std::uint32_t done = 0;
    std::uint32_t batch = 1;
    double secondsPerSpp = 0.0;  // measured on the last batch
    // Deterministic batch schedule 1, 2, 4, ... maxBatchSpp: sample s of pixel p always uses
    // the random stream (p, s, seed), and the merge order depends only on spp, so a render
    // is bit-reproducible for a given scene, seed, spp and device.
    while (true) {
        if (options.cancel && options.cancel->load()) {
            stats.cancelled = true;
            break;
        }
        std::uint32_t n = batch;
        if (!timed) {
            if (done >= options.spp) break;
            n = std::min(batch, options.spp - done);
        } else {
            const double elapsed = total.seconds();
            // Shrink the next batch to what fits the remaining budget; stop when not even
            // one sample per pixel fits (at least one batch always runs).
            if (done > 0) {
                const double left = budget - elapsed;
                const auto fits = static_cast<std::uint32_t>(std::max(0.0, left / std::max(secondsPerSpp, 1e-9)));
                if (fits == 0) break;
                n = std::min(n, fits);
            }
        }
        Timer batchTimer;
        stream.setWhat("pt batch " + std::to_string(stats.batches) + " (samples " + std::to_string(done) + ".." +
                       std::to_string(done + n - 1) + ", seed " + std::to_string(options.seed) + ")");
        const auto onWait = [&] {
            if (timed) progress.update(total.seconds());
        };
        if (wavefront) {
            for (std::uint32_t i = 0; i < n; ++i)
                wavefront->traceSample(stream, done + i, options.seed, options.profile ? &timer : nullptr, onWait);
        } else {
            VkCommandBuffer cmd = stream.begin();
            if (options.profile) timer.reset(cmd);
            pass.record(cmd, done, n, options.seed, options.profile ? &timer : nullptr);
            stream.submit();
            stream.waitAll(onWait);
            if (options.profile) timer.collect();
        }
        const gpu::Counters c = pass.takeCounters();
        stats.raysTraced += c.raysTraced;
        stats.pathsCompleted += c.pathsCompleted;
        stats.nanSamples += c.nanSamples;
        done += n;
        ++stats.batches;
        secondsPerSpp = batchTimer.seconds() / n;
        const double mraysPerS = static_cast<double>(stats.raysTraced) / std::max(1e-9, phase.seconds()) * 1e-6;
        char rate[64];
        std::snprintf(rate, sizeof rate, "%u spp, %.2f Mrays/s", done, mraysPerS);
        progress.update(timed ? total.seconds() : static_cast<double>(done), rate);
        batch = std::min(batch * 2, options.maxBatchSpp);
    }
    stats.samplingMs = phase.ms();
    stats.spp = done;
    progress.finish(std::to_string(done) + " spp");

    phase.restart();
    pass.readback(result.image, result.varianceOfMean);
    stats.readbackMs = phase.ms();
    stats.kernels = timer.totals();
    if (stats.nanSamples > 0 && !options.quiet)
        std::fprintf(stderr, "gdpt: warning: %llu samples were NaN/Inf and were counted as zero\n",
                     static_cast<unsigned long long>(stats.nanSamples));
    return result;
}

}  // namespace gdpt
