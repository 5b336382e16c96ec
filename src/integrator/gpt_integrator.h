// gpt_integrator.h — gradient-domain path tracing (Kettunen, Manzi, Aittala, Lehtinen,
// Durand, Zwicker, "Gradient-Domain Path Tracing", ACM TOG 34(4), 2015) as an integrator:
//   1. sample: a base path and four offset paths (shifted into the neighbouring pixels) per
//      camera sample, accumulating the primal, the gradients dx and dy, the very-direct
//      light and their variances (gpt_sampler.h);
//   2. reconstruct: screened Poisson solves of the primal and gradients (§4; L1 by IRLS by
//      default), on the device;
//   3. compose: final = reconstruction (× modulation with demodulation) + direct (§5).
// Layers: final (default channels), recon_<name> per reconstruction, primal, dx, dy, direct,
// var_primal, var_dx, var_dy, var_direct, primal_plus_direct, and modulation when
// demodulated.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "integrator/integrator.h"
#include "integrator/reconstruction_stage.h"

namespace gdpt {

class GptIntegrator final : public Integrator {
public:
    // `name`: "gpt", or the gpt-<reconstruction> form it was made from.
    GptIntegrator(std::string name, GptOptions options);
    ~GptIntegrator() override;

    [[nodiscard]] std::string name() const override { return name_; }
    [[nodiscard]] std::uint32_t maxBatchSpp(int width, int height) const override;
    [[nodiscard]] ExrAttributes identity(const Scene& scene, const RenderOptions& options) const override;
    // The reconstructions' time (ReconstructionStage::reserve): with options.reconCache the
    // remembered time of this device, size and solves, else a calibration solve per
    // reconstruction; without, one calibration per integrator raised to the longest
    // reconstruction it has run (the steady state of a benchmark that renders many times).
    ReservedTime reserveAfterSampling(const vk::Context& ctx, int width, int height) override;
    RenderOutput render(const vk::Context& ctx, const Scene& scene, const RenderOptions& options) override;
    void describe(nlohmann::json& summary, const RenderStats& stats) const override;
    [[nodiscard]] std::string summary(const RenderStats& stats) const override;

private:
    std::string name_;
    GptOptions options_;
    ReconstructionStage stage_;
};

}  // namespace gdpt
