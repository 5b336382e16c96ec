#include "render/passes/gpt_pass.h"

#include <algorithm>
#include <string>

#include "gpt.spv.h"
#include "gpt_resolve.spv.h"
#include "gpt_split.spv.h"
#include "gpt_split_units.spv.h"
#include "gpt_units.spv.h"
#include "lib/surface_rules.glsl"
#include "render/device_scene/scene_gpu.h"
#include "util/error.h"
#include "util/parallel.h"
#include "vk/commands.h"
#include "vk/context.h"

namespace gdpt {
namespace {
// Pixel-samples per dispatch: a G-PT sample costs about three PT samples on lavapipe (2.5x
// the rays), so this bound keeps each dispatch within ~1.5x of PtPass's (well below any
// watchdog) while keeping dispatches few.
constexpr std::uint64_t kMaxPixelSamplesPerDispatch = 1u << 19;
constexpr std::uint32_t kNumStats = 10;  // bindings kBindGptCentral .. kBindGptDirect

const char* const kStatNames[kNumStats] = {
    "gpt central",        "gpt neighbor right", "gpt neighbor down", "gpt neighbor left", "gpt neighbor up",
    "gpt gradient right", "gpt gradient down",  "gpt gradient left", "gpt gradient up",   "gpt direct"};

vk::KernelDesc gptDesc(const SceneSpec& scene, const vk::DeviceInfo& device, WorkgroupSize wg,
                       bool halfVector, bool splitBounce, bool demodulate,
                       const EmitterSupersamplingPass& visible) {
    std::vector<std::uint32_t> extra = {gpu::kBindCounters, gpu::kBindGptDemodMask, gpu::kBindGptModulation,
                                        gpu::kBindGptStreamKey};
    for (std::uint32_t i = 0; i < kNumStats; ++i) extra.push_back(gpu::kBindGptCentral + i);
    vk::KernelDesc d = scene.kernelDesc(
        splitBounce ? GDPT_TRACING_KERNEL("gpt", gpt_split) : GDPT_TRACING_KERNEL("gpt", gpt), device, wg,
        extra, sizeof(gpu::GptFrameParams), /*bundles=*/splitBounce);
    for (auto& [id, value] : d.specConstants)
        if (id == gpu::kSpecHasGlossy) value = halfVector ? 1u : 0u;
    d.specConstants.push_back({gpu::kSpecGptDemodulate, demodulate ? 1u : 0u});
    visible.configure(d);
    EdgePass::configure(d);
    return d;
}

vk::KernelDesc resolveDesc(WorkgroupSize wg, const EmitterSupersamplingPass& visible) {
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

// The per-pixel buffers of the pass and the passes it owns (checkPixelBuffers).
std::vector<PixelBuffer> pixelBuffers(const GptPassOptions& options) {
    std::vector<PixelBuffer> b = {{"each G-PT per-pixel statistics buffer", sizeof(gpu::PixelStats)},
                                  {"the resolved G-PT images", sizeof(gpu::GptResolved)},
                                  {"the emitter-supersampling statistics", sizeof(gpu::PixelStats)},
                                  {"the emitter-supersampling probe and list", kEmitterProbeBytesPerPixel},
                                  {"the edge mask", sizeof(std::uint32_t)},
                                  {"the edge sample rates", sizeof(std::uint32_t)},
                                  {"the edge probe", sizeof(gpu::EdgeProbe)}};
    if (options.demodulate) {
        b.push_back({"the demodulation mask", sizeof(std::uint32_t)});
        b.push_back({"the modulation statistics", sizeof(gpu::PixelStats)});
    }
    if (options.streams) b.push_back({"the pixel streams", sizeof(gpu::PixelStream)});
    return b;
}

std::array<vk::Buffer, kNumStats> makeStats(const vk::Context& ctx, std::uint64_t pixels) {
    auto make = [&](std::uint32_t i) {
        return vk::Buffer(ctx, pixels * sizeof(gpu::PixelStats), kStatNames[i]);
    };
    return {make(0), make(1), make(2), make(3), make(4), make(5), make(6), make(7), make(8), make(9)};
}
}  // namespace

// Whether some vertex can be classified glossy: a specular layer at or below the threshold,
// or one below bsdf.glsl's Dirac cutoff (perceptual roughness 0.01), which
// bsdfRoughnessForShift reports as 0 whatever the threshold. Same rule as features.cpp's
// hasGlossy, evaluated for the spec's threshold (SceneGpuOptions::shiftThreshold).
bool gptNeedsHalfVector(const SceneSpec& scene) {
    const float threshold = scene.shiftThreshold();
    const SceneFeatures& f = scene.features();
    constexpr float kDiracRoughness = 0.01f;  // sqrt(kDeltaAlpha)
    return f.hasSpecularLayer && (f.minRoughness <= threshold || f.minRoughness < kDiracRoughness);
}

bool splitBounceDefault(const vk::DeviceInfo& device) {
    return device.lavapipeBeforeMesa23;
}

bool splitBounceFor(const vk::DeviceInfo& device, GptPassOptions::SplitBounce s) {
    if (s == GptPassOptions::SplitBounce::Auto) return splitBounceDefault(device);
    return s == GptPassOptions::SplitBounce::On;
}

bool demodulationApplies(const Scene& scene) {
    return std::any_of(scene.materials.begin(), scene.materials.end(), gpu::modulatesLambertian);
}

namespace {
// edge.comp's test between two probe points, applied to two pixels' first probes.
bool sameSurface(const gpu::EdgeProbe& a, const gpu::EdgeProbe& b) {
    if (a.hit != b.hit) return false;
    return a.hit == 0 ||
           gpu::probeHitsAgree(a.material, a.position, a.normal, b.material, b.position, b.normal);
}
}  // namespace

std::vector<std::uint32_t> demodulationMask(const std::vector<std::uint32_t>& edgeMask,
                                            const std::vector<gpu::EdgeProbe>& probes, std::uint32_t width,
                                            std::uint32_t height) {
    const std::size_t n = std::size_t{width} * height;
    GDPT_CHECK(edgeMask.size() == n && probes.size() == n);
    std::vector<std::uint32_t> out(n, 0u);
    for (std::uint32_t y = 0; y < height; ++y)
        for (std::uint32_t x = 0; x < width; ++x) {
            const std::size_t p = std::size_t{y} * width + x;
            bool safe = true;
            for (std::uint32_t v = y > 0 ? y - 1 : 0; safe && v <= std::min(y + 1, height - 1); ++v)
                for (std::uint32_t u = x > 0 ? x - 1 : 0; safe && u <= std::min(x + 1, width - 1); ++u) {
                    const std::size_t q = std::size_t{v} * width + u;
                    safe = edgeMask[q] == 0 && sameSurface(probes[p], probes[q]);
                }
            out[p] = safe ? 1u : 0u;
        }
    return out;
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
      shiftThreshold_(scene.shiftThreshold()),
      options_(options),
      halfVector_(options.forceHalfVector || gptNeedsHalfVector(scene)),
      splitBounce_(splitBounceFor(ctx.info(), options.splitBounce)),
      occlusionBeams_(splitBounce_ && !scene.bvhUnitSteps(ctx.info(), /*bundles=*/true)),
      checked_(ctx, width_, height_, pixelBuffers(options)),
      counters_(ctx, sizeof(gpu::Counters), "gpt counters"),
      emitterSupersampling_(ctx, scene, wg, options.emitterSupersampling, counters_, creation),
      edges_(ctx, scene, wg, options.edgeSamples, creation, options.demodulate),
      kernel_(ctx,
              gptDesc(scene, ctx.info(), wg, halfVector_, splitBounce_, options.demodulate,
                      emitterSupersampling_),
              creation),
      resolveKernel_(ctx, resolveDesc(wg, emitterSupersampling_), creation),
      stats_(makeStats(ctx, std::uint64_t{width_} * height_)),
      resolved_(ctx, std::uint64_t{width_} * height_ * sizeof(gpu::GptResolved), "gpt resolved"),
      // Without demodulation: 16-byte placeholders.
      demodMask_(ctx, options.demodulate ? std::uint64_t{width_} * height_ * sizeof(std::uint32_t) : 0,
                 "gpt demodulation mask"),
      modulation_(ctx, options.demodulate ? std::uint64_t{width_} * height_ * sizeof(gpu::PixelStats) : 0,
                  "gpt modulation"),
      streams_(ctx, options.streams ? std::uint64_t{width_} * height_ * sizeof(gpu::PixelStream) : 0,
               "gpt pixel streams") {
    if (options_.streams) {
        if (options_.streams->size() != std::size_t{width_} * height_)
            throw Error("gpt pixel streams: " + std::to_string(options_.streams->size()) + " entries for " +
                        std::to_string(width_) + "x" + std::to_string(height_) + " pixels");
        streams_.uploadVector(*options_.streams);
    }
    kernel_.bind(gpu::kBindCounters, counters_);
    for (std::uint32_t i = 0; i < kNumStats; ++i) {
        kernel_.bindAddress(gpu::kBindGptCentral + i, stats_[i]);
        resolveKernel_.bindAddress(gpu::kBindGptCentral + i, stats_[i]);
    }
    resolveKernel_.bindAddress(gpu::kBindGptResolved, resolved_);
    kernel_.bindAddress(gpu::kBindGptDemodMask, demodMask_);  // all 0 (no pixel) until findEdges()
    kernel_.bindAddress(gpu::kBindGptModulation, modulation_);
    kernel_.bindAddress(gpu::kBindGptStreamKey, streams_);
    demodMask_.zero();
    emitterSupersampling_.bindTo(kernel_);
    emitterSupersampling_.bindTo(resolveKernel_);
    edges_.bindTo(kernel_);
    reset();
}

void GptPass::attach(const SceneGpu& scene) {
    scene.bindTo(kernel_);
    emitterSupersampling_.attach(scene);
    edges_.attach(scene);
}

double GptPass::waitForPipelines() const {
    return emitterSupersampling_.waitForPipeline() + edges_.waitForPipeline() + kernel_.wait() +
           resolveKernel_.wait();
}

void GptPass::findEdges(vk::CommandStream& stream) {
    edges_.find(stream);
    edges_.bindTo(kernel_);
    if (options_.demodulate && !edges_.mask().empty()) {
        const std::vector<std::uint32_t> mask =
            demodulationMask(edges_.mask(), edges_.probes(), width_, height_);
        demodMask_.uploadVector(mask);
        demodulatedPixels_ = 0;
        for (std::uint32_t v : mask) demodulatedPixels_ += v;
    }
}

void GptPass::reset() {
    for (auto& b : stats_) b.zero();
    modulation_.zero();
    counters_.zero();
    emitterSupersampling_.reset();
}

gpu::GptFrameParams GptPass::frameParams() const {
    gpu::GptFrameParams p{};
    p.shiftThreshold = shiftThreshold_;
    p.width = width_;
    p.height = height_;
    p.streamKeys = options_.streams ? 1u : 0u;
    p.sampleRates = options_.countWeights && edges_.ratesDiffer() ? 1u : 0u;
    return p;
}

void GptPass::record(VkCommandBuffer cmd, std::uint32_t sampleBase, std::uint32_t spp, std::uint32_t seed,
                     vk::GpuTimer* timer, std::uint32_t rows) {
    emitterSupersampling_.record(cmd, sampleBase, spp, seed, timer);
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

void GptPass::recordWarmUp(VkCommandBuffer cmd) const {
    gpu::GptFrameParams p = frameParams();
    p.rowCount = 0;  // every invocation returns at once
    kernel_.dispatch(cmd, 1, 1, 1, &p, nullptr);
    resolveKernel_.dispatch(cmd, 1, 1, 1, &p, nullptr);
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
    out.push_back(emitterSupersampling_.downloadStats());
    if (options_.demodulate)
        out.push_back(modulation_.downloadVector<gpu::PixelStats>(std::size_t{width_} * height_));
    return out;
}

void GptPass::uploadStats(const std::vector<std::vector<gpu::PixelStats>>& stats) {
    const std::size_t pixels = std::size_t{width_} * height_;
    const std::size_t expected = stats_.size() + 1 + (options_.demodulate ? 1 : 0);
    bool sizesMatch = stats.size() == expected;
    for (std::size_t i = 0; sizesMatch && i < stats.size(); ++i) sizesMatch = stats[i].size() == pixels;
    if (!sizesMatch)
        throw Error("gpt pixel statistics: expected " + std::to_string(expected) + " buffers of " +
                    std::to_string(pixels) + " entries");
    for (std::size_t i = 0; i < stats_.size(); ++i) stats_[i].uploadVector(stats[i]);
    emitterSupersampling_.uploadStats(stats[stats_.size()]);
    if (options_.demodulate) modulation_.uploadVector(stats.back());
}

GptImages GptPass::readback() const {
    const std::size_t pixels = std::size_t{width_} * height_;
    const auto px = resolved_.read<gpu::GptResolved>(pixels);
    const int w = static_cast<int>(width_), h = static_cast<int>(height_);
    GptImages out{Image(w, h), Image(w, h), Image(w, h), Image(w, h),
                  Image(w, h), Image(w, h), Image(w, h), Image(w, h)};
    // Interleaved records to planes, in ranges over the cores (a 4K image: 800 MB each way).
    parallelRanges(0, pixels, std::size_t{1} << 14, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) {
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
    });
    if (options_.demodulate) {
        // m̄ per pixel; 1 where no sample has arrived (nothing to modulate there).
        const auto m = modulation_.downloadVector<gpu::PixelStats>(px.size());
        out.modulation = Image(w, h, 1.0f);
        out.varModulation = Image(w, h, 0.0f);
        for (std::size_t i = 0; i < m.size(); ++i) {
            const double n = m[i].count;
            for (int c = 0; c < 3 && n > 0; ++c) {
                out.modulation.plane(c)[i] = m[i].mean[c];
                if (n > 1) out.varModulation.plane(c)[i] = static_cast<float>(m[i].m2[c] / (n - 1.0) / n);
            }
        }
    }
    return out;
}

std::vector<Image> GptPass::readbackMeans(bool withGradients) const {
    const std::size_t pixels = std::size_t{width_} * height_;
    const auto px = resolved_.read<gpu::GptResolved>(pixels);
    const int w = static_cast<int>(width_), h = static_cast<int>(height_);
    std::vector<Image> out(withGradients ? 3 : 1, Image(w, h));
    parallelRanges(0, pixels, std::size_t{1} << 14, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
            for (int c = 0; c < 3; ++c) {
                out[0].plane(c)[i] = px[i].primal[c];
                if (!withGradients) continue;
                out[1].plane(c)[i] = px[i].dx[c];
                out[2].plane(c)[i] = px[i].dy[c];
            }
    });
    return out;
}

}  // namespace gdpt
