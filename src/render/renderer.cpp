#include "render/renderer.h"

#include <algorithm>
#include <memory>
#include <utility>

#include "render/batch_loop.h"
#include "render/wavefront_pass.h"
#include "util/timer.h"
#include "vk/commands.h"
#include "vk/context.h"

namespace gdpt {

RenderResult renderPt(const vk::Context& ctx, const Scene& scene, const RenderOptions& options) {
    RenderResult result;
    RenderStats& stats = result.stats;
    Timer total;
    Timer phase;
    // The pipelines compile on worker threads while this thread builds and uploads the scene.
    SceneSpec spec(scene, options.scene);
    PtPass pass(ctx, spec, options.workgroup, options.visibleSupersampling, vk::PipelineCreation::Background);
    SceneGpu sceneGpu(ctx, scene, options.scene, std::move(spec));
    pass.attach(sceneGpu);
    stats.bvhBuildMs = sceneGpu.bvhInfo().buildMs;
    stats.bvhRegisterStack = sceneGpu.spec().bvhRegisterStack();
    stats.features = sceneGpu.features();
    std::unique_ptr<WavefrontPass> wavefront;
    if (options.schedule == Schedule::Wavefront)
        wavefront = std::make_unique<WavefrontPass>(ctx, sceneGpu, pass, options.workgroup);
    vk::GpuTimer timer(ctx);
    vk::CommandStream stream(ctx, "pt");
    if (options.resume) pass.uploadStats(options.resume->buffers);
    if (options.whileCompiling) options.whileCompiling();
    stats.pipelineWaitMs = 1e3 * pass.waitForPipelines();
    stats.uploadMs = phase.ms() - stats.bvhBuildMs;
    const auto snapshot = [&](SamplerState& state) {
        state.buffers = pass.downloadStats();
        Image variance;
        pass.readback(state.preview, variance);
    };

    runBatchLoop(options, "render", total, stats,
                 [&](std::uint32_t first, std::uint32_t n, std::uint32_t rows, const std::function<void()>& onWait) {
                     stream.setWhat("pt batch " + std::to_string(stats.batches) + " (samples " +
                                    std::to_string(first) + ".." + std::to_string(first + n - 1) + ", seed " +
                                    std::to_string(options.seed) + ")");
                     if (wavefront) {
                         for (std::uint32_t i = 0; i < n; ++i)
                             wavefront->traceSample(stream, first + i, options.seed,
                                                    options.profile ? &timer : nullptr, onWait);
                     } else {
                         VkCommandBuffer cmd = stream.begin();
                         if (options.profile) timer.reset(cmd);
                         pass.record(cmd, first, n, options.seed, options.profile ? &timer : nullptr, rows);
                         stream.submit();
                         stream.waitAll(onWait);
                         if (options.profile) timer.collect();
                     }
                     return pass.takeCounters();
                 },
                 snapshot);

    phase.restart();
    pass.readback(result.image, result.varianceOfMean);
    stats.readbackMs = phase.ms();
    const gpu::VisibleCounter visible = pass.visible().report();
    stats.visibleSupersampling = pass.visible().samplesPerSpp();
    stats.visibleRaysPerSample = visible.raysPerSample;
    stats.visibleRefinedPixels = visible.refinedPixels;
    stats.kernels = timer.totals();
    return result;
}

}  // namespace gdpt
