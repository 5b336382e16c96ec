#include "render/gpt_renderer.h"

#include <algorithm>
#include <string>
#include <utility>

#include "render/batch_loop.h"
#include "util/error.h"
#include "util/timer.h"
#include "vk/commands.h"
#include "vk/context.h"

namespace gdpt {

RenderResultGpt renderGpt(const vk::Context& ctx, const Scene& scene, const RenderOptions& options) {
    return renderGpt(ctx, scene, options, GptPassOptions{});
}

Demodulation parseDemodulation(const std::string& text) {
    if (text == "auto") return Demodulation::Auto;
    if (text == "on") return Demodulation::On;
    if (text == "off") return Demodulation::Off;
    throw UsageError("--demodulate '" + text + "' must be auto, on or off");
}

bool demodulates(const Scene& scene, Demodulation d) {
    return d == Demodulation::On || (d == Demodulation::Auto && demodulationApplies(scene));
}

Image gptFinal(const Image& image, const Image* modulation, const Image* direct) {
    Image out = image;
    for (int c = 0; c < 3; ++c)
        for (std::size_t i = 0; i < out.pixelCount(); ++i) {
            float& v = out.plane(c)[i];
            if (modulation) v *= modulation->plane(c)[i];
            if (direct) v += direct->plane(c)[i];
        }
    return out;
}

Image gptFinal(const RenderResultGpt& result, const Image& recon) {
    return gptFinal(recon, result.modulation.empty() ? nullptr : &result.modulation, &result.direct);
}

RenderResultGpt renderGpt(const vk::Context& ctx, const Scene& scene, const RenderOptions& options,
                          GptPassOptions gpt) {
    RenderResultGpt result;
    RenderStats& stats = result.stats;
    Timer total;
    Timer phase;
    // The pipelines compile on worker threads (lavapipe: most of the set-up, on one core)
    // while this thread builds the BVH and uploads the scene.
    gpt.shiftThreshold = options.scene.shiftThreshold;
    gpt.visibleSupersampling = options.visibleSupersampling;
    gpt.edgeSamples = options.edgeSamples;
    gpt.demodulate = demodulates(scene, options.demodulate);
    SceneSpec spec(scene, options.scene);
    GptPass pass(ctx, spec, options.workgroup, gpt, vk::PipelineCreation::Background);
    SceneGpu sceneGpu(ctx, scene, options.scene, std::move(spec));
    pass.attach(sceneGpu);
    stats.bvhBuildMs = sceneGpu.bvhInfo().buildMs;
    stats.bvhRegisterStack = sceneGpu.spec().bvhRegisterStack();
    stats.features = sceneGpu.features();
    stats.gptSplitBounce = pass.splitBounceCompiled();
    // The edge probe waits only for its own small pipeline and runs while the path kernel's
    // still compiles.
    vk::CommandStream stream(ctx, "gpt");
    pass.findEdges(stream);
    if (options.whileCompiling) options.whileCompiling();
    stats.pipelineWaitMs = 1e3 * pass.waitForPipelines();
    vk::GpuTimer timer(ctx);
    if (options.resume) pass.uploadStats(options.resume->buffers);
    stats.uploadMs = phase.ms() - stats.bvhBuildMs;

    // A snapshot resolves the statistics so far (resolve only writes the resolved buffer, so
    // sampling can continue afterwards) for a primal + direct preview.
    const auto resolveNow = [&] {
        VkCommandBuffer cmd = stream.begin();
        if (options.profile) timer.reset(cmd);
        pass.resolve(cmd, options.profile ? &timer : nullptr);
        stream.setWhat("gpt resolve");
        stream.submit();
        stream.waitAll();
        if (options.profile) timer.collect();
    };
    const auto snapshot = [&](SamplerState& state) {
        state.buffers = pass.downloadStats();
        resolveNow();
        const GptImages images = pass.readback();
        state.preview = gptFinal(images.primal, images.modulation.empty() ? nullptr : &images.modulation,
                                 &images.direct);
    };

    runBatchLoop(options, "render gpt", total, stats,
                 [&](std::uint32_t first, std::uint32_t n, std::uint32_t rows, const std::function<void()>& onWait) {
                     VkCommandBuffer cmd = stream.begin();
                     if (options.profile) timer.reset(cmd);
                     pass.record(cmd, first, n, options.seed, options.profile ? &timer : nullptr, rows);
                     stream.setWhat("gpt batch " + std::to_string(stats.batches) + " (samples " +
                                    std::to_string(first) + ".." + std::to_string(first + n - 1) + ", seed " +
                                    std::to_string(options.seed) + ")");
                     stream.submit();
                     stream.waitAll(onWait);
                     if (options.profile) timer.collect();
                     return pass.takeCounters();
                 },
                 snapshot);

    // Gather the neighbours' terms (a separate submission so its time is its own).
    phase.restart();
    resolveNow();
    GptImages images = pass.readback();
    result.primal = std::move(images.primal);
    result.dx = std::move(images.dx);
    result.dy = std::move(images.dy);
    result.direct = std::move(images.direct);
    result.varPrimal = std::move(images.varPrimal);
    result.varDx = std::move(images.varDx);
    result.varDy = std::move(images.varDy);
    result.varDirect = std::move(images.varDirect);
    result.modulation = std::move(images.modulation);
    result.varModulation = std::move(images.varModulation);
    stats.readbackMs = phase.ms();
    const gpu::VisibleCounter visible = pass.visible().report();
    stats.visibleSupersampling = pass.visible().samplesPerSpp();
    stats.visibleRaysPerSample = visible.raysPerSample;
    stats.visibleRefinedPixels = visible.refinedPixels;
    stats.edgeSamples = pass.edges().samplesPerSpp();
    stats.edgePixels = stats.edgeSamples > 0 ? pass.edges().count() : 0;
    stats.demodulated = pass.demodulating();
    stats.demodulatedPixels = pass.demodulatedPixels();
    stats.kernels = timer.totals();
    return result;
}

}  // namespace gdpt
