// pt_sampler.h — the sampling stage of path tracing: per-pixel running statistics of the
// path samples (PtPass, pt.comp) and of emitter supersampling, read back as the mean image
// and the variance of that mean. The PT integrator (pt_integrator.h) writes them as layers.
#pragma once

#include <cstdint>

#include "integrator/render_options.h"
#include "scene/scene.h"

namespace gdpt {

namespace vk {
class Context;
}

// Pixel-samples per batch of path tracing (maxBatchSppFor).
inline constexpr std::uint64_t kPtBatchPixelSamples = std::uint64_t{1} << 18;

struct RenderResult {
    Image image;           // mean radiance
    Image varianceOfMean;  // per-pixel variance of the mean (sample variance / n)
    RenderStats stats;
};

// Renders with options (maxBatchSpp 0: the default for the size, kPtBatchPixelSamples).
RenderResult renderPt(const vk::Context& ctx, const Scene& scene, const RenderOptions& options);

}  // namespace gdpt
