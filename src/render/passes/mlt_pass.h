// mlt_pass.h — the Metropolis pass: owns mlt.comp (bootstrap, chain start, mutation steps and
// the very-direct image; see the kernel for the phases) and the buffers it writes. The
// integrator (integrator/mlt_integrator.h) drives the phases and splats the records.
#pragma once

#include <cstdint>
#include <vector>

#include "image/image.h"
#include "mlt_shared.h"
#include "render/device_scene/scene_gpu.h"
#include "render/passes/emitter_supersampling_pass.h"
#include "render/passes/gpt_pass.h"
#include "vk/buffer.h"
#include "vk/kernel.h"

namespace gdpt {

namespace vk {
class Context;
class CommandStream;
class GpuTimer;
}  // namespace vk

struct MltPassOptions {
    bool baseOnly = false;            // PSSMLT: the base path alone; else G-MLT (base + offsets)
    std::uint32_t chains = 4096;      // Markov chains run at once
    std::uint32_t stepsPerBatch = 8;  // mutation steps a batch records (records buffer size)
    float largeStep = 0.5f;           // probability of a large step
    float targetAlpha = 0.25f;        // G-MLT: weight of the primal term of the target
    float targetExponent = 1.0f;      // the target walked is the method's to this power
    // Rays per camera sample of the very-direct image in the pixels where the emission the camera
    // sees changes (emitter supersampling, emitter_supersampling_pass.h); 0: off.
    std::uint32_t emitterSupersampling = kDefaultEmitterSupersampling;
    // G-MLT: the sample's split bounce loop (mlt.comp's mlt_split build, as gpt_split; the same
    // values either way). PSSMLT traces the path tracer's path and has no such loop.
    GptPassOptions::SplitBounce splitBounce = GptPassOptions::SplitBounce::Auto;
};

// Counters of the chains (summed over chains, from their MltChain).
struct MltAcceptance {
    std::uint64_t proposedSmall = 0, acceptedSmall = 0, proposedLarge = 0, acceptedLarge = 0;
};

class MltPass {
public:
    // Pipelines created as `creation` says (Background: while the caller builds the SceneGpu);
    // attach() binds the scene's buffers.
    MltPass(const vk::Context& ctx, const SceneSpec& spec, WorkgroupSize wg, MltPassOptions options,
            vk::PipelineCreation creation);
    void attach(const SceneGpu& scene);
    double waitForPipelines() const;
    // Records one dispatch that does no work (the direct phase with no rows): lavapipe compiles
    // the kernel to machine code at its first dispatch (seconds with a cold shader cache), so
    // that compile is timed here and not as the bootstrap's or the very-direct light's
    // (SamplingPass::recordWarmUp for PT and G-PT).
    void recordWarmUp(VkCommandBuffer cmd) const;

    // Records `count` bootstrap samples from sample index `first` into the bootstrap buffer
    // (capacity: the count of the first call, which allocates it).
    void recordBootstrap(VkCommandBuffer cmd, std::uint32_t first, std::uint32_t count, std::uint32_t seed,
                         vk::GpuTimer* timer);
    // Their targets and pixels (after the fence).
    [[nodiscard]] std::vector<gpu::MltBootstrapSample> bootstrapSamples(std::uint32_t count) const;
    // The divisors of the target per image block of `block` pixels square (row-major,
    // ceil(width / block) per row), for the chains recorded after; block 0: none.
    void setNormaliser(std::uint32_t block, const std::vector<float>& divisors);
    // Starts chain c at bootstrap sample starts[c] (starts.size() == chains).
    void recordStart(VkCommandBuffer cmd, const std::vector<std::uint32_t>& starts, std::uint32_t seed,
                     vk::GpuTimer* timer);
    // b' of the splat weights (mlt.glsl; the bootstrap's b̂), for the mutations recorded after.
    void setMisNormalisation(float b) { misNormalisation_ = b; }
    // Records `steps` (≤ stepsPerBatch) mutation steps of every chain, step indices from `first`.
    void recordMutations(VkCommandBuffer cmd, std::uint32_t first, std::uint32_t steps, std::uint32_t seed,
                         vk::GpuTimer* timer);
    // The records of the last batch of `steps` steps, in step then chain order (after the fence).
    [[nodiscard]] const gpu::MltRecord* records(std::uint32_t steps);
    // The very-direct image, `samples` stratified camera samples per pixel; in the pixels
    // where the emission changes within their neighbourhood (an emitter's rim), `samples`
    // camera samples of emitterSupersampling rays each instead (PT's and G-PT's emitter
    // supersampling).
    void recordDirect(VkCommandBuffer cmd, std::uint32_t samples, std::uint32_t seed, vk::GpuTimer* timer);
    [[nodiscard]] Image directImage() const;
    // The emitter supersampling of the very-direct image (its report, after recordDirect's fence).
    [[nodiscard]] const EmitterSupersamplingPass& emitterSupersampling() const { return visible_; }
    [[nodiscard]] MltAcceptance acceptance() const;
    // Reads the counters written since the last call and clears them (after the fence).
    gpu::Counters takeCounters();
    [[nodiscard]] const MltPassOptions& options() const { return options_; }
    // Whether the kernel is the split bounce loop build (mlt_split; G-MLT only).
    [[nodiscard]] bool splitBounceCompiled() const { return splitBounce_; }

private:
    [[nodiscard]] gpu::MltParams params(std::uint32_t phase, std::uint32_t count, std::uint32_t seed) const;
    void dispatchChains(VkCommandBuffer cmd, const gpu::MltParams& p, vk::GpuTimer* timer) const;

    const vk::Context& ctx_;
    std::uint32_t width_, height_;
    float shiftThreshold_;
    float misNormalisation_ = 0.0f;
    MltPassOptions options_;
    vk::Buffer counters_, chains_, pss_, records_, starts_, direct_;
    vk::Buffer bootstrap_, normaliser_;
    std::uint32_t normaliseBlock_ = 0, normaliseColumns_ = 0;  // setNormaliser's blocks
    std::vector<gpu::MltRecord> host_;
    bool splitBounce_;
    vk::Kernel kernel_;
    EmitterSupersamplingPass visible_;
};

}  // namespace gdpt
