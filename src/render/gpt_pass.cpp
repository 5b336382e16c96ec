#include "render/gpt_pass.h"

#include <algorithm>
#include <string>

#include "gpt.spv.h"
#include "gpt_split.spv.h"
#include "gpt_resolve.spv.h"
#include "render/scene_gpu.h"
#include "util/error.h"
#include "vk/commands.h"
#include "vk/context.h"

namespace gdpt {
namespace {
// Pixel-samples per dispatch: a G-PT sample costs about three PT samples on lavapipe (2.5x
// the rays), so this bound keeps each dispatch within ~1.5x of PtPass's (well below any
// watchdog) while keeping dispatches few.
constexpr std::uint64_t kMaxPixelSamplesPerDispatch = 1u << 19;
constexpr std::uint32_t kNumStats = 10;  // bindings kBindGptCentral .. kBindGptDirect

const char* const kStatNames[kNumStats] = {"gpt central",    "gpt neighbor right", "gpt neighbor down",
                                           "gpt neighbor left", "gpt neighbor up",  "gpt gradient right",
                                           "gpt gradient down", "gpt gradient left", "gpt gradient up",
                                           "gpt direct"};

// Whether some vertex can be classified glossy: a specular layer at or below the threshold,
// or one below bsdf.glsl's Dirac cutoff (perceptual roughness 0.01), which
// bsdfRoughnessForShift reports as 0 whatever the threshold. Same rule as features.cpp's
// hasGlossy, evaluated here for the pass's own threshold (GptPassOptions::shiftThreshold).
bool needsHalfVector(const SceneSpec& scene, float threshold) {
    const SceneFeatures& f = scene.features();
    constexpr float kDiracRoughness = 0.01f;  // sqrt(kDeltaAlpha)
    return f.hasSpecularLayer && (f.minRoughness <= threshold || f.minRoughness < kDiracRoughness);
}

bool splitBounceFor(const vk::DeviceInfo& device, GptPassOptions::SplitBounce s) {
    if (s == GptPassOptions::SplitBounce::Auto) return splitBounceDefault(device);
    return s == GptPassOptions::SplitBounce::On;
}

vk::KernelDesc gptDesc(const SceneSpec& scene, WorkgroupSize wg, bool halfVector, bool splitBounce,
                       const VisiblePass& visible) {
    std::vector<std::uint32_t> extra = {gpu::kBindCounters};
    for (std::uint32_t i = 0; i < kNumStats; ++i) extra.push_back(gpu::kBindGptCentral + i);
    vk::KernelDesc d = scene.kernelDesc(splitBounce ? vk::kernelDesc("gpt", GDPT_KERNEL_SPIRV(gpt_split))
                                                    : vk::kernelDesc("gpt", GDPT_KERNEL_SPIRV(gpt)),
                                        wg, extra, sizeof(gpu::GptFrameParams));
    for (auto& [id, value] : d.specConstants)
        if (id == gpu::kSpecHasGlossy) value = halfVector ? 1u : 0u;
    visible.configure(d);
    EdgePass::configure(d);
    return d;
}

vk::KernelDesc resolveDesc(WorkgroupSize wg, const VisiblePass& visible) {
    vk::KernelDesc d = vk::kernelDesc("gpt_resolve", GDPT_KERNEL_SPIRV(gpt_resolve));
    for (std::uint32_t i = 0; i < kNumStats; ++i) d.bindings.push_back(gpu::kBindGptCentral + i);
    d.bindings.push_back(gpu::kBindGptResolved);
    d.pushConstantBytes = sizeof(gpu::GptFrameParams);
    d.specConstants = {{gpu::kSpecWorkgroupX, wg.x}, {gpu::kSpecWorkgroupY, wg.y}};
    d.localSizeX = wg.x;
    d.localSizeY = wg.y;
    visible.configure(d);
    return d;
}

std::array<vk::Buffer, kNumStats> makeStats(const vk::Context& ctx, std::uint64_t pixels) {
    auto make = [&](std::uint32_t i) { return vk::Buffer(ctx, pixels * sizeof(gpu::PixelStats), kStatNames[i]); };
    return {make(0), make(1), make(2), make(3), make(4), make(5), make(6), make(7), make(8), make(9)};
}
}  // namespace

bool splitBounceDefault(const vk::DeviceInfo& device) {
    return device.lavapipeBeforeMesa23;
}

GptPass::GptPass(const vk::Context& ctx, const SceneGpu& scene, WorkgroupSize wg, GptPassOptions options)
    : GptPass(ctx, scene.spec(), wg, options, vk::PipelineCreation::Now) {
    attach(scene);
}

GptPass::GptPass(const vk::Context& ctx, const SceneSpec& scene, WorkgroupSize wg, GptPassOptions options,
                 vk::PipelineCreation creation)
    : ctx_(ctx),
      width_(scene.width()),
      height_(scene.height()),
      options_(options),
      halfVector_(options.forceHalfVector || needsHalfVector(scene, options.shiftThreshold)),
      splitBounce_(splitBounceFor(ctx.info(), options.splitBounce)),
      counters_(ctx, sizeof(gpu::Counters), "gpt counters"),
      visible_(ctx, scene, wg, options.visibleSupersampling, counters_, creation),
      edges_(ctx, scene, wg, options.edgeSamples, creation),
      kernel_(ctx, gptDesc(scene, wg, halfVector_, splitBounce_, visible_), creation),
      resolveKernel_(ctx, resolveDesc(wg, visible_), creation),
      stats_(makeStats(ctx, std::uint64_t{width_} * height_)),
      resolved_(ctx, std::uint64_t{width_} * height_ * sizeof(gpu::GptResolved), "gpt resolved") {
    const std::string what = " of a " + std::to_string(width_) + "x" + std::to_string(height_) + " image";
    ctx.checkStorageBufferSize(stats_[0].size(), "each G-PT per-pixel statistics buffer" + what);
    ctx.checkStorageBufferSize(resolved_.size(), "the resolved G-PT images" + what);
    kernel_.bind(gpu::kBindCounters, counters_);
    for (std::uint32_t i = 0; i < kNumStats; ++i) {
        kernel_.bind(gpu::kBindGptCentral + i, stats_[i]);
        resolveKernel_.bind(gpu::kBindGptCentral + i, stats_[i]);
    }
    resolveKernel_.bind(gpu::kBindGptResolved, resolved_);
    visible_.bindTo(kernel_);
    visible_.bindTo(resolveKernel_);
    edges_.bindTo(kernel_);
    reset();
}

void GptPass::attach(const SceneGpu& scene) {
    scene.bindTo(kernel_);
    visible_.attach(scene);
    edges_.attach(scene);
}

double GptPass::waitForPipelines() const {
    return visible_.waitForPipeline() + edges_.waitForPipeline() + kernel_.wait() + resolveKernel_.wait();
}

void GptPass::findEdges(vk::CommandStream& stream) {
    edges_.find(stream);
    edges_.bindTo(kernel_);
}

void GptPass::reset() {
    for (auto& b : stats_) b.zero();
    counters_.zero();
    visible_.reset();
}

gpu::GptFrameParams GptPass::frameParams() const {
    gpu::GptFrameParams p{};
    p.shiftThreshold = options_.shiftThreshold;
    p.width = width_;
    p.height = height_;
    return p;
}

void GptPass::record(VkCommandBuffer cmd, std::uint32_t sampleBase, std::uint32_t spp, std::uint32_t seed,
                     vk::GpuTimer* timer, std::uint32_t rows) {
    visible_.record(cmd, sampleBase, spp, seed, timer);
    // gpt.comp over `tileRows` rows of `width_` items: image rows, or (listCount > 0) the
    // edge list's entries in rows of `width_` (its edge-list mode).
    const auto dispatchTiled = [&](std::uint32_t tileRows, std::uint32_t first, std::uint32_t n,
                                   std::uint32_t tileSeed, std::uint32_t listCount) {
        recordTiled(cmd, ctx_.info(), width_, tileRows, first, n, kMaxPixelSamplesPerDispatch,
                    [&](const DispatchTile& t) {
                        gpu::GptFrameParams p = frameParams();
                        setTileParams(p, t, tileSeed);
                        p.listCount = listCount;
                        kernel_.dispatchItems(cmd, width_, p.rowCount, &p, timer);
                    });
    };
    dispatchTiled(std::min(rows, height_), sampleBase, spp, seed, 0);
    // The edge pixels' extra samples, after the barrier that ends recordTiled, since both
    // merge into the same pixels' statistics.
    const std::uint32_t k = edges_.samplesPerSpp();
    if (edges_.count() == 0 || k == 0 || rows < height_) return;
    dispatchTiled((edges_.count() + width_ - 1) / width_, sampleBase * k, spp * k, edgeSampleSeed(seed),
                  edges_.count());
}

void GptPass::resolve(VkCommandBuffer cmd, vk::GpuTimer* timer) {
    gpu::GptFrameParams p = frameParams();
    p.rowOffset = 0;
    p.rowCount = height_;
    resolveKernel_.dispatchItems(cmd, width_, height_, &p, timer);
    vk::computeBarrier(cmd);
}

gpu::Counters GptPass::takeCounters() {
    gpu::Counters c{};
    counters_.download(&c, sizeof c);
    counters_.zero();
    return c;
}

std::vector<std::vector<gpu::PixelStats>> GptPass::downloadStats() const {
    std::vector<std::vector<gpu::PixelStats>> out;
    for (const auto& b : stats_)
        out.push_back(b.downloadVector<gpu::PixelStats>(std::size_t{width_} * height_));
    out.push_back(visible_.downloadStats());
    return out;
}

void GptPass::uploadStats(const std::vector<std::vector<gpu::PixelStats>>& stats) {
    const std::size_t pixels = std::size_t{width_} * height_;
    bool sizesMatch = stats.size() == stats_.size() + 1;
    for (std::size_t i = 0; sizesMatch && i < stats.size(); ++i) sizesMatch = stats[i].size() == pixels;
    if (!sizesMatch)
        throw Error("gpt pixel statistics: expected " + std::to_string(stats_.size() + 1) + " buffers of " +
                    std::to_string(pixels) + " entries");
    for (std::size_t i = 0; i < stats_.size(); ++i) stats_[i].uploadVector(stats[i]);
    visible_.uploadStats(stats.back());
}

GptImages GptPass::readback() const {
    const auto px = resolved_.downloadVector<gpu::GptResolved>(std::size_t{width_} * height_);
    const int w = static_cast<int>(width_), h = static_cast<int>(height_);
    GptImages out{Image(w, h), Image(w, h), Image(w, h), Image(w, h),
                  Image(w, h), Image(w, h), Image(w, h), Image(w, h)};
    for (std::size_t i = 0; i < px.size(); ++i) {
        const gpu::GptResolved& r = px[i];
        for (int c = 0; c < 3; ++c) {
            out.primal.plane(c)[i] = r.primal[c];
            out.dx.plane(c)[i] = r.dx[c];
            out.dy.plane(c)[i] = r.dy[c];
            out.direct.plane(c)[i] = r.direct[c];
            out.varPrimal.plane(c)[i] = r.varPrimal[c];
            out.varDx.plane(c)[i] = r.varDx[c];
            out.varDy.plane(c)[i] = r.varDy[c];
            out.varDirect.plane(c)[i] = r.varDirect[c];
        }
    }
    return out;
}

}  // namespace gdpt
