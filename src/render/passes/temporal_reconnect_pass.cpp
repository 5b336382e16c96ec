#include "render/passes/temporal_reconnect_pass.h"

#include <algorithm>

#include "render/passes/pt_pass.h"
#include "tgpt_reconnect.spv.h"
#include "tgpt_reconnect_units.spv.h"
#include "util/error.h"
#include "vk/commands.h"
#include "vk/context.h"

namespace gdpt {
namespace {
// Pixel-samples per dispatch (each sample traces two paths: a quarter of pt_pass's bound).
constexpr std::uint64_t kMaxPixelSamplesPerDispatch = 1u << 18;
}  // namespace

TemporalReconnectPass::TemporalReconnectPass(const vk::Context& ctx, const SceneGpu& pair,
                                             const std::array<std::vector<gpu::TemporalPartner>, 2>& partners,
                                             WorkgroupSize wg)
    : ctx_(ctx),
      width_(pair.spec().width()),
      height_(pair.spec().height()),
      checked_(ctx, 2 * width_, height_,
               {{"the temporal partners", sizeof(gpu::TemporalPartner)},
                {"the temporal differences' statistics", sizeof(gpu::PixelStats)},
                {"the temporal base paths' statistics", sizeof(gpu::PixelStats)}}),
      counters_(ctx, sizeof(gpu::Counters), "temporal counters"),
      kernel_(ctx,
              pair.kernelDesc(GDPT_TRACING_KERNEL("tgpt_reconnect", tgpt_reconnect), ctx.info(), wg,
                              {gpu::kBindCounters, gpu::kBindTemporalPartner, gpu::kBindTemporalDifference,
                               gpu::kBindTemporalBase},
                              sizeof(gpu::TemporalParams)),
              vk::PipelineCreation::Now),
      partners_(ctx, 2ull * width_ * height_ * sizeof(gpu::TemporalPartner), "temporal partners"),
      differences_(ctx, 2ull * width_ * height_ * sizeof(gpu::PixelStats), "temporal differences"),
      bases_(ctx, 2ull * width_ * height_ * sizeof(gpu::PixelStats), "temporal base paths") {
    pair.bindTo(kernel_);
    kernel_.bind(gpu::kBindCounters, counters_);
    kernel_.bindAddress(gpu::kBindTemporalPartner, partners_);
    kernel_.bindAddress(gpu::kBindTemporalDifference, differences_);
    kernel_.bindAddress(gpu::kBindTemporalBase, bases_);
    const std::size_t pixels = std::size_t{width_} * height_;
    std::vector<gpu::TemporalPartner> both;
    both.reserve(2 * pixels);
    for (const auto& p : partners) {
        if (p.size() != pixels)
            throw Error("temporal partners: " + std::to_string(p.size()) + " entries for a " +
                        std::to_string(width_) + "x" + std::to_string(height_) + " image");
        for (const gpu::TemporalPartner& e : p)
            if (e.pixel != gpu::kInvalidIndex && e.pixel >= pixels)
                throw Error("temporal partners: pixel " + std::to_string(e.pixel) + " is outside the image");
        both.insert(both.end(), p.begin(), p.end());
    }
    partners_.uploadVector(both);
    reset();
}

void TemporalReconnectPass::reset() {
    differences_.zero();
    bases_.zero();
    counters_.zero();
}

void TemporalReconnectPass::record(VkCommandBuffer cmd, std::uint32_t sampleBase, std::uint32_t spp,
                                   std::array<std::uint32_t, 2> seeds, std::uint32_t flags,
                                   vk::GpuTimer* timer) {
    for (std::uint32_t direction = 0; direction < 2; ++direction)
        recordTiled(cmd, ctx_.info(), width_, height_, sampleBase, spp, kMaxPixelSamplesPerDispatch,
                    [&](const DispatchTile& t) {
                        gpu::TemporalParams p{};
                        setTileParams(p, t, seeds[direction]);
                        p.baseFrame = direction;
                        p.flags = flags;
                        kernel_.dispatchItems(cmd, width_, p.rowCount, &p, timer);
                    });
}

gpu::Counters TemporalReconnectPass::takeCounters() {
    gpu::Counters c{};
    counters_.download(&c, sizeof c);
    counters_.zero();
    return c;
}

std::array<TemporalDirectionImages, 2> TemporalReconnectPass::readback() const {
    const std::size_t pixels = std::size_t{width_} * height_;
    const auto differences = differences_.read<gpu::PixelStats>(2 * pixels);
    const auto bases = bases_.read<gpu::PixelStats>(2 * pixels);
    std::array<TemporalDirectionImages, 2> out;
    for (std::size_t d = 0; d < 2; ++d) {
        statsToImages(differences.data() + d * pixels, width_, height_, out[d].difference,
                      out[d].varDifference);
        statsToImages(bases.data() + d * pixels, width_, height_, out[d].base, out[d].varBase);
    }
    return out;
}

}  // namespace gdpt
