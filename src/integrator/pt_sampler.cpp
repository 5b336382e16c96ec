#include "integrator/pt_sampler.h"

#include <memory>

#include "integrator/pixel_sampling.h"
#include "render/passes/pt_pass.h"
#include "vk/context.h"

namespace gdpt {

RenderResult renderPt(const vk::Context& ctx, const Scene& scene, const RenderOptions& requested) {
    const RenderOptions options = withBatchLimit(requested, kPtBatchPixelSamples);
    PtPass* pass = nullptr;
    PixelSampling sampling(ctx, scene, options, "pt", [&](const SceneSpec& spec) {
        auto p = std::make_unique<PtPass>(ctx, spec, options.workgroup, options.emitterSupersampling,
                                          vk::PipelineCreation::Background);
        pass = p.get();
        return p;
    });
    sampling.run([&] {
        Image mean, variance;
        pass->readback(mean, variance);
        return mean;
    });
    RenderResult result;
    if (sampling.stats().handedOff) {  // the statistics went to another process (or a shard file)
        sampling.finish();
        result.stats = sampling.stats();
        return result;
    }
    Timer phase;
    pass->readback(result.image, result.varianceOfMean);
    sampling.stats().readbackMs = phase.ms();
    sampling.finish();
    result.stats = sampling.stats();
    return result;
}

}  // namespace gdpt
