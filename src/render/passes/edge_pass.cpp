#include "render/passes/edge_pass.h"

#include <algorithm>
#include <string>

#include "edge.spv.h"
#include "edge_units.spv.h"
#include "gpt_shared.h"
#include "util/error.h"
#include "vk/commands.h"
#include "vk/context.h"

namespace gdpt {
namespace {
std::uint32_t checkedFactor(std::uint32_t samplesPerSpp) {
    if (samplesPerSpp > kMaxEdgeSamples && samplesPerSpp != kEdgeSamplesAuto)
        throw Error("edge samples " + std::to_string(samplesPerSpp) + " is above the maximum " +
                    std::to_string(kMaxEdgeSamples));
    return samplesPerSpp;
}
}  // namespace

std::uint32_t edgeSampleSeed(std::uint32_t seed) {
    // A bijective integer mix (the finaliser of MurmurHash3) of the seed with a constant, so
    // distinct seeds keep distinct edge streams.
    std::uint32_t h = seed ^ 0x65646765u;  // "edge"
    h ^= h >> 16;
    h *= 0x85ebca6bu;
    h ^= h >> 13;
    h *= 0xc2b2ae35u;
    h ^= h >> 16;
    return h;
}

EdgePass::EdgePass(const vk::Context& ctx, const SceneSpec& scene, WorkgroupSize wg,
                   std::uint32_t samplesPerSpp, vk::PipelineCreation creation, bool maskNeeded)
    : ctx_(ctx),
      width_(scene.width()),
      height_(scene.height()),
      samplesPerSpp_(checkedFactor(samplesPerSpp)),
      maskNeeded_(maskNeeded),
      // Disabled: 16-byte placeholders.
      maskBuffer_(ctx, enabled() ? std::uint64_t{width_} * height_ * sizeof(std::uint32_t) : 0, "edge mask"),
      probeBuffer_(ctx, enabled() ? std::uint64_t{width_} * height_ * sizeof(gpu::EdgeProbe) : 0,
                   "edge probe"),
      list_(ctx, 0, "edge list"),
      rates_(ctx, 0, "edge sample rates") {
    if (!enabled()) return;
    vk::KernelDesc d = scene.kernelDesc(GDPT_TRACING_KERNEL("edge", edge), ctx.info(), wg,
                                        {gpu::kBindGptEdgeMask, gpu::kBindGptEdgeProbe}, 0);
    kernel_.emplace(ctx, d, creation);
    kernel_->bindAddress(gpu::kBindGptEdgeMask, maskBuffer_);
    kernel_->bindAddress(gpu::kBindGptEdgeProbe, probeBuffer_);
}

void EdgePass::attach(const SceneGpu& scene) {
    if (kernel_) scene.bindTo(*kernel_);
}

void EdgePass::configure(vk::KernelDesc& desc) {
    desc.bindings.push_back(gpu::kBindGptEdgeList);
    desc.bindings.push_back(gpu::kBindGptSampleRate);
}

void EdgePass::bindTo(vk::Kernel& kernel) const {
    kernel.bindAddress(gpu::kBindGptEdgeList, list_);
    kernel.bindAddress(gpu::kBindGptSampleRate, rates_);
}

void EdgePass::find(vk::CommandStream& stream) {
    if (!enabled() || found_) return;
    VkCommandBuffer cmd = stream.begin();
    kernel_->dispatchItems(cmd, width_, height_, nullptr, nullptr);
    vk::computeBarrier(cmd);
    stream.setWhat("edge probe (" + std::to_string(width_) + "x" + std::to_string(height_) + ")");
    stream.submitAndWait();
    mask_ = maskBuffer_.downloadVector<std::uint32_t>(std::size_t{width_} * height_);
    if (maskNeeded_) probes_ = probeBuffer_.downloadVector<gpu::EdgeProbe>(std::size_t{width_} * height_);
    edgeCount_ = static_cast<std::uint32_t>(
        std::count_if(mask_.begin(), mask_.end(), [](std::uint32_t m) { return m != 0; }));
    const std::vector<std::uint32_t> list = edgeSampleList(mask_, width_, height_);
    count_ = static_cast<std::uint32_t>(list.size());
    if (samplesPerSpp_ == kEdgeSamplesAuto) samplesPerSpp_ = autoEdgeSamples(count_, mask_.size());
    if (count_ > 0) {
        list_ = vk::Buffer(ctx_, list.size() * sizeof(std::uint32_t), "edge list");
        list_.uploadVector(list);
    }
    if (ratesDiffer()) {  // else gpt.comp reads no rate (a probe for demodulation alone: factor 0)
        rates_ = vk::Buffer(ctx_, mask_.size() * sizeof(std::uint32_t), "edge sample rates");
        rates_.uploadVector(edgeSampleRates(list, samplesPerSpp_, width_, height_));
    }
    found_ = true;
}

}  // namespace gdpt
