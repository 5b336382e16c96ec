// temporal_reconnect_pass.h — the temporal reconnection shift's pass (tgpt_reconnect.comp): the
// kernel over a frame pair on the device (SceneGpu's two-frame form), each pixel's partner in the
// other frame, and per direction the statistics of the pair-weighted differences and of the base
// paths' own radiance. Direction d samples its base paths in frame d and their offsets in frame
// 1 − d; the temporal difference from pixel p of frame 0 to its partner q of frame 1 is
// D_0(p) − D_1(q) (docs/animation.md, "The reconnection shift").
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "gdpt_shared.h"
#include "image/image.h"
#include "render/device_scene/scene_gpu.h"
#include "render/passes/pixel_buffers.h"
#include "temporal_shared.h"
#include "vk/buffer.h"
#include "vk/kernel.h"

namespace gdpt {

namespace vk {
class Context;
class GpuTimer;
}  // namespace vk

// One direction's statistics as images: per pixel the mean and the variance of the mean of the
// pair-weighted differences and of the base paths' radiance.
struct TemporalDirectionImages {
    Image difference, varDifference, base, varBase;
};

class TemporalReconnectPass {
public:
    // `pair`: the two frames (SceneGpu(ctx, a, b, options)); it must outlive the pass.
    // `partners`: each pixel's partner in the other frame, per direction (width·height entries
    // each; pixel kInvalidIndex: no difference at that pixel).
    TemporalReconnectPass(const vk::Context& ctx, const SceneGpu& pair,
                          const std::array<std::vector<gpu::TemporalPartner>, 2>& partners,
                          WorkgroupSize wg = {});

    // Clears the statistics and counters.
    void reset();
    // Records `spp` samples per pixel from sample index `sampleBase` in both directions, direction
    // d with seed seeds[d]; `flags`: gpu::kTemporalFlag* (tests).
    void record(VkCommandBuffer cmd, std::uint32_t sampleBase, std::uint32_t spp,
                std::array<std::uint32_t, 2> seeds, std::uint32_t flags = 0, vk::GpuTimer* timer = nullptr);
    // After the fence: the counters written since the last call (cleared), and each direction's
    // statistics.
    gpu::Counters takeCounters();
    [[nodiscard]] std::array<TemporalDirectionImages, 2> readback() const;
    double waitForPipeline() const { return kernel_.wait(); }

private:
    const vk::Context& ctx_;
    std::uint32_t width_, height_;
    PixelBuffersChecked checked_;  // before any buffer below exists
    vk::Buffer counters_;
    vk::Kernel kernel_;
    vk::Buffer partners_, differences_, bases_;  // two directions' entries, direction 0's first
};

}  // namespace gdpt
