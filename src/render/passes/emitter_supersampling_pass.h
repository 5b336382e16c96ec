// emitter_supersampling_pass.h — emitter supersampling (emitter_supersampling.comp): a separate estimate of
// the emission the camera sees at its first hit, in the pixels where it changes within the
// pixel's 3x3 neighbourhood, with `samplesPerSpp` stratified first-hit rays per camera
// sample. PtPass and GptPass each own one; their kernels leave that term out in the pixels
// it covers (shaders/lib/visible_emission.glsl), and their readbacks add its estimate back.
//
// The pass is disabled (no pipeline, nothing recorded, all counts zero) when the factor is
// 0 or the scene has nothing the camera could see emit (no emissive triangle, no
// environment).
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "gdpt_shared.h"
#include "image/image.h"
#include "render/device_scene/scene_gpu.h"
#include "render/passes/emitter_supersampling_options.h"
#include "vk/buffer.h"
#include "vk/kernel.h"

namespace gdpt {

// Bytes per pixel of the pass's probe buffer: the probe's signature, then the list of the
// refined pixels, which may hold every pixel (emitter_supersampling.comp).
inline constexpr std::uint64_t kEmitterProbeBytesPerPixel = 2 * sizeof(std::uint32_t);

namespace vk {
class Context;
class GpuTimer;
}  // namespace vk

class EmitterSupersamplingPass {
public:
    // samplesPerSpp in [0, kMaxEmitterSupersampling]; 0 disables the pass.
    EmitterSupersamplingPass(const vk::Context& ctx, const SceneGpu& scene, WorkgroupSize wg,
                             std::uint32_t samplesPerSpp, const vk::Buffer& counters);
    // The same before the scene is on the device: the pipeline is created as `creation`
    // says, and attach() binds the scene's buffers once they exist (before record()).
    EmitterSupersamplingPass(const vk::Context& ctx, const SceneSpec& spec, WorkgroupSize wg,
                             std::uint32_t samplesPerSpp, const vk::Buffer& counters,
                             vk::PipelineCreation creation);
    void attach(const SceneGpu& scene);
    // Waits for a pipeline created in the background; the seconds waited.
    double waitForPipeline() const { return kernel_ ? kernel_->wait() : 0.0; }

    [[nodiscard]] bool enabled() const { return samplesPerSpp_ > 0; }
    // Adds what a kernel that reads the statistics needs to its descriptor: the binding
    // kBindVisibleStats and the constant kSpecVisibleEmission (off when disabled).
    void configure(vk::KernelDesc& desc) const;
    // Binds the statistics (kBindVisibleStats) to such a kernel.
    void bindTo(vk::Kernel& kernel) const;
    // Records the probe (once per seed, the first time) and the refine rays of a batch of
    // `spp` camera samples from `sampleBase`, then a barrier; the path kernels of the batch
    // are recorded after it. Nothing when disabled.
    void record(VkCommandBuffer cmd, std::uint32_t sampleBase, std::uint32_t spp, std::uint32_t seed,
                vk::GpuTimer* timer);
    // Clears the statistics (and forgets the probe).
    void reset();
    // The statistics (after the fence), for checkpoints, and their replacement.
    [[nodiscard]] std::vector<gpu::PixelStats> downloadStats() const;
    void uploadStats(const std::vector<gpu::PixelStats>& stats);
    // Adds the supersampled estimate's mean to `mean` and its variance of the mean to
    // `varianceOfMean` (either may be null) in the refined pixels (after the fence).
    void addTo(Image* mean, Image* varianceOfMean) const;
    // Sets `image` to the supersampled estimate's mean in the refined pixels (after the fence):
    // for a caller whose own estimate of the term covers every pixel (mlt_pass.h).
    void replaceIn(Image& image) const;
    // Refined pixels of the current probe and the rays per camera sample they get (the
    // factor, less where the ray budget cut it), after the fence of a record(); 0 before.
    [[nodiscard]] gpu::VisibleCounter report() const;
    [[nodiscard]] std::uint32_t samplesPerSpp() const { return samplesPerSpp_; }

private:
    std::uint32_t width_, height_;
    std::uint32_t samplesPerSpp_;
    std::optional<vk::Kernel> kernel_;
    vk::Buffer stats_;
    vk::Buffer probe_;
    vk::Buffer counter_;
    bool probed_ = false;
    std::uint32_t probeSeed_ = 0;
};

}  // namespace gdpt
