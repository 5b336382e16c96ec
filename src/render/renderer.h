// renderer.h — the render loop: upload the scene, then for each batch trace samples and fold
// them into the per-pixel statistics, reporting progress from completed GPU work, until the
// sample count or the time budget is reached; then read the images back.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <string>

#include "image/image.h"
#include "render/edge_options.h"
#include "render/pt_pass.h"
#include "render/sampler_state.h"
#include "render/scene_gpu.h"
#include "scene/scene.h"
#include "vk/timing.h"

namespace gdpt {

namespace vk {
class Context;
}

// How the path tracer is scheduled on the device: one kernel per whole path batch
// (megakernel, the default: measured faster on lavapipe) or a kernel per bounce stage.
enum class Schedule { Megakernel, Wavefront };

// G-PT's first-hit texture demodulation (render/gpt_pass.h): Auto = on where it can act
// (demodulationApplies: a base-colour texture on a Lambertian-only material).
enum class Demodulation { Auto, On, Off };

struct RenderOptions {
    SceneGpuOptions scene;
    std::uint32_t spp = 16;        // samples per pixel (ignored when timeBudget > 0)
    double timeBudget = 0.0;       // seconds for the whole render (0 = use spp)
    double elapsedBefore = 0.0;    // seconds already spent (e.g. loading) counted in the budget
    std::uint32_t seed = 0;
    bool profile = false;
    bool quiet = false;
    WorkgroupSize workgroup;
    Schedule schedule = Schedule::Megakernel;
    // Rays per camera sample in the pixels of emitter-silhouette supersampling
    // (render/visible_pass.h); 0 = off.
    std::uint32_t visibleSupersampling = kDefaultVisibleSupersampling;
    // G-PT: extra camera samples per camera sample in the pixels a geometric edge crosses
    // (render/edge_pass.h); 0 = off. PT ignores it.
    std::uint32_t edgeSamples = kDefaultEdgeSamples;
    // G-PT: first-hit texture demodulation (render/gpt_pass.h). PT ignores it.
    Demodulation demodulate = Demodulation::Auto;
    std::uint32_t maxBatchSpp = 16;  // largest batch (samples per pixel per submission)
    const std::atomic<bool>* cancel = nullptr;  // set asynchronously to stop between batches
    // Continue from this state (its statistics and batch-schedule position) instead of from
    // zero samples; the caller has checked that it belongs to this scene, size, seed and
    // method. spp / timeBudget then count the total / this run's time as usual.
    const SamplerState* resume = nullptr;
    // If set, called with the current state at a batch boundary every checkpointEvery
    // seconds (0 = never) and once when sampling ends, finished or cancelled.
    std::function<void(const SamplerState&)> checkpoint;
    double checkpointEvery = 0.0;
    // If set, run on the calling thread after the scene is on the device, while the kernels'
    // pipelines may still be compiling on worker threads (vk::PipelineCreation::Background),
    // before sampling; for set-up of the caller's own that should overlap that compile (the
    // reconstruction's pipelines). Its time counts in the budget like everything else.
    std::function<void()> whileCompiling;
};

struct RenderStats {
    std::uint32_t spp = 0;              // samples in every pixel
    std::uint32_t partialPassRows = 0;  // timed renders: rows (from the top) with one sample more
    std::uint32_t batches = 0;
    double bvhBuildMs = 0.0;
    std::uint32_t bvhRegisterStack = 0;  // entries of the kernels' register traversal stack (0: in memory)
    double uploadMs = 0.0;       // scene upload + pipeline creation (the part not overlapped)
    double pipelineWaitMs = 0.0; // of which: waiting for the pipelines after the scene upload
    double samplingMs = 0.0;     // wall time of the batch loop
    double readbackMs = 0.0;
    double reconstructionMs = 0.0;  // G-PT: screened Poisson solve(s)
    std::uint64_t raysTraced = 0;
    std::uint64_t pathsCompleted = 0;
    std::uint64_t nanSamples = 0;
    std::uint64_t shiftPairs = 0;     // G-PT: shifts attempted (offsets in the image, base hit)
    std::uint64_t shiftFailures = 0;  // G-PT: shifts that failed (pair fell back to the base)
    bool gptSplitBounce = false;      // G-PT: the kernel ran the split bounce loop
    std::uint32_t visibleSupersampling = 0;  // emitter-silhouette supersampling factor (0 = off)
    std::uint32_t visibleRaysPerSample = 0;  // rays per camera sample it took (after its ray budget)
    std::uint32_t visibleRefinedPixels = 0;  // pixels it covered
    std::uint32_t edgeSamples = 0;  // G-PT: extra samples per camera sample in edge pixels (0 = off)
    std::uint32_t edgePixels = 0;   // G-PT: pixels a geometric edge crosses
    bool demodulated = false;             // G-PT: first-hit texture demodulation was on
    std::uint32_t demodulatedPixels = 0;  // G-PT: pixels it acted in (away from the edges)
    bool cancelled = false;
    std::map<std::string, vk::KernelTime> kernels;
    SceneFeatures features;
};

struct RenderResult {
    Image image;           // mean radiance
    Image varianceOfMean;  // per-pixel variance of the mean (sample variance / n)
    RenderStats stats;
};

RenderResult renderPt(const vk::Context& ctx, const Scene& scene, const RenderOptions& options);

}  // namespace gdpt
