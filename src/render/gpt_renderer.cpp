#include "render/gpt_renderer.h"

#include <algorithm>
#include <cstdio>
#include <string>

#include "util/progress.h"
#include "util/timer.h"
#include "vk/commands.h"
#include "vk/context.h"

namespace gdpt {

RenderResultGpt renderGpt(const vk::Context& ctx, const Scene& scene, const RenderOptions& options) {
    return renderGpt(ctx, scene, options, GptPassOptions{});
}

RenderResultGpt renderGpt(const vk::Context& ctx, const Scene& scene, const RenderOptions& options,
                          GptPassOptions gpt) {
    RenderResultGpt result;
    RenderStats& stats = result.stats;
    Timer total;
    Timer phase;
    SceneGpu sceneGpu(ctx, scene, options.scene);
    stats.bvhBuildMs = sceneGpu.bvhInfo().buildMs;
    stats.features = sceneGpu.features();
    gpt.shiftThreshold = options.scene.shiftThreshold;
    GptPass pass(ctx, sceneGpu, options.workgroup, gpt);
    vk::GpuTimer timer(ctx);
    vk::CommandStream stream(ctx, "gpt");
    stats.uploadMs = phase.ms() - stats.bvhBuildMs;

    // The batch loop of renderPt: deterministic schedule 1, 2, 4, ... maxBatchSpp, so sample s
    // of pixel p always uses stream (p, s, seed) and the result is bit-reproducible.
    const bool timed = options.timeBudget > 0.0;
    const double budget = options.timeBudget - options.elapsedBefore;
    Progress progress("render gpt", timed ? budget : static_cast<double>(options.spp), options.quiet);
    phase.restart();
    std::uint32_t done = 0;
    std::uint32_t batch = 1;
    double secondsPerSpp = 0.0;
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
            const double left = budget - total.seconds();
            const auto fits = static_cast<std::uint32_t>(std::max(0.0, left / std::max(secondsPerSpp, 1e-9)));
            if (fits == 0) break;
            n = std::min(n, fits);
        }
        Timer batchTimer;
        VkCommandBuffer cmd = stream.begin();
        if (options.profile) timer.reset(cmd);
        pass.record(cmd, done, n, options.seed, options.profile ? &timer : nullptr);
        stream.setWhat("gpt batch " + std::to_string(stats.batches) + " (samples " + std::to_string(done) + ".." +
                       std::to_string(done + n - 1) + ", seed " + std::to_string(options.seed) + ")");
        stream.submit();
        stream.waitAll([&] {
            if (timed) progress.update(total.seconds());
        });
        if (options.profile) timer.collect();
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

    // Gather the neighbours' terms (a separate submission so its time is its own).
    phase.restart();
    VkCommandBuffer cmd = stream.begin();
    if (options.profile) timer.reset(cmd);
    pass.resolve(cmd, options.profile ? &timer : nullptr);
    stream.setWhat("gpt resolve");
    stream.submit();
    stream.waitAll();
    if (options.profile) timer.collect();
    GptImages images = pass.readback();
    result.primal = std::move(images.primal);
    result.dx = std::move(images.dx);
    result.dy = std::move(images.dy);
    result.direct = std::move(images.direct);
    result.varPrimal = std::move(images.varPrimal);
    result.varDx = std::move(images.varDx);
    result.varDy = std::move(images.varDy);
    result.varDirect = std::move(images.varDirect);
    stats.readbackMs = phase.ms();
    stats.kernels = timer.totals();
    if (stats.nanSamples > 0 && !options.quiet)
        std::fprintf(stderr, "gdpt: warning: %llu G-PT samples were NaN/Inf and were counted as zero\n",
                     static_cast<unsigned long long>(stats.nanSamples));
    return result;
}

}  // namespace gdpt
