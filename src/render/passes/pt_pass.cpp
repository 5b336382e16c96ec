#include "render/passes/pt_pass.h"

#include <algorithm>

#include "pt.spv.h"
#include "pt_units.spv.h"
#include "render/device_scene/scene_gpu.h"
#include "util/error.h"
#include "util/parallel.h"
#include "vk/commands.h"
#include "vk/context.h"

namespace gdpt {
namespace {
// Upper bound of pixel-samples in one dispatch (about 0.3 s on lavapipe for the Cornell
// box); keeps every dispatch far below a GPU driver's watchdog timeout.
constexpr std::uint64_t kMaxPixelSamplesPerDispatch = 1u << 20;

}  // namespace

namespace {
vk::KernelDesc ptDesc(const SceneSpec& scene, const vk::DeviceInfo& device, WorkgroupSize wg,
                      const EmitterSupersamplingPass& visible) {
    vk::KernelDesc d =
        scene.kernelDesc(GDPT_TRACING_KERNEL("pt", pt), device, wg, {gpu::kBindAccum, gpu::kBindCounters});
    visible.configure(d);
    return d;
}
}  // namespace

std::uint32_t samplesPerDispatch(const vk::DeviceInfo& device, std::uint32_t batchSpp) {
    return device.isCpu ? std::min<std::uint32_t>(1, batchSpp) : batchSpp;
}

void recordTiled(VkCommandBuffer cmd, const vk::DeviceInfo& device, std::uint32_t width, std::uint32_t height,
                 std::uint32_t sampleBase, std::uint32_t spp, std::uint64_t maxPixelSamples,
                 const std::function<void(const DispatchTile&)>& dispatch) {
    const std::uint32_t step = samplesPerDispatch(device, spp);
    const std::uint64_t perRow = std::uint64_t{width} * step;
    const auto rowsPerDispatch = static_cast<std::uint32_t>(
        std::max<std::uint64_t>(1, maxPixelSamples / std::max<std::uint64_t>(perRow, 1)));
    for (std::uint32_t first = 0; first < spp; first += step) {
        for (std::uint32_t row = 0; row < height; row += rowsPerDispatch)
            dispatch({sampleBase + first, std::min(step, spp - first), row,
                      std::min(rowsPerDispatch, height - row)});
        vk::computeBarrier(cmd);
    }
}

PtPass::PtPass(const vk::Context& ctx, const SceneGpu& scene, WorkgroupSize wg,
               std::uint32_t emitterSupersampling)
    : PtPass(ctx, scene.spec(), wg, emitterSupersampling, vk::PipelineCreation::Now) {
    attach(scene);
}

PtPass::PtPass(const vk::Context& ctx, const SceneSpec& scene, WorkgroupSize wg,
               std::uint32_t emitterSupersampling, vk::PipelineCreation creation)
    : ctx_(ctx),
      width_(scene.width()),
      height_(scene.height()),
      // Its accumulation and emitter supersampling's statistics and probe.
      checked_(ctx, width_, height_,
               {{"the per-pixel statistics", sizeof(gpu::PixelStats)},
                {"the emitter-supersampling statistics", sizeof(gpu::PixelStats)},
                {"the emitter-supersampling probe and list", kEmitterProbeBytesPerPixel}}),
      counters_(ctx, sizeof(gpu::Counters), "pt counters"),
      emitterSupersampling_(ctx, scene, wg, emitterSupersampling, counters_, creation),
      kernel_(ctx, ptDesc(scene, ctx.info(), wg, emitterSupersampling_), creation),
      accum_(ctx, std::uint64_t{width_} * height_ * sizeof(gpu::PixelStats), "pt pixel statistics") {
    kernel_.bindAddress(gpu::kBindAccum, accum_);
    kernel_.bind(gpu::kBindCounters, counters_);
    emitterSupersampling_.bindTo(kernel_);
    reset();
}

void PtPass::attach(const SceneGpu& scene) {
    scene.bindTo(kernel_);
    emitterSupersampling_.attach(scene);
}

double PtPass::waitForPipelines() const {
    return emitterSupersampling_.waitForPipeline() + kernel_.wait();
}

void PtPass::reset() {
    accum_.zero();
    counters_.zero();
    emitterSupersampling_.reset();
}

void PtPass::record(VkCommandBuffer cmd, std::uint32_t sampleBase, std::uint32_t spp, std::uint32_t seed,
                    vk::GpuTimer* timer, std::uint32_t rows) {
    emitterSupersampling_.record(cmd, sampleBase, spp, seed, timer);
    recordTiled(cmd, ctx_.info(), width_, std::min(rows, height_), sampleBase, spp,
                kMaxPixelSamplesPerDispatch, [&](const DispatchTile& t) {
                    gpu::FrameParams p{};
                    setTileParams(p, t, seed);
                    kernel_.dispatchItems(cmd, width_, p.rowCount, &p, timer);
                });
}

void PtPass::recordWarmUp(VkCommandBuffer cmd) const {
    gpu::FrameParams p{};
    p.rowCount = 0;  // every invocation returns at once
    kernel_.dispatch(cmd, 1, 1, 1, &p, nullptr);
}

gpu::Counters PtPass::takeCounters() {
    gpu::Counters c{};
    counters_.download(&c, sizeof c);
    counters_.zero();
    return c;
}

std::vector<std::vector<gpu::PixelStats>> PtPass::downloadStats() const {
    return {accum_.downloadVector<gpu::PixelStats>(std::size_t{width_} * height_),
            emitterSupersampling_.downloadStats()};
}

void PtPass::uploadStats(const std::vector<std::vector<gpu::PixelStats>>& stats) {
    if (stats.size() != 2)
        throw Error("pt pixel statistics: " + std::to_string(stats.size()) +
                    " buffers, expected 2 (path samples, visible emission)");
    if (stats[0].size() != std::size_t{width_} * height_)
        throw Error("pt pixel statistics: " + std::to_string(stats[0].size()) + " entries for a " +
                    std::to_string(width_) + "x" + std::to_string(height_) + " image");
    accum_.uploadVector(stats[0]);
    emitterSupersampling_.uploadStats(stats[1]);
}

void statsToImages(const gpu::PixelStats* stats, std::uint32_t width, std::uint32_t height, Image& mean,
                   Image& varianceOfMean) {
    const std::size_t pixels = std::size_t{width} * height;
    mean = Image(static_cast<int>(width), static_cast<int>(height));
    varianceOfMean = Image(static_cast<int>(width), static_cast<int>(height));
    parallelRanges(0, pixels, std::size_t{1} << 14, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) {
            const auto& s = stats[i];
            const float n = static_cast<float>(s.count);
            for (int c = 0; c < 3; ++c) {
                mean.plane(c)[i] = s.mean[c];
                // Unbiased sample variance divided by n = variance of the mean estimate.
                varianceOfMean.plane(c)[i] = s.count > 1 ? s.m2[c] / (n - 1.0f) / n : 0.0f;
            }
        }
    });
}

void PtPass::readback(Image& mean, Image& varianceOfMean) const {
    const auto stats = accum_.read<gpu::PixelStats>(std::size_t{width_} * height_);
    statsToImages(stats.data(), width_, height_, mean, varianceOfMean);
    // Independent estimates of two parts of the pixel: their means and variances add.
    emitterSupersampling_.addTo(&mean, &varianceOfMean);
}

}  // namespace gdpt
