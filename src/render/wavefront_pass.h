// wavefront_pass.h — the wavefront schedule of the path tracer (wf_extend.comp +
// wf_shade.comp): one path per pixel in flight, a traversal-only kernel and a shading kernel
// alternating per bounce, the path state kept in a buffer. Same estimator as the megakernel
// (lib/pt_core.glsl); kept to measure the two schedules against each other
// (`gdpt render --schedule wavefront`).
#pragma once

#include <cstdint>
#include <functional>

#include "render/pt_pass.h"
#include "vk/buffer.h"
#include "vk/kernel.h"

namespace gdpt {

class SceneGpu;
namespace vk {
class CommandStream;
}

class WavefrontPass {
public:
    WavefrontPass(const vk::Context& ctx, const SceneGpu& scene, PtPass& pt, WorkgroupSize wg = {});
    // Traces sample `sampleIndex` of every pixel to completion (several submissions of
    // kBouncesPerSubmit bounces until no path is alive) and merges it into pt's statistics.
    void traceSample(vk::CommandStream& stream, std::uint32_t sampleIndex, std::uint32_t seed, vk::GpuTimer* timer,
                     const std::function<void()>& onWait);

private:
    const vk::Context& ctx_;
    std::uint32_t width_, height_;
    vk::Kernel extend_;
    vk::Kernel shade_;
    vk::Buffer paths_;
    vk::Buffer hits_;
    const vk::Buffer& counters_;
    VisiblePass& visible_;
};

}  // namespace gdpt
