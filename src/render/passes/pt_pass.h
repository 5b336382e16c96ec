// pt_pass.h — the path-tracing pass: owns the pt.comp kernel, the per-pixel statistics and
// the counters it writes. record() appends one batch (tiled in rows so that no single
// dispatch runs long enough to trip a GPU watchdog).
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "gdpt_shared.h"
#include "image/image.h"
#include "render/device_scene/scene_gpu.h"
#include "render/passes/emitter_supersampling_pass.h"
#include "render/passes/pixel_buffers.h"
#include "render/passes/sampling_pass.h"
#include "vk/buffer.h"
#include "vk/kernel.h"

namespace gdpt {

namespace vk {
class Context;
class GpuTimer;
struct DeviceInfo;
}  // namespace vk

// Camera samples per pixel that one dispatch of a path kernel may take. llvmpipe ends any
// outermost loop of a shader after 65535 iterations, silently, counting the iterations of
// the loops nested in it (LP_MAX_TGSI_LOOP_ITERATIONS; see poisson_scalars.comp): the loop
// over a pixel's samples, around the bounce loop and the BVH traversals, crossed that with
// long paths (a 100-bounce furnace lost 14 % of its energy at 16 samples per dispatch), so
// CPU devices take one sample per dispatch and the bounce loop is outermost. Elsewhere the
// whole batch.
std::uint32_t samplesPerDispatch(const vk::DeviceInfo& device, std::uint32_t batchSpp);

// One dispatch of a batch: camera samples [sampleBase, sampleBase + samples) of the image
// rows [rowOffset, rowOffset + rowCount).
struct DispatchTile {
    std::uint32_t sampleBase, samples, rowOffset, rowCount;
};

// Fills the tile's fields of a path kernel's push constants (gpu::FrameParams and
// gpu::GptFrameParams begin with the same five).
template <class Params>
void setTileParams(Params& p, const DispatchTile& t, std::uint32_t seed) {
    p.sampleBase = t.sampleBase;
    p.samplesPerPixel = t.samples;
    p.seed = seed;
    p.rowOffset = t.rowOffset;
    p.rowCount = t.rowCount;
}

// Records a batch of `spp` camera samples from `sampleBase` of a width x height image as
// dispatches of samplesPerDispatch samples and at most maxPixelSamples pixel-samples each
// (row tiles, so that no dispatch runs long enough to trip a GPU watchdog), calling
// `dispatch` per tile and recording a compute barrier after each step of samples (every
// dispatch of a step writes disjoint pixels; the next step merges into the same ones).
void recordTiled(VkCommandBuffer cmd, const vk::DeviceInfo& device, std::uint32_t width, std::uint32_t height,
                 std::uint32_t sampleBase, std::uint32_t spp, std::uint64_t maxPixelSamples,
                 const std::function<void(const DispatchTile&)>& dispatch);

// Each pixel's mean and the variance of that mean (the unbiased sample variance over n; 0 below
// two samples) of `stats` (width·height entries), as images.
void statsToImages(const gpu::PixelStats* stats, std::uint32_t width, std::uint32_t height, Image& mean,
                   Image& varianceOfMean);

class PtPass final : public SamplingPass {
public:
    // emitterSupersampling: rays per camera sample of emitter supersampling
    // (emitter_supersampling_pass.h; 0 = off).
    PtPass(const vk::Context& ctx, const SceneGpu& scene, WorkgroupSize wg = {},
           std::uint32_t emitterSupersampling = kDefaultEmitterSupersampling);
    // The same before the scene is on the device: the pipelines are created as `creation`
    // says (Background: while the caller builds the SceneGpu), and attach() binds the
    // scene's buffers (before record()).
    PtPass(const vk::Context& ctx, const SceneSpec& spec, WorkgroupSize wg,
           std::uint32_t emitterSupersampling, vk::PipelineCreation creation);
    void attach(const SceneGpu& scene) override;
    // Waits for pipelines created in the background; the seconds waited.
    double waitForPipelines() const override;
    void recordWarmUp(VkCommandBuffer cmd) const override;

    // Clears the statistics and counters.
    void reset();
    // Records a batch of `spp` samples per pixel starting at sample index `sampleBase`.
    // `rows`: only the first that many image rows (a timed render's partial last pass).
    void record(VkCommandBuffer cmd, std::uint32_t sampleBase, std::uint32_t spp, std::uint32_t seed,
                vk::GpuTimer* timer, std::uint32_t rows = UINT32_MAX) override;
    // Reads the counters written since the last call and clears them (after the fence).
    gpu::Counters takeCounters() override;
    // Mean radiance and the variance of that mean, per pixel (after the fence); includes
    // the supersampled visible emission.
    void readback(Image& mean, Image& varianceOfMean) const;
    // The raw per-pixel statistics (after the fence): the path samples', then the
    // supersampled visible emission's; and their replacement (before the next record()) to
    // continue a checkpointed render (two buffers of width*height entries).
    [[nodiscard]] std::vector<std::vector<gpu::PixelStats>> downloadStats() const override;
    void uploadStats(const std::vector<std::vector<gpu::PixelStats>>& stats) override;
    [[nodiscard]] EmitterSupersamplingPass& emitterSupersampling() { return emitterSupersampling_; }
    [[nodiscard]] const EmitterSupersamplingPass& emitterSupersampling() const override {
        return emitterSupersampling_;
    }

private:
    const vk::Context& ctx_;
    std::uint32_t width_, height_;
    PixelBuffersChecked checked_;  // before any buffer below exists
    vk::Buffer counters_;
    EmitterSupersamplingPass emitterSupersampling_;
    vk::Kernel kernel_;
    vk::Buffer accum_;
};

}  // namespace gdpt
