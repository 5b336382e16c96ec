// render_options.h — what every integrator is asked (RenderOptions: image, sampling, time
// budget, checkpoints, cancellation) and what its sampling reports (RenderStats), plus the
// path tracer's sampled images (RenderResult). Method-specific settings live with their
// integrator (integrator/gpt_integrator.h).
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "image/image.h"
#include "integrator/sample_share.h"
#include "integrator/sampler_state.h"
#include "render/device_scene/features.h"
#include "render/device_scene/scene_spec.h"
#include "render/passes/emitter_supersampling_options.h"
#include "vk/timing.h"

namespace gdpt {

// Largest batch (samples per pixel per submission) of a width x height render such that one
// batch is about `pixelSamplesPerBatch` pixel-samples (clamped to 1..16). It depends only on
// the image size and the method, so the batch schedule (1, 2, 4, ... this) -- and hence the
// merge order and every bit of the result -- is the same on every run, and a batch stays
// well under a second on lavapipe, so an interrupt is served promptly.
std::uint32_t maxBatchSppFor(int width, int height, std::uint64_t pixelSamplesPerBatch);

struct RenderStats;

// Seconds a timed render reserves for its stages after sampling (the reconstruction; readback
// and output), and the load factor (util/cpu_share.h) that the sampling of the run which
// measured them felt; 0: measured in this run, or on a device whose load is not measured.
struct ReservedTime {
    double seconds = 0.0;
    double load = 0.0;
};

struct RenderOptions {
    SceneGpuOptions scene;
    std::uint32_t spp = 16;      // samples per pixel (ignored when timeBudget > 0)
    double timeBudget = 0.0;     // seconds for the whole render (0 = use spp)
    double elapsedBefore = 0.0;  // seconds already spent (e.g. loading) counted in the budget
    // Timed renders may end with a partial pass (one more sample in the top rows); false: whole
    // samples per pixel only (temporal G-PT pairs every sample of a half with the next frame's).
    bool partialPass = true;
    // Timed renders: the reservations already taken off timeBudget, as measured. The batch
    // loop carries each to the load it measures on its last batch (atLoad) and takes off the
    // difference too, so that a busier (or idler) machine than the one that measured them
    // moves the end of sampling accordingly.
    std::vector<ReservedTime> reservedAfterSampling;
    // Timed renders: when the reconstruction must end (the budget's end less the time reserved
    // for the output, which as remembered includes the readback before the reconstruction:
    // ReconstructionStage gives the solves this plus the readback's time); an L1 reconstruction
    // stops reweighting by then (SolveOptions::deadline). None: no limit.
    std::optional<std::chrono::steady_clock::time_point> reconstructionDeadline;
    // Measure the load during sampling (stats.samplingLoad); set by the sampler on CPU devices,
    // where other processes compete with the device's threads.
    bool measureLoad = false;
    std::uint32_t seed = 0;
    bool profile = false;
    bool quiet = false;
    WorkgroupSize workgroup;
    // Rays per camera sample in the pixels of emitter supersampling
    // (render/passes/emitter_supersampling_pass.h); 0 = off.
    std::uint32_t emitterSupersampling = kDefaultEmitterSupersampling;
    // Largest batch (samples per pixel per submission); 0 = the method's default for the
    // image size (maxBatchSppFor), what the command line uses.
    std::uint32_t maxBatchSpp = 0;
    // Sample counts (increasing) at which a batch must end: a batch never runs across one, so
    // that a caller reading the sums at batch ends sees these counts (tgpt's groups of
    // paired samples, integrator/sample_groups.h). Empty: the schedule alone decides.
    std::vector<std::uint32_t> batchStops;
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
    // A render split across processes (sample_share.h): this process takes only the samples of
    // its share, and `spp` counts the whole render's samples per pixel (this process takes
    // share.localSpp(spp) of them; a timed render's share samples for the whole budget).
    SampleShare share;
    // If set, called once when sampling ends, finished or cancelled, with this process's
    // statistics (and a preview) and its stats (counters it may add to): returns the
    // statistics the method's later stages continue from (the merge over every process, on the
    // process that finishes the render), or nothing (the others, and a shard that writes its
    // statistics: the method stops after sampling and returns no layers, stats.handedOff).
    std::function<std::optional<SamplerState>(SamplerState mine, RenderStats& stats)> combine;
};

// One screened Poisson reconstruction of a render (G-PT): the solver's report in brief.
struct ReconstructionStats {
    std::string method;              // "l1", "l2", "wl2", "wl1"
    int iterations = 0;              // inner iterations, summed over IRLS rounds
    int irlsIterations = 0;          // 1 for L2/WL2
    double residual = 0.0;           // final relative residual, max over channels
    double tolerance = 0.0;          // the relative residual asked for
    bool converged = false;          // every channel reached the tolerance
    double ms = 0.0;                 // the solve and the debiasing
    int debiasScale = 0;             // node spacing (px) of the debiasing (poisson/debias.h); 0: not debiased
    double debiasMeanChange = 0.0;   // the debiasing's change of the image mean, relative
    double debiasMs = 0.0;           // of ms: the debiasing (host)
    bool stoppedAtDeadline = false;  // IRLS rounds left out to end within a timed render's budget
    std::string solver;              // the linear solver: "mg-pcg", "host-pcg", ... (poisson_gpu.h)
    double alpha = 0.0;              // the primal term's weight
};

// A render split across processes (sample_share.h): how its parts were merged.
struct DistributedStats {
    std::uint32_t parts = 1;             // processes (ranks) or shards; 1: not split
    std::vector<std::uint32_t> partSpp;  // samples per pixel each part took, in part order
    std::uint64_t bytesPerPart = 0;      // statistics each part sent (or wrote)
    double mergeMs = 0.0;                // receiving and merging them (rank 0, or gdpt merge)
    double waitMs = 0.0;                 // rank 0 waiting for the other ranks to end sampling
};

// Metropolis light transport (pssmlt, gmlt): the chains and the bootstrap.
struct MltStats {
    std::uint32_t chains = 0;
    std::uint64_t mutations = 0;  // proposals, all chains
    std::uint64_t proposedSmall = 0, acceptedSmall = 0, proposedLarge = 0, acceptedLarge = 0;
    std::uint64_t bootstrapSamples = 0;
    double bootstrapEss = 0.0;               // their targets' effective sample size, (Σ T)² / Σ T²
    double normalisation = 0.0;              // b̂ = ∫ T: the mean target of fresh states
    double normalisationStdErr = 0.0;        // its standard error
    std::uint64_t normalisationSamples = 0;  // fresh states it averages (bootstrap + large steps)
    double splatMs = 0.0;                    // reading the records back and adding them up (host)
};

// Temporal G-PT (tgpt): the window a frame was reconstructed in, and its two half renders.
struct TgptStats {
    int windowFirst = 0;                // first frame of the window
    int windowFrames = 0;               // frames reconstructed together
    std::uint32_t firstHalfSpp = 0;     // samples per pixel seeded with the frame's own seed
    std::uint32_t secondHalfSpp = 0;    // ... with the next frame's seed (paired with it)
    bool temporalToPrevious = false;    // the frame has a dt to the frame before it
    bool joinedPreviousWindow = false;  // the window's solve was tied to the window before
    // Motion shift (TemporalShift::Motion): pixels of the frame before with a partner in this
    // frame (motion_map.h), and the host time of its primary hits and the map.
    std::uint64_t motionPartnered = 0;
    double motionMs = 0.0;
    // Groups of paired samples behind the variance of dt from the frame before (var_dt,
    // sample_groups.h): its degrees of freedom per pixel are one fewer; 0 without a dt.
    int dtVarianceGroups = 0;
    // Reconnection shift (TemporalShift::Reconnect): the camera samples per pixel of each of its
    // two directions from the frame before, the pass's time, and its pairs and the pairs whose
    // shift failed at the first vertex (temporal_reconnect.h).
    std::uint32_t temporalSpp = 0;
    double temporalMs = 0.0;
    std::uint64_t temporalPairs = 0, temporalFailures = 0;
};

struct RenderStats {
    std::uint32_t spp = 0;              // samples in every pixel
    std::uint32_t partialPassRows = 0;  // timed renders: rows (from the top) with one sample more
    std::uint32_t batches = 0;
    double bvhBuildMs = 0.0;
    std::uint64_t sceneDeviceBytes = 0;  // the scene's tables on the device (BVH, triangles, textures...)
    std::uint32_t bvhRegisterStack = 0;  // entries of the kernels' register traversal stack (0: in memory)
    bool bvhUnitSteps = false;           // the kernels traverse in unit steps (SceneSpec::bvhUnitSteps)
    // Emissive material -> NEE's probability of picking it, and whether the light probe set
    // them (SceneGpu::lightShares).
    std::map<std::uint32_t, double> lightShares;
    bool lightProbed = false;
    double uploadMs = 0.0;           // scene upload + pipeline creation (the part not overlapped)
    double pipelineWaitMs = 0.0;     // of which: waiting for the pipelines after the scene upload
    double compileMs = 0.0;          // the main kernels' first, empty, dispatch (lavapipe compiles there)
    double setupSeconds = 0.0;       // the render's time when sampling began (its fixed costs before it)
    double firstBatchSeconds = 0.0;  // this run's first batch (PT, G-PT: 1 spp; MLT: one step)
    double samplingLoad = 0.0;       // load factor over the batch loop (util/cpu_share.h); 0: not measured
    double reserveScale = 1.0;       // timed: the reservations at the last batch's load ÷ as measured
    double samplingMs = 0.0;         // wall time of the batch loop
    double readbackMs = 0.0;
    double reconstructionMs = 0.0;                     // G-PT: screened Poisson solve(s)
    std::vector<ReconstructionStats> reconstructions;  // G-PT: one per reconstruction, in order
    std::uint64_t raysTraced = 0;
    std::uint64_t pathsCompleted = 0;
    std::uint64_t nanSamples = 0;
    std::uint64_t shiftPairs = 0;                 // G-PT: shifts attempted (offsets in the image, base hit)
    std::uint64_t shiftFailures = 0;              // G-PT: shifts that failed (pair fell back to the base)
    bool gptSplitBounce = false;                  // G-PT, gmlt: the kernel ran the split bounce loop
    bool gptOcclusionBeams = false;               // G-PT: ... and traced the offsets' rays as beams
    std::uint32_t emitterSupersampling = 0;       // emitter supersampling factor (0 = off)
    std::uint32_t emitterRaysPerSample = 0;       // rays per camera sample it took (after its ray budget)
    std::uint32_t emitterSupersampledPixels = 0;  // pixels it covered
    std::uint32_t edgeSamples = 0;        // G-PT: extra samples per camera sample in edge pixels (0 = off)
    std::uint32_t edgePixels = 0;         // G-PT: pixels with the extra samples (edge pixels and neighbours)
    std::uint32_t edgeProbePixels = 0;    // G-PT: pixels a geometric edge crosses (the probe's)
    bool demodulated = false;             // G-PT: first-hit texture demodulation was on
    std::uint32_t demodulatedPixels = 0;  // G-PT: pixels it acted in (away from the edges)
    bool cancelled = false;
    // RenderOptions::combine took the statistics to finish the render elsewhere (or to write
    // them as a shard): no later stages ran, no layers.
    bool handedOff = false;
    DistributedStats distributed;
    MltStats mlt;
    TgptStats tgpt;
    std::map<std::string, vk::KernelTime> kernels;
    SceneFeatures features;
};

}  // namespace gdpt
