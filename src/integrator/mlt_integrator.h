// mlt_integrator.h — Metropolis light transport in primary sample space (Kelemen,
// Szirmay-Kalos, Antal, Csonka 2002) with thousands of chains on the device, as two methods:
//   pssmlt  the target is the luminance of the path's contribution; the image is the splatted
//           primal (+ the very-direct light);
//   gmlt    gradient-domain MLT (Lehtinen, Karras, Laine, Aittala, Durand, Aila 2013): each
//           state is a G-PT camera sample (a base path and its four offsets through the shift
//           mapping), the target is the sum of its absolute gradients plus α times its
//           radiance, and the splatted primal and gradients are reconstructed by the screened
//           Poisson solve (L1 by default), to which the very-direct light is added.
// Stages: the very-direct image; the bootstrap (fresh states: the normalisation b and the
// chains' starting states); the chains' mutation steps, whose records the host splats in a
// fixed order (no float atomics: bit-reproducible per seed and device); the estimate
// (mlt_estimate.h); for gmlt the reconstruction. --spp N asks for N mutations per pixel on
// average. docs/mlt.md has the estimator and the measurements.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "integrator/integrator.h"
#include "integrator/reconstruction_stage.h"
#include "render/passes/mlt_pass.h"

namespace gdpt {

class MltIntegrator final : public Integrator {
public:
    // `name`: "pssmlt" or "gmlt".
    MltIntegrator(std::string name, MltOptions options);
    ~MltIntegrator() override;

    [[nodiscard]] std::string name() const override { return name_; }
    [[nodiscard]] std::uint32_t maxBatchSpp(int width, int height) const override;
    [[nodiscard]] ExrAttributes identity(const Scene& scene, const RenderOptions& options) const override;
    ReservedTime reserveAfterSampling(const vk::Context& ctx, int width, int height) override;
    RenderOutput render(const vk::Context& ctx, const Scene& scene, const RenderOptions& options) override;
    void describe(nlohmann::json& summary, const RenderStats& stats) const override;
    [[nodiscard]] std::string summary(const RenderStats& stats) const override;

private:
    [[nodiscard]] bool gradients() const { return name_ == "gmlt"; }

    std::string name_;
    MltOptions options_;
    ReconstructionStage stage_;
};

// Chains of a width x height render when MltOptions::chains is 0: one per 16 pixels, at least
// 1024 and at most 65536 (enough invocations for a CPU device's threads and a GPU's lanes;
// fewer chains mutate longer).
std::uint32_t defaultMltChains(int width, int height);

}  // namespace gdpt
