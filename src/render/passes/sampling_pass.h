// sampling_pass.h — what the integrators' sampling driver (integrator/pixel_sampling.h) needs
// of a per-pixel sampling pass (PtPass, GptPass): bind the scene, wait for the pipelines,
// do one-off work before the first batch, record batches, and read or replace the
// per-pixel statistics. A pass that samples per pixel implements it; its images are read
// back through its own interface.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <vector>

#include "gdpt_shared.h"

namespace gdpt {

class SceneGpu;
class EmitterSupersamplingPass;
namespace vk {
class CommandStream;
class GpuTimer;
}  // namespace vk

class SamplingPass {
public:
    virtual ~SamplingPass() = default;
    // Binds the scene's buffers (once, before prepare()).
    virtual void attach(const SceneGpu& scene) = 0;
    // Work before the first batch that needs the scene but not the pass's main pipeline (it
    // may still be compiling); submits on `stream` and waits. Default: none.
    virtual void prepare(vk::CommandStream& stream) { (void)stream; }
    // Waits for pipelines created in the background; the seconds waited.
    virtual double waitForPipelines() const = 0;
    // Records one dispatch of each of the pass's main kernels that does no work (no rows):
    // lavapipe compiles a kernel to machine code at its first dispatch (seconds for the large
    // ones when its shader cache is cold), so this moves that compile before the first batch,
    // where a timed render counts it as a fixed cost and not as the price of a sample.
    virtual void recordWarmUp(VkCommandBuffer cmd) const = 0;
    // Records a batch of `spp` camera samples per pixel from sample `sampleBase`; `rows`:
    // only the first that many image rows (a timed render's partial last pass).
    virtual void record(VkCommandBuffer cmd, std::uint32_t sampleBase, std::uint32_t spp, std::uint32_t seed,
                        vk::GpuTimer* timer, std::uint32_t rows) = 0;
    // Reads the counters written since the last call and clears them (after the fence).
    virtual gpu::Counters takeCounters() = 0;
    // The raw per-pixel statistics (after the fence) and their replacement (before the next
    // record()) to continue a checkpointed render.
    [[nodiscard]] virtual std::vector<std::vector<gpu::PixelStats>> downloadStats() const = 0;
    virtual void uploadStats(const std::vector<std::vector<gpu::PixelStats>>& stats) = 0;
    [[nodiscard]] virtual const EmitterSupersamplingPass& emitterSupersampling() const = 0;
    // Whether the main kernel is a build that traces ray bundles in node steps, which picks its
    // traversal form by SceneSpec::bvhUnitSteps(device, bundles = true). Default: no.
    [[nodiscard]] virtual bool tracesBundles() const { return false; }
};

}  // namespace gdpt
