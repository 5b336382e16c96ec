// pt_integrator.h — path tracing as an integrator: one stage, sampling (pt_sampler.h).
// Layers: the mean image (default channels) and `variance`, the per-pixel variance of the
// mean. The unbiased baseline every other method is measured against.
#pragma once

#include "integrator/integrator.h"

namespace gdpt {

class PtIntegrator final : public Integrator {
public:
    [[nodiscard]] std::string name() const override { return "pt"; }
    [[nodiscard]] std::uint32_t maxBatchSpp(int width, int height) const override;
    [[nodiscard]] ExrAttributes identity(const Scene& scene, const RenderOptions& options) const override;
    RenderOutput render(const vk::Context& ctx, const Scene& scene, const RenderOptions& options) override;
};

}  // namespace gdpt
