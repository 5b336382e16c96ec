#include "integrator/temporal_reconnect.h"

#include <array>

#include "poisson/poisson_spacetime.h"
#include "render/passes/temporal_reconnect_pass.h"
#include "util/error.h"
#include "util/interrupt.h"
#include "util/timer.h"
#include "vk/commands.h"
#include "vk/context.h"

namespace gdpt {
namespace {

// Camera samples per pixel (each direction) of one submission.
constexpr std::uint32_t kTemporalBatchSpp = 4;

}  // namespace

TemporalDifferences reconnectDifferences(const vk::Context& ctx, const Scene& a, const Scene& b,
                                         const MotionMap& map, const SceneGpuOptions& sceneOptions,
                                         const TemporalReconnectOptions& options) {
    Timer timer;
    enterPhase("temporal reconnection");
    const int width = sceneOptions.width, height = sceneOptions.height;
    const std::size_t pixels = std::size_t(width) * std::size_t(height);
    if (map.partner.size() != pixels)
        throw Error("temporal reconnection: a motion map of " + std::to_string(map.partner.size()) +
                    " pixels for a " + std::to_string(width) + "x" + std::to_string(height) + " image");
    SceneGpuOptions quiet = sceneOptions;
    quiet.quiet = true;
    const SceneGpu pair(ctx, a, b, quiet);

    // Partners both ways: p of a goes to q of b with the motion's sub-pixel part δ, q back to p
    // with −δ (the inverse toroidal shift).
    std::array<std::vector<gpu::TemporalPartner>, 2> partners;
    for (auto& p : partners) p.assign(pixels, gpu::TemporalPartner{gpu::kInvalidIndex, 0.0f, 0.0f, 0});
    for (std::size_t p = 0; p < pixels; ++p) {
        const std::uint32_t q = map.partner[p];
        if (q == kNoTemporalPartner) continue;
        const glm::vec2 d = map.subpixel.empty() ? glm::vec2(0.0f) : map.subpixel[p];
        partners[0][p] = {q, d.x, d.y, 0};
        partners[1][q] = {static_cast<std::uint32_t>(p), -d.x, -d.y, 0};
    }
    TemporalReconnectPass pass(ctx, pair, partners);

    // Batches of a few samples per pixel: an interrupt stops the pass between them, and the
    // 32-bit counters are summed per batch.
    TemporalDifferences out;
    vk::CommandStream stream(ctx, "temporal reconnection");
    for (std::uint32_t first = 0; first < options.spp; first += kTemporalBatchSpp) {
        if (interruptRequested()) {
            out.cancelled = true;
            return out;
        }
        const std::uint32_t spp = std::min(kTemporalBatchSpp, options.spp - first);
        stream.setWhat("temporal reconnection (samples " + std::to_string(first) + ".." +
                       std::to_string(first + spp - 1) + ")");
        pass.record(stream.begin(), first, spp, {options.seed, options.seed + 0x9E3779B9u}, options.flags);
        stream.submit();
        stream.waitAll([] {});
        const gpu::Counters c = pass.takeCounters();
        out.rays += c.raysTraced;
        out.pairs += c.shiftPairs;
        out.failures += c.shiftFailures;
        out.nanSamples += c.nanSamples;
    }

    std::array<TemporalDirectionImages, 2> images = pass.readback();
    const TemporalDirectionImages& forward = images[0];
    const TemporalDirectionImages& reverse = images[1];
    out.baseA = std::move(images[0].base);
    out.varBaseA = std::move(images[0].varBase);
    out.baseB = std::move(images[1].base);
    out.varBaseB = std::move(images[1].varBase);
    out.dt = Image(width, height);
    out.varDt = Image(width, height);
    for (std::size_t p = 0; p < pixels; ++p) {
        const std::uint32_t q = map.partner[p];
        if (q == kNoTemporalPartner) continue;
        for (int c = 0; c < 3; ++c) {
            out.dt.plane(c)[p] = forward.difference.plane(c)[p] - reverse.difference.plane(c)[q];
            out.varDt.plane(c)[p] = forward.varDifference.plane(c)[p] + reverse.varDifference.plane(c)[q];
        }
    }
    out.seconds = timer.seconds();
    return out;
}

}  // namespace gdpt
