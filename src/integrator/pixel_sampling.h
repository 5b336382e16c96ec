// pixel_sampling.h — the sampling stage every per-pixel integrator shares (PT, G-PT):
//   1. set-up: the pass's pipelines compile on worker threads while this thread builds the
//      BVH and uploads the scene; the pass's one-off work (G-PT: the edge probe); the
//      caller's whileCompiling; the wait for the pipelines; the statistics of a resumed
//      checkpoint; an empty first dispatch of the main kernels (lavapipe compiles them there);
//   2. the batch loop (sampling_loop.h): record a batch, submit, wait, fold its counters,
//      snapshots for checkpoints;
//   3. the statistics of the run (emitter supersampling, per-kernel times).
// The caller reads the pass's images back afterwards through the pass's own interface.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "integrator/render_options.h"
#include "render/device_scene/scene_gpu.h"
#include "render/passes/sampling_pass.h"
#include "scene/scene.h"
#include "util/timer.h"
#include "vk/commands.h"
#include "vk/timing.h"

namespace gdpt {

class PixelSampling {
public:
    // Checks the scene's emission (checkRadianceRange), creates the pass (from the scene's
    // spec, pipelines in the background) and uploads the scene. `kind` names the pass in progress lines and
    // device-loss messages ("pt", "gpt"); options.maxBatchSpp must be resolved (non-zero).
    using MakePass = std::function<std::unique_ptr<SamplingPass>(const SceneSpec& spec)>;
    PixelSampling(const vk::Context& ctx, const Scene& scene, const RenderOptions& options, std::string kind,
                  const MakePass& makePass);

    // Set-up after the upload, then the batch loop. `preview` returns a viewable image of the
    // samples so far for a checkpoint (called after a batch's fence). `afterBatch`, if set, is
    // called after each batch that covered every row, with the samples per pixel done so far
    // (a render split across processes has none: its batches are not the render's).
    void run(const std::function<Image()>& preview,
             const std::function<void(std::uint32_t done)>& afterBatch = {});

    [[nodiscard]] SamplingPass& pass() { return *pass_; }
    [[nodiscard]] vk::CommandStream& stream() { return stream_; }
    // The timer to pass to recorded work when profiling, else null.
    [[nodiscard]] vk::GpuTimer* timer() { return options_.profile ? &timer_ : nullptr; }
    // Records `work` into a command buffer, submits it and waits, calling onWait while the
    // device works (profiled; `what` names it in device-loss messages). Every batch is one.
    void submitAndWait(const std::string& what, const std::function<void(VkCommandBuffer)>& work,
                       const std::function<void()>& onWait = {});
    // The statistics so far; finish() adds emitter supersampling and the kernel times.
    [[nodiscard]] RenderStats& stats() { return stats_; }
    void finish();

private:
    const vk::Context& ctx_;
    RenderOptions options_;
    std::string kind_;
    Timer total_;
    RenderStats stats_;
    std::unique_ptr<SamplingPass> pass_;
    std::unique_ptr<SceneGpu> scene_;
    vk::GpuTimer timer_;
    vk::CommandStream stream_;
};

// options with maxBatchSpp resolved: kept if set, else maxBatchSppFor(size, pixelSamplesPerBatch).
RenderOptions withBatchLimit(RenderOptions options, std::uint64_t pixelSamplesPerBatch);

}  // namespace gdpt
