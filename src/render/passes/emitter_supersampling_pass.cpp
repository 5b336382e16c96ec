#include "render/passes/emitter_supersampling_pass.h"

#include <algorithm>
#include <cstddef>
#include <string>

#include "emitter_supersampling.spv.h"
#include "emitter_supersampling_units.spv.h"
#include "util/error.h"
#include "vk/commands.h"
#include "vk/context.h"

namespace gdpt {
namespace {
// Refine rays per camera sample over the whole image: a quarter of a ray per pixel, so
// that a scene whose emission edges are everywhere (an emissive texture filling the view)
// costs at most about a quarter of a primary ray per pixel and sample more (a G-PT sample
// traces about 17 rays, a PT sample 3 to 4).
std::uint32_t rayBudget(std::uint32_t width, std::uint32_t height) {
    return std::max<std::uint32_t>(1, width * height / 4);
}

// The factor the pass runs with: 0 (disabled) where the scene has nothing the camera could
// see emit. Throws for a factor above the bound.
std::uint32_t activeFactor(std::uint32_t samplesPerSpp, const SceneSpec& scene) {
    if (samplesPerSpp > kMaxEmitterSupersampling)
        throw Error("emitter supersampling " + std::to_string(samplesPerSpp) + " is above the maximum " +
                    std::to_string(kMaxEmitterSupersampling));
    return emitterSupersamplingPossible(scene.features()) ? samplesPerSpp : 0;
}
}  // namespace

EmitterSupersamplingPass::EmitterSupersamplingPass(const vk::Context& ctx, const SceneGpu& scene,
                                                   WorkgroupSize wg, std::uint32_t samplesPerSpp,
                                                   const vk::Buffer& counters)
    : EmitterSupersamplingPass(ctx, scene.spec(), wg, samplesPerSpp, counters, vk::PipelineCreation::Now) {
    attach(scene);
}

EmitterSupersamplingPass::EmitterSupersamplingPass(const vk::Context& ctx, const SceneSpec& scene,
                                                   WorkgroupSize wg, std::uint32_t samplesPerSpp,
                                                   const vk::Buffer& counters, vk::PipelineCreation creation)
    : width_(scene.width()),
      height_(scene.height()),
      samplesPerSpp_(activeFactor(samplesPerSpp, scene)),
      // Disabled: 16-byte placeholders (the path kernels compile the read out).
      stats_(ctx, enabled() ? std::uint64_t{width_} * height_ * sizeof(gpu::PixelStats) : 0,
             "emitter-supersampling statistics"),
      probe_(ctx, enabled() ? std::uint64_t{width_} * height_ * kEmitterProbeBytesPerPixel : 0,
             "emitter-supersampling probe and list"),
      counter_(ctx, sizeof(gpu::VisibleCounter), "emitter-supersampling counter") {
    if (!enabled()) return;
    vk::KernelDesc d = scene.kernelDesc(
        GDPT_TRACING_KERNEL("emitter_supersampling", emitter_supersampling), ctx.info(), wg,
        {gpu::kBindCounters, gpu::kBindVisibleStats, gpu::kBindVisibleProbe, gpu::kBindVisibleCounter},
        sizeof(gpu::VisibleParams));
    kernel_.emplace(ctx, d, creation);
    kernel_->bind(gpu::kBindCounters, counters);
    kernel_->bindAddress(gpu::kBindVisibleStats, stats_);
    kernel_->bindAddress(gpu::kBindVisibleProbe, probe_);
    kernel_->bind(gpu::kBindVisibleCounter, counter_);
    reset();
}

void EmitterSupersamplingPass::attach(const SceneGpu& scene) {
    if (kernel_) scene.bindTo(*kernel_);
}

void EmitterSupersamplingPass::configure(vk::KernelDesc& desc) const {
    desc.bindings.push_back(gpu::kBindVisibleStats);
    desc.specConstants.push_back({gpu::kSpecVisibleEmission, enabled() ? 1u : 0u});
}

void EmitterSupersamplingPass::bindTo(vk::Kernel& kernel) const {
    kernel.bindAddress(gpu::kBindVisibleStats, stats_);
}

void EmitterSupersamplingPass::reset() {
    stats_.zero();
    counter_.zero();
    probed_ = false;
}

void EmitterSupersamplingPass::record(VkCommandBuffer cmd, std::uint32_t sampleBase, std::uint32_t spp,
                                      std::uint32_t seed, vk::GpuTimer* timer) {
    if (!enabled() || spp == 0) return;
    gpu::VisibleParams p{};
    p.sampleBase = sampleBase;
    p.samplesPerPixel = spp;
    p.seed = seed;
    p.samplesPerSpp = samplesPerSpp_;
    p.rayBudget = rayBudget(width_, height_);
    if (!probed_ || probeSeed_ != seed) {
        // The probe, the list and the refine dispatch's size: the same for every batch of a
        // render with this seed, so a resumed render redoes them and refines the same pixels.
        counter_.zero();
        p.phase = gpu::kVisiblePhaseProbe;
        kernel_->dispatchItems(cmd, width_, height_, &p, timer);
        vk::computeBarrier(cmd);
        p.phase = gpu::kVisiblePhaseCount;
        kernel_->dispatchItems(cmd, width_, height_, &p, timer);
        vk::computeBarrier(cmd);
        p.phase = gpu::kVisiblePhaseArgs;
        kernel_->dispatch(cmd, 1, 1, 1, &p, timer);
        vk::computeBarrier(cmd);
        probed_ = true;
        probeSeed_ = seed;
    }
    p.phase = gpu::kVisiblePhaseRefine;
    kernel_->dispatchIndirect(cmd, counter_, offsetof(gpu::VisibleCounter, groupsX), &p, timer);
    vk::computeBarrier(cmd);
}

std::vector<gpu::PixelStats> EmitterSupersamplingPass::downloadStats() const {
    if (!enabled()) return std::vector<gpu::PixelStats>(std::size_t{width_} * height_);
    return stats_.downloadVector<gpu::PixelStats>(std::size_t{width_} * height_);
}

void EmitterSupersamplingPass::uploadStats(const std::vector<gpu::PixelStats>& stats) {
    if (stats.size() != std::size_t{width_} * height_)
        throw Error("emitter-supersampling statistics: " + std::to_string(stats.size()) + " entries for a " +
                    std::to_string(width_) + "x" + std::to_string(height_) + " image");
    if (!enabled()) {
        const bool empty =
            std::all_of(stats.begin(), stats.end(), [](const gpu::PixelStats& s) { return s.count == 0; });
        if (!empty)
            throw Error("emitter-supersampling statistics have samples, but emitter supersampling is off");
        return;
    }
    stats_.uploadVector(stats);
}

void EmitterSupersamplingPass::addTo(Image* mean, Image* varianceOfMean) const {
    if (!enabled()) return;
    const auto stats = downloadStats();
    for (std::size_t i = 0; i < stats.size(); ++i) {
        const gpu::PixelStats& s = stats[i];
        if (s.count == 0) continue;
        const float n = static_cast<float>(s.count);
        for (int c = 0; c < 3; ++c) {
            if (mean) mean->plane(c)[i] += s.mean[c];
            // Over camera samples (each the mean of its k rays): rays that stratify the pixel
            // across samples make this an upper bound.
            if (varianceOfMean && s.count > 1) varianceOfMean->plane(c)[i] += s.m2[c] / (n - 1.0f) / n;
        }
    }
}

void EmitterSupersamplingPass::replaceIn(Image& image) const {
    if (!enabled()) return;
    const auto stats = downloadStats();
    for (std::size_t i = 0; i < stats.size(); ++i)
        if (stats[i].count > 0)
            for (int c = 0; c < 3; ++c) image.plane(c)[i] = stats[i].mean[c];
}

gpu::VisibleCounter EmitterSupersamplingPass::report() const {
    gpu::VisibleCounter c{};
    if (enabled() && probed_) counter_.download(&c, sizeof c);
    return c;
}

}  // namespace gdpt
