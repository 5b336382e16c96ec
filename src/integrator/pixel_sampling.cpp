#include "integrator/pixel_sampling.h"

#include <algorithm>
#include <utility>

#include "integrator/sampling_loop.h"
#include "render/passes/emitter_supersampling_pass.h"
#include "scene/radiance_range.h"
#include "vk/context.h"

namespace gdpt {

std::uint32_t maxBatchSppFor(int width, int height, std::uint64_t pixelSamplesPerBatch) {
    const std::uint64_t pixels = std::uint64_t(std::max(width, 1)) * std::uint64_t(std::max(height, 1));
    return static_cast<std::uint32_t>(std::clamp<std::uint64_t>(pixelSamplesPerBatch / pixels, 1, 16));
}

RenderOptions withBatchLimit(RenderOptions options, std::uint64_t pixelSamplesPerBatch) {
    if (options.maxBatchSpp == 0)
        options.maxBatchSpp = maxBatchSppFor(options.scene.width, options.scene.height, pixelSamplesPerBatch);
    return options;
}

PixelSampling::PixelSampling(const vk::Context& ctx, const Scene& scene, const RenderOptions& options,
                             std::string kind, const MakePass& makePass)
    : ctx_(ctx), options_(options), kind_(std::move(kind)), timer_(ctx), stream_(ctx, kind_) {
    // Emission whose samples or their squares would overflow float32 is refused before any
    // work (radiance_range.h), rather than written as NaN/Inf pixels.
    checkRadianceRange(scene, options.scene.envRadiance);
    Timer phase;
    // The pipelines compile on worker threads (lavapipe: most of the set-up, on one core)
    // while this thread builds the BVH and uploads the scene.
    SceneSpec spec(scene, options.scene);
    pass_ = makePass(spec);
    scene_ = std::make_unique<SceneGpu>(ctx, scene, options.scene, std::move(spec));
    pass_->attach(*scene_);
    stats_.bvhBuildMs = scene_->bvhInfo().buildMs;
    stats_.sceneDeviceBytes = scene_->deviceBytes();
    stats_.bvhRegisterStack = scene_->spec().bvhRegisterStack();
    stats_.bvhUnitSteps = scene_->spec().bvhUnitSteps(ctx.info(), pass_->tracesBundles());
    stats_.lightShares = scene_->lightShares();
    stats_.lightProbed = scene_->lightProbed();
    stats_.features = scene_->features();
    stats_.uploadMs = phase.ms() - stats_.bvhBuildMs;
}

void PixelSampling::submitAndWait(const std::string& what, const std::function<void(VkCommandBuffer)>& work,
                                  const std::function<void()>& onWait) {
    VkCommandBuffer cmd = stream_.begin();
    if (options_.profile) timer_.reset(cmd);
    work(cmd);
    stream_.setWhat(what);
    stream_.submit();
    stream_.waitAll(onWait);
    if (options_.profile) timer_.collect();
}

void PixelSampling::run(const std::function<Image()>& preview,
                        const std::function<void(std::uint32_t done)>& afterBatch) {
    Timer phase;
    // The pass's own set-up waits only for its small pipelines and runs while the main
    // kernel still compiles.
    pass_->prepare(stream_);
    if (options_.whileCompiling) options_.whileCompiling();
    stats_.pipelineWaitMs = 1e3 * pass_->waitForPipelines();
    if (options_.resume) pass_->uploadStats(options_.resume->buffers);
    stats_.uploadMs += phase.ms();
    Timer compile;
    submitAndWait(kind_ + " kernels' first dispatch", [&](VkCommandBuffer cmd) { pass_->recordWarmUp(cmd); });
    stats_.compileMs = compile.ms();

    const auto snapshot = [&](SamplerState& state) {
        state.buffers = pass_->downloadStats();
        state.preview = preview();
    };
    const std::string label = (kind_ == "pt" ? "render" : "render " + kind_) +
                              (options_.share.split() ? " (part " + options_.share.text() + ")" : "");
    // A share of a split render (sample_share.h) runs the batch schedule over its own samples;
    // its local sample j is the render's sample share.globalSample(j), recorded one sample per
    // pixel at a time (what CPU devices do anyway, "One sample per dispatch").
    const SampleShare share = options_.share;
    RenderOptions loop = options_;
    loop.spp = share.localSpp(options_.spp);
    loop.measureLoad = ctx_.info().type == "cpu";
    runBatchLoop(
        loop, label.c_str(), total_, stats_,
        [&](std::uint32_t first, std::uint32_t n, std::uint32_t rows, const std::function<void()>& onWait) {
            const std::string samples = share.split()
                                            ? std::to_string(n) + " of part " + share.text() +
                                                  " from sample " + std::to_string(share.globalSample(first))
                                            : std::to_string(first) + ".." + std::to_string(first + n - 1);
            const std::string what = kind_ + " batch " + std::to_string(stats_.batches) + " (samples " +
                                     samples + ", seed " + std::to_string(options_.seed) + ")";
            submitAndWait(
                what,
                [&](VkCommandBuffer cmd) {
                    if (!share.split()) {
                        pass_->record(cmd, first, n, options_.seed, timer(), rows);
                        return;
                    }
                    for (std::uint32_t j = first; j < first + n; ++j)
                        pass_->record(cmd, static_cast<std::uint32_t>(share.globalSample(j)), 1,
                                      options_.seed, timer(), rows);
                },
                onWait);
            const gpu::Counters counters = pass_->takeCounters();
            if (afterBatch && !share.split() && rows == static_cast<std::uint32_t>(options_.scene.height))
                afterBatch(first + n);
            return counters;
        },
        snapshot);
    if (options_.combine) {
        SamplerState mine;
        mine.spp = stats_.spp;
        mine.batches = stats_.batches;
        if (!stats_.cancelled) snapshot(mine);
        std::optional<SamplerState> merged = options_.combine(std::move(mine), stats_);
        if (!merged) {
            stats_.handedOff = true;
            return;
        }
        Timer upload;
        pass_->uploadStats(merged->buffers);
        stats_.spp = merged->spp;
        stats_.uploadMs += upload.ms();
    }
}

void PixelSampling::finish() {
    const EmitterSupersamplingPass& emitter = pass_->emitterSupersampling();
    const gpu::VisibleCounter counter = emitter.report();
    stats_.emitterSupersampling = emitter.samplesPerSpp();
    stats_.emitterRaysPerSample = counter.raysPerSample;
    stats_.emitterSupersampledPixels = counter.refinedPixels;
    stats_.kernels = timer_.totals();
}

}  // namespace gdpt
