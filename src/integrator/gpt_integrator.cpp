#include "integrator/gpt_integrator.h"

#include <algorithm>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>

#include "integrator/gpt_alpha.h"
#include "integrator/gpt_reconstruction.h"
#include "integrator/render_identity.h"
#include "util/interrupt.h"
#include "util/timer.h"
#include "vk/context.h"

namespace gdpt {

GptIntegrator::GptIntegrator(std::string name, GptOptions options)
    : name_(std::move(name)),
      options_(std::move(options)),
      stage_(options_.reconstructions, options_.alpha.value_or(kGptAlphaEmitters), options_.tolerance,
             options_.debiasCells, options_.solver) {}

GptIntegrator::~GptIntegrator() = default;

std::uint32_t GptIntegrator::maxBatchSpp(int width, int height) const {
    return maxBatchSppFor(width, height, kGptBatchPixelSamples);
}

ExrAttributes GptIntegrator::identity(const Scene& scene, const RenderOptions& options) const {
    return {{"shift_threshold", exactFloat(options.scene.shiftThreshold)},
            {"edge_samples", edgeSamplesText(options_.sampling.edgeSamples)},
            {"edge_sample_pixels", kEdgeSamplePixels},
            {"pair_weights", kPairWeights},
            {"demodulate", demodulates(scene, options_.sampling.demodulate) ? "on" : "off"}};
}

ReservedTime GptIntegrator::reserveAfterSampling(const vk::Context& ctx, int width, int height) {
    return stage_.reserve(ctx, width, height, options_.reconCache);
}

RenderOutput GptIntegrator::render(const vk::Context& ctx, const Scene& scene, const RenderOptions& options) {
    const int width = options.scene.width, height = options.scene.height;
    // Stage 1, sampling. The reconstruction's pipelines are created while the path kernels
    // compile.
    RenderOptions sampling = options;
    if (!stage_.empty()) {
        // The solver's fields are allocated here, after the sampling pass has checked that the
        // image's per-pixel buffers fit the device (an image too large is refused at once).
        sampling.whileCompiling = [&] {
            if (options.whileCompiling) options.whileCompiling();
            stage_.solver(ctx, width, height).preparePipelines(stage_.solves());
        };
    }
    RenderResultGpt g = renderGpt(ctx, scene, sampling, options_.sampling);
    RenderOutput out;
    out.stats = g.stats;
    if (g.stats.cancelled || g.stats.handedOff) return out;

    // Stage 2, the screened Poisson reconstructions of the primal and gradients, the final one
    // given or chosen by the scene's surfaces (gpt_reconstruction.h), with the primal weight
    // given or chosen by the scene's light (gpt_alpha.h).
    if (options_.reconstructionByScene)
        stage_.setFinal(gptDefaultReconstruction(gptSurfaces(g.stats.features)));
    stage_.setAlpha(options_.alpha.value_or(gptDefaultAlpha(gptLighting(g.stats.features))));
    PoissonInput input;
    input.primal = &g.primal;
    input.dx = &g.dx;
    input.dy = &g.dy;
    input.varPrimal = &g.varPrimal;
    input.varDx = &g.varDx;
    input.varDy = &g.varDy;
    std::vector<NamedLayer> recons = stage_.run(input, options, out.stats, options_.reconCache);

    // Stage 3, compose: final = reconstruction (x modulation) + direct (Kettunen et al. 2015,
    // §5: the very-direct light is not reconstructed). Without a reconstruction, the primal.
    out.layers.push_back({"", gptFinal(g, recons.empty() ? g.primal : recons.front().image)});
    for (NamedLayer& r : recons) out.layers.push_back(std::move(r));
    Image primalPlusDirect = gptFinal(g, g.primal);
    const std::vector<NamedLayer> buffers = {{"primal", std::move(g.primal)},
                                             {"dx", std::move(g.dx)},
                                             {"dy", std::move(g.dy)},
                                             {"direct", std::move(g.direct)},
                                             {"var_primal", std::move(g.varPrimal)},
                                             {"var_dx", std::move(g.varDx)},
                                             {"var_dy", std::move(g.varDy)},
                                             {"var_direct", std::move(g.varDirect)},
                                             {"primal_plus_direct", std::move(primalPlusDirect)}};
    out.layers.insert(out.layers.end(), buffers.begin(), buffers.end());
    if (g.stats.demodulated) out.layers.push_back({"modulation", std::move(g.modulation)});
    return out;
}

void GptIntegrator::describe(nlohmann::json& j, const RenderStats& s) const {
    j["gpt_split_bounce"] = s.gptSplitBounce;
    j["gpt_occlusion_beams"] = s.gptOcclusionBeams;
    j["edge_samples"] = edgeSamplesJson(s);
    j["demodulation"] = {{"on", s.demodulated}, {"pixels", s.demodulatedPixels}};
    j["reconstructions"] = reconstructionsJson(s);
    // Where the reconstructions' α came from: --alpha, or the scene's light (gpt_alpha.h).
    j["alpha_choice"] = options_.alpha ? std::string("--alpha")
                                       : std::string("scene light: ") + toString(gptLighting(s.features));
    // Where the final reconstruction came from: --recon, or the scene's surfaces
    // (gpt_reconstruction.h).
    if (!options_.reconstructions.empty())
        j["recon_choice"] = options_.reconstructionByScene
                                ? std::string("scene surfaces: ") + toString(gptSurfaces(s.features))
                                : std::string("--recon");
}

std::string GptIntegrator::summary(const RenderStats& s) const {
    std::string text;
    if (s.edgePixels)
        text += ", x" + std::to_string(1 + s.edgeSamples) + " in " + std::to_string(s.edgePixels) +
                " pixels around " + std::to_string(s.edgeProbePixels) + " edge pixels";
    if (s.demodulated) text += ", demodulated in " + std::to_string(s.demodulatedPixels) + " pixels";
    return text;
}

}  // namespace gdpt
