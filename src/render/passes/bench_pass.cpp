#include "render/passes/bench_pass.h"

#include "bench_rays.spv.h"
#include "bench_rays_units.spv.h"
#include "render/device_scene/scene_gpu.h"
#include "util/timer.h"
#include "vk/commands.h"
#include "vk/context.h"

namespace gdpt {
namespace {}  // namespace

BenchRaysPass::BenchRaysPass(const vk::Context& ctx, const SceneGpu& scene, WorkgroupSize wg)
    : ctx_(ctx),
      width_(scene.constants().width),
      height_(scene.constants().height),
      kernel_(ctx, scene.kernelDesc(GDPT_TRACING_KERNEL("bench_rays", bench_rays), ctx.info(), wg,
                                    {gpu::kBindCounters})),
      counters_(ctx, sizeof(gpu::Counters), "bench counters") {
    scene.bindTo(kernel_);
    kernel_.bind(gpu::kBindCounters, counters_);
}

BenchRaysPass::Result BenchRaysPass::run(std::uint32_t spp, bool incoherent, std::uint32_t seed) {
    counters_.zero();
    vk::CommandStream stream(ctx_, incoherent ? "bench incoherent rays" : "bench primary rays");
    gpu::FrameParams p{};
    p.samplesPerPixel = spp;
    p.seed = seed;
    p.rowOffset = 0;
    p.rowCount = height_;
    p.pad0 = incoherent ? 1u : 0u;
    VkCommandBuffer cmd = stream.begin();
    kernel_.dispatchItems(cmd, width_, height_, &p);
    vk::computeBarrier(cmd);
    Timer t;
    const double cpu0 = processCpuSeconds();
    stream.submitAndWait();
    Result r;
    r.seconds = t.seconds();
    r.cpuSeconds = processCpuSeconds() - cpu0;
    gpu::Counters c{};
    counters_.download(&c, sizeof c);
    r.rays = c.raysTraced;
    return r;
}

}  // namespace gdpt
