#include "integrator/gpt_sampler.h"

#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>

#include "integrator/pixel_sampling.h"
#include "util/error.h"
#include "vk/context.h"

namespace gdpt {

Demodulation parseDemodulation(const std::string& text) {
    if (text == "auto") return Demodulation::Auto;
    if (text == "on") return Demodulation::On;
    if (text == "off") return Demodulation::Off;
    throw UsageError("--demodulate '" + text + "' must be auto, on or off");
}

bool demodulates(const Scene& scene, Demodulation d) {
    return d == Demodulation::On || (d == Demodulation::Auto && demodulationApplies(scene));
}

Image gptFinal(const Image& image, const Image* modulation, const Image* direct) {
    Image out = image;
    for (int c = 0; c < 3; ++c)
        for (std::size_t i = 0; i < out.pixelCount(); ++i) {
            float& v = out.plane(c)[i];
            if (modulation) v *= modulation->plane(c)[i];
            if (direct) v += direct->plane(c)[i];
        }
    return out;
}

Image gptFinal(const RenderResultGpt& result, const Image& recon) {
    return gptFinal(recon, result.modulation.empty() ? nullptr : &result.modulation, &result.direct);
}

RenderResultGpt renderGpt(const vk::Context& ctx, const Scene& scene, const RenderOptions& requested,
                          const GptSamplingOptions& gpt) {
    const RenderOptions options = withBatchLimit(requested, kGptBatchPixelSamples);
    GptPassOptions passOptions;
    passOptions.forceHalfVector = gpt.forceHalfVector;
    passOptions.splitBounce = gpt.splitBounce;
    passOptions.emitterSupersampling = options.emitterSupersampling;
    passOptions.edgeSamples = gpt.edgeSamples;
    passOptions.demodulate = demodulates(scene, gpt.demodulate);
    passOptions.streams = gpt.streams;
    GptPass* pass = nullptr;
    PixelSampling sampling(ctx, scene, options, "gpt", [&](const SceneSpec& spec) {
        auto p = std::make_unique<GptPass>(ctx, spec, options.workgroup, passOptions,
                                           vk::PipelineCreation::Background);
        pass = p.get();
        return p;
    });
    // Gathers the neighbours' terms into the resolved buffer (resolve only writes that
    // buffer, so sampling can continue after a checkpoint's snapshot).
    const auto resolveNow = [&] {
        sampling.submitAndWait("gpt resolve",
                               [&](VkCommandBuffer cmd) { pass->resolve(cmd, sampling.timer()); });
    };
    const auto recordGroup = [&](std::uint32_t done) {
        if (!gpt.groups->wants(done)) return;
        resolveNow();
        gpt.groups->record(done, pass->readbackMeans(gpt.groupGradients));
    };
    sampling.run(
        [&] {
            resolveNow();
            const GptImages images = pass->readback();
            return gptFinal(images.primal, images.modulation.empty() ? nullptr : &images.modulation,
                            &images.direct);
        },
        gpt.groups ? std::function<void(std::uint32_t)>(recordGroup) : std::function<void(std::uint32_t)>());

    RenderResultGpt result;
    if (sampling.stats().handedOff) {  // the statistics went to another process (or a shard file)
        sampling.finish();
        result.stats = sampling.stats();
        return result;
    }
    // The gather after the last batch (a separate submission so its time is its own).
    Timer phase;
    resolveNow();
    GptImages images = pass->readback();
    result.primal = std::move(images.primal);
    result.dx = std::move(images.dx);
    result.dy = std::move(images.dy);
    result.direct = std::move(images.direct);
    result.varPrimal = std::move(images.varPrimal);
    result.varDx = std::move(images.varDx);
    result.varDy = std::move(images.varDy);
    result.varDirect = std::move(images.varDirect);
    result.modulation = std::move(images.modulation);
    result.varModulation = std::move(images.varModulation);
    RenderStats& stats = sampling.stats();
    stats.readbackMs = phase.ms();
    stats.gptSplitBounce = pass->splitBounceCompiled();
    stats.gptOcclusionBeams = pass->occlusionBeamsCompiled();
    const std::uint32_t factor = pass->edges().samplesPerSpp();
    stats.edgeSamples = factor == kEdgeSamplesAuto ? 0 : factor;
    stats.edgePixels = stats.edgeSamples > 0 ? pass->edges().count() : 0;
    stats.edgeProbePixels = stats.edgeSamples > 0 ? pass->edges().edgeCount() : 0;
    stats.demodulated = pass->demodulating();
    stats.demodulatedPixels = pass->demodulatedPixels();
    sampling.finish();
    result.stats = stats;
    return result;
}

nlohmann::json edgeSamplesJson(const RenderStats& s) {
    return {{"factor", s.edgeSamples}, {"pixels", s.edgePixels}, {"edge_pixels", s.edgeProbePixels}};
}

}  // namespace gdpt
