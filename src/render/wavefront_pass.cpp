#include "render/wavefront_pass.h"

#include <cstddef>

#include "render/scene_gpu.h"
#include "vk/commands.h"
#include "vk/context.h"
#include "vk/timing.h"
#include "wf_extend.spv.h"
#include "wf_shade.spv.h"

namespace gdpt {
namespace {

constexpr std::uint32_t kBouncesPerSubmit = 6;

}  // namespace

namespace {
vk::KernelDesc shadeDesc(const SceneGpu& scene, WorkgroupSize wg, const VisiblePass& visible) {
    vk::KernelDesc d = scene.kernelDesc(vk::kernelDesc("wf_shade", GDPT_KERNEL_SPIRV(wf_shade)), wg,
                                        {gpu::kBindAccum, gpu::kBindCounters, gpu::kBindPathState, gpu::kBindPathHits});
    visible.configure(d);
    return d;
}
}  // namespace

WavefrontPass::WavefrontPass(const vk::Context& ctx, const SceneGpu& scene, PtPass& pt, WorkgroupSize wg)
    : ctx_(ctx),
      width_(scene.constants().width),
      height_(scene.constants().height),
      extend_(ctx, scene.kernelDesc(vk::kernelDesc("wf_extend", GDPT_KERNEL_SPIRV(wf_extend)), wg,
                                    {gpu::kBindPathState, gpu::kBindPathHits})),
      shade_(ctx, shadeDesc(scene, wg, pt.visible())),
      paths_(ctx, std::uint64_t{width_} * height_ * sizeof(gpu::PathState), "wavefront path state"),
      hits_(ctx, std::uint64_t{width_} * height_ * sizeof(glm::vec4), "wavefront hits"),
      counters_(pt.counters()),
      visible_(pt.visible()) {
    ctx.checkStorageBufferSize(paths_.size(), "the wavefront path state");
    scene.bindTo(extend_);
    scene.bindTo(shade_);
    extend_.bind(gpu::kBindPathState, paths_);
    extend_.bind(gpu::kBindPathHits, hits_);
    shade_.bind(gpu::kBindAccum, pt.accum());
    shade_.bind(gpu::kBindCounters, pt.counters());
    shade_.bind(gpu::kBindPathState, paths_);
    shade_.bind(gpu::kBindPathHits, hits_);
    visible_.bindTo(shade_);
}

void WavefrontPass::traceSample(vk::CommandStream& stream, std::uint32_t sampleIndex, std::uint32_t seed,
                                vk::GpuTimer* timer, const std::function<void()>& onWait) {
    gpu::FrameParams p{};
    p.sampleBase = sampleIndex;
    p.samplesPerPixel = 1;
    p.seed = seed;
    p.rowCount = height_;
    bool first = true;
    while (true) {
        VkCommandBuffer cmd = stream.begin();
        if (timer) timer->reset(cmd);
        if (first) {
            visible_.record(cmd, sampleIndex, 1, seed, timer);
            p.pad0 = 0;  // start the paths
            shade_.dispatchItems(cmd, width_, height_, &p, timer);
            vk::computeBarrier(cmd);
            first = false;
        }
        p.pad0 = 1;
        for (std::uint32_t b = 0; b < kBouncesPerSubmit; ++b) {
            extend_.dispatchItems(cmd, width_, height_, &p, timer);
            vk::computeBarrier(cmd);
            if (b + 1 == kBouncesPerSubmit) {
                // Every shade dispatch counts live paths into counters.pad; clearing it
                // before the last one leaves the number alive at the end of this submission.
                vkCmdFillBuffer(cmd, counters_.get(), offsetof(gpu::Counters, pad), sizeof(std::uint32_t), 0);
                vk::computeBarrier(cmd);
            }
            shade_.dispatchItems(cmd, width_, height_, &p, timer);
            vk::computeBarrier(cmd);
        }
        stream.submit();
        stream.waitAll(onWait);
        if (timer) timer->collect();
        gpu::Counters c{};
        counters_.download(&c, sizeof c);
        if (c.pad == 0) break;
    }
}

}  // namespace gdpt
