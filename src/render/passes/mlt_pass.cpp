#include "render/passes/mlt_pass.h"

#include <algorithm>
#include <string>

#include "mlt.spv.h"
#include "mlt_split.spv.h"
#include "mlt_split_units.spv.h"
#include "mlt_units.spv.h"
#include "util/error.h"
#include "vk/commands.h"
#include "vk/context.h"

namespace gdpt {
namespace {
// Chains (or samples) per row of a dispatch: mlt.comp numbers its items row by row.
constexpr std::uint32_t kItemsPerRow = 256;

vk::KernelDesc mltDesc(const SceneSpec& scene, const vk::DeviceInfo& device, WorkgroupSize wg, bool baseOnly,
                       bool splitBounce) {
    const std::vector<std::uint32_t> extra = {
        gpu::kBindCounters,     gpu::kBindMltChains, gpu::kBindMltPss,    gpu::kBindMltRecords,
        gpu::kBindMltBootstrap, gpu::kBindMltStarts, gpu::kBindMltDirect, gpu::kBindMltNormalise};
    vk::KernelDesc d = scene.kernelDesc(
        splitBounce ? GDPT_TRACING_KERNEL("mlt", mlt_split) : GDPT_TRACING_KERNEL("mlt", mlt), device, wg,
        extra, sizeof(gpu::MltParams));
    for (auto& [id, value] : d.specConstants)
        if (id == gpu::kSpecHasGlossy) value = gptNeedsHalfVector(scene) ? 1u : 0u;
    d.specConstants.push_back({gpu::kSpecMltBaseOnly, baseOnly ? 1u : 0u});
    return d;
}

std::uint64_t recordCapacity(const MltPassOptions& o) {
    return std::uint64_t{2} * o.chains * o.stepsPerBatch;
}
}  // namespace

MltPass::MltPass(const vk::Context& ctx, const SceneSpec& spec, WorkgroupSize wg, MltPassOptions options,
                 vk::PipelineCreation creation)
    : ctx_(ctx),
      width_(spec.width()),
      height_(spec.height()),
      shiftThreshold_(spec.shiftThreshold()),
      options_(options),
      counters_(ctx, sizeof(gpu::Counters), "mlt counters"),
      chains_(ctx, std::uint64_t{options.chains} * sizeof(gpu::MltChain), "mlt chains"),
      pss_(ctx, std::uint64_t{options.chains} * gpu::kMltPssDims * sizeof(float), "mlt chain states"),
      records_(ctx, recordCapacity(options) * sizeof(gpu::MltRecord), "mlt records"),
      starts_(ctx, std::uint64_t{options.chains} * sizeof(std::uint32_t), "mlt chain starts"),
      direct_(ctx, std::uint64_t{width_} * height_ * 4 * sizeof(float), "mlt direct"),
      bootstrap_(ctx, 0, "mlt bootstrap"),
      normaliser_(ctx, 0, "mlt normaliser"),
      splitBounce_(!options.baseOnly && splitBounceFor(ctx.info(), options.splitBounce)),
      kernel_(ctx, mltDesc(spec, ctx.info(), wg, options.baseOnly, splitBounce_), creation),
      visible_(ctx, spec, wg, options.emitterSupersampling, counters_, creation) {
    GDPT_CHECK(options.chains > 0 && options.stepsPerBatch > 0);
    kernel_.bind(gpu::kBindCounters, counters_);
    kernel_.bind(gpu::kBindMltChains, chains_);
    kernel_.bind(gpu::kBindMltPss, pss_);
    kernel_.bind(gpu::kBindMltRecords, records_);
    kernel_.bind(gpu::kBindMltStarts, starts_);
    kernel_.bind(gpu::kBindMltDirect, direct_);
    kernel_.bind(gpu::kBindMltBootstrap, bootstrap_);
    kernel_.bind(gpu::kBindMltNormalise, normaliser_);
    counters_.zero();
    chains_.zero();
}

void MltPass::attach(const SceneGpu& scene) {
    scene.bindTo(kernel_);
    visible_.attach(scene);
}

double MltPass::waitForPipelines() const {
    return kernel_.wait() + visible_.waitForPipeline();
}

void MltPass::recordWarmUp(VkCommandBuffer cmd) const {
    const gpu::MltParams p = params(gpu::kMltPhaseDirect, 0, 0);  // no rows: every invocation returns
    kernel_.dispatch(cmd, 1, 1, 1, &p, nullptr);
    vk::computeBarrier(cmd);
}

gpu::MltParams MltPass::params(std::uint32_t phase, std::uint32_t count, std::uint32_t seed) const {
    gpu::MltParams p{};
    p.phase = phase;
    p.count = count;
    p.seed = seed;
    p.width = width_;
    p.height = height_;
    p.shiftThreshold = shiftThreshold_;
    p.largeStep = options_.largeStep;
    p.targetAlpha = options_.targetAlpha;
    p.targetExponent = options_.targetExponent;
    p.misNormalisation = misNormalisation_;
    p.normaliseBlock = normaliseBlock_;
    p.normaliseColumns = normaliseColumns_;
    return p;
}

void MltPass::dispatchChains(VkCommandBuffer cmd, const gpu::MltParams& p, vk::GpuTimer* timer) const {
    const std::uint32_t rows = (p.count + kItemsPerRow - 1) / kItemsPerRow;
    kernel_.dispatchItems(cmd, std::min(p.count, kItemsPerRow), rows, &p, timer);
    vk::computeBarrier(cmd);
}

void MltPass::recordBootstrap(VkCommandBuffer cmd, std::uint32_t first, std::uint32_t count,
                              std::uint32_t seed, vk::GpuTimer* timer) {
    if (bootstrap_.size() < std::uint64_t{count} * sizeof(gpu::MltBootstrapSample)) {
        bootstrap_ =
            vk::Buffer(ctx_, std::uint64_t{count} * sizeof(gpu::MltBootstrapSample), "mlt bootstrap");
        kernel_.bind(gpu::kBindMltBootstrap, bootstrap_);
    }
    gpu::MltParams p = params(gpu::kMltPhaseBootstrap, count, seed);
    p.index = first;
    dispatchChains(cmd, p, timer);
}

std::vector<gpu::MltBootstrapSample> MltPass::bootstrapSamples(std::uint32_t count) const {
    return bootstrap_.downloadVector<gpu::MltBootstrapSample>(count);
}

void MltPass::setNormaliser(std::uint32_t block, const std::vector<float>& divisors) {
    normaliseBlock_ = block;
    normaliseColumns_ = block ? (width_ + block - 1) / block : 0;
    if (block == 0) return;
    const std::uint64_t rows = (height_ + block - 1) / block;
    GDPT_CHECK(divisors.size() == normaliseColumns_ * rows);
    normaliser_ = vk::Buffer(ctx_, divisors.size() * sizeof(float), "mlt normaliser");
    normaliser_.uploadVector(divisors);
    kernel_.bind(gpu::kBindMltNormalise, normaliser_);
}

void MltPass::recordStart(VkCommandBuffer cmd, const std::vector<std::uint32_t>& starts, std::uint32_t seed,
                          vk::GpuTimer* timer) {
    GDPT_CHECK(starts.size() == options_.chains);
    starts_.uploadVector(starts);
    dispatchChains(cmd, params(gpu::kMltPhaseStart, options_.chains, seed), timer);
}

void MltPass::recordMutations(VkCommandBuffer cmd, std::uint32_t first, std::uint32_t steps,
                              std::uint32_t seed, vk::GpuTimer* timer) {
    GDPT_CHECK(steps <= options_.stepsPerBatch);
    for (std::uint32_t s = 0; s < steps; ++s) {
        gpu::MltParams p = params(gpu::kMltPhaseMutate, options_.chains, seed);
        p.index = first + s;
        p.recordOffset = 2 * options_.chains * s;
        dispatchChains(cmd, p, timer);
    }
}

const gpu::MltRecord* MltPass::records(std::uint32_t steps) {
    const std::size_t n = std::size_t{2} * options_.chains * steps;
    host_.resize(n);
    if (n) records_.download(host_.data(), n * sizeof(gpu::MltRecord));
    return host_.data();
}

void MltPass::recordDirect(VkCommandBuffer cmd, std::uint32_t samples, std::uint32_t seed,
                           vk::GpuTimer* timer) {
    visible_.record(cmd, 0, samples, seed, timer);
    // Rows per dispatch: about 2^18 pixel-samples each (no dispatch long enough for a watchdog).
    const std::uint64_t perRow = std::uint64_t{width_} * std::max(samples, 1u);
    const auto rowsPer =
        static_cast<std::uint32_t>(std::clamp<std::uint64_t>((1u << 18) / perRow, 1, height_));
    for (std::uint32_t row = 0; row < height_; row += rowsPer) {
        gpu::MltParams p = params(gpu::kMltPhaseDirect, std::min(rowsPer, height_ - row), seed);
        p.directSamples = samples;
        p.rowOffset = row;
        kernel_.dispatchItems(cmd, width_, p.count, &p, timer);
    }
    vk::computeBarrier(cmd);
}

Image MltPass::directImage() const {
    const std::size_t n = std::size_t{width_} * height_;
    const std::vector<float> v = direct_.downloadVector<float>(4 * n);
    Image out(static_cast<int>(width_), static_cast<int>(height_));
    for (std::size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c) out.plane(c)[i] = v[4 * i + static_cast<std::size_t>(c)];
    // The rim pixels' estimate from their own, independent rays (chosen by the probe's rays only,
    // so unbiased; emitter_supersampling.comp) replaces the direct phase's there.
    visible_.replaceIn(out);
    return out;
}

MltAcceptance MltPass::acceptance() const {
    const auto chains = chains_.downloadVector<gpu::MltChain>(options_.chains);
    MltAcceptance a;
    for (const gpu::MltChain& c : chains) {
        a.proposedSmall += c.proposedSmall;
        a.acceptedSmall += c.acceptedSmall;
        a.proposedLarge += c.proposedLarge;
        a.acceptedLarge += c.acceptedLarge;
    }
    return a;
}

gpu::Counters MltPass::takeCounters() {
    gpu::Counters c{};
    counters_.download(&c, sizeof c);
    counters_.zero();
    return c;
}

}  // namespace gdpt
