#include "integrator/pt_integrator.h"

#include <utility>

#include "integrator/pt_sampler.h"

namespace gdpt {

std::uint32_t PtIntegrator::maxBatchSpp(int width, int height) const {
    return maxBatchSppFor(width, height, kPtBatchPixelSamples);
}

ExrAttributes PtIntegrator::identity(const Scene&, const RenderOptions&) const {
    return {};
}

RenderOutput PtIntegrator::render(const vk::Context& ctx, const Scene& scene, const RenderOptions& options) {
    RenderResult r = renderPt(ctx, scene, options);
    RenderOutput out;
    out.stats = r.stats;
    if (r.stats.cancelled || r.stats.handedOff) return out;
    out.layers = {{"", std::move(r.image)}, {"variance", std::move(r.varianceOfMean)}};
    return out;
}

}  // namespace gdpt
