// gpt_pass.h — the gradient-domain path-tracing pass: owns gpt.comp (base + 4 offset paths
// per camera sample, per-pixel statistics of central / neighbour / gradient / direct
// radiance) and gpt_resolve.comp (gathers neighbours' terms into primal, dx, dy, direct and
// their variances), with the buffers they write. Like PtPass: record() appends one batch
// tiled in rows; resolve() appends the gather; readback() after the fence.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "gpt_shared.h"
#include "image/image.h"
#include "render/passes/edge_pass.h"
#include "render/passes/emitter_supersampling_pass.h"
#include "render/passes/pt_pass.h"
#include "render/passes/sampling_pass.h"
#include "scene/scene.h"
#include "vk/buffer.h"
#include "vk/context.h"
#include "vk/kernel.h"

namespace gdpt {

class SceneGpu;
namespace vk {
class Context;
class GpuTimer;
}  // namespace vk

struct GptPassOptions {
    // Compile the half-vector branch in even if the scene has no glossy/specular vertex
    // (kHasGlossy spec constant forced true; for measuring what the branch costs).
    bool forceHalfVector = false;
    // The split bounce loop of gpt.comp (its gpt_split build): Auto = where it was measured
    // to pay (splitBounceDefault); the image is the same either way.
    enum class SplitBounce { Auto, On, Off };
    SplitBounce splitBounce = SplitBounce::Auto;
    // Rays per camera sample of emitter supersampling (emitter_supersampling_pass.h; 0 = off).
    std::uint32_t emitterSupersampling = kDefaultEmitterSupersampling;
    // Extra camera samples per camera sample in the pixels a geometric edge crosses
    // (edge_pass.h; 0 = off, kEdgeSamplesAuto = the rule of edge_options.h).
    std::uint32_t edgeSamples = kEdgeSamplesAuto;
    // The pair weights count the two pixels' sample counts where the edge samples make them
    // differ (shift.glsl, "Sample counts"); false: both ends alike, as before 2026-12-05 (tests
    // and measurements).
    bool countWeights = true;
    // First-hit texture demodulation (gpt.comp, kSpecGptDemodulate) in the pixels that
    // demodulationMask keeps (away from the edge probe's edges and from neighbours whose probe
    // saw another surface); GptImages::modulation then holds m̄ and primal/dx/dy are of
    // J = I / m̄.
    bool demodulate = false;
    // Where each pixel's camera samples come from (width × height entries: random stream and
    // jitter shift, gpt_shared.h), or null: pixel p draws stream p unshifted, as the path
    // tracer does. Temporal G-PT sets it to carry paths along the scene's motion
    // (integrator/motion_map.h).
    std::shared_ptr<const std::vector<gpu::PixelStream>> streams;
};

// Whether first-hit demodulation can act on a scene: some material has a base-colour texture
// and a Lambertian-only BSDF (the rule of gpt.comp's firstHitModulation).
bool demodulationApplies(const Scene& scene);

// The pixels where gpt.comp demodulates: 1 where every pixel q of the 3x3 neighbourhood of p
// (p included) holds no edge (edgeMask 0) and q's probe saw the same surface as p's (both
// missed, or the same material with edge.comp's normal and tangent-plane tests passed), else
// 0. The neighbour test catches the edges that lie between two pixels' probe points, such as
// an axis-aligned silhouette crossing a pixel near its border.
std::vector<std::uint32_t> demodulationMask(const std::vector<std::uint32_t>& edgeMask,
                                            const std::vector<gpu::EdgeProbe>& probes, std::uint32_t width,
                                            std::uint32_t height);

// Whether the shift needs its half-vector branch on this scene: some vertex can be glossy at
// the spec's shift threshold (gpt.comp's kHasGlossy; mlt.comp traces the same sample).
bool gptNeedsHalfVector(const SceneSpec& scene);

// Whether the split bounce loop pays on this device: lavapipe with Mesa before 23, which runs
// every branch under lane masks (15-25 % faster samples there); elsewhere the single loop,
// as on Mesa 25's lavapipe, where the split measured no faster and only costs pipeline
// creation time (bench/RESULTS.md, split bounce loop).
bool splitBounceDefault(const vk::DeviceInfo& device);
// The choice `s` on `device` (Auto: splitBounceDefault).
bool splitBounceFor(const vk::DeviceInfo& device, GptPassOptions::SplitBounce s);

// The resolved images (see gpt_resolve.comp for the estimators). With demodulation, primal,
// dx, dy and their variances are of J = I / m̄, `modulation` is m̄ (the final image is
// modulation × reconstruction + direct) and `varModulation` its variance (of the mean); else
// both are empty.
struct GptImages {
    Image primal, dx, dy, direct, varPrimal, varDx, varDy, varDirect, modulation, varModulation;
};

class GptPass final : public SamplingPass {
public:
    GptPass(const vk::Context& ctx, const SceneGpu& scene, WorkgroupSize wg = {},
            GptPassOptions options = {});
    // The same before the scene is on the device: the pipelines are created as `creation`
    // says (Background: while the caller builds the SceneGpu), and attach() binds the
    // scene's buffers (before record()).
    GptPass(const vk::Context& ctx, const SceneSpec& spec, WorkgroupSize wg, GptPassOptions options,
            vk::PipelineCreation creation);
    void attach(const SceneGpu& scene) override;
    // Waits for pipelines created in the background; the seconds waited.
    double waitForPipelines() const override;
    void recordWarmUp(VkCommandBuffer cmd) const override;

    // Finds the edge pixels (edge_pass.h) on `stream`, submitting and waiting; before the
    // first record(), else the batches have no extra edge samples. Once per pass.
    void findEdges(vk::CommandStream& stream);
    void prepare(vk::CommandStream& stream) override { findEdges(stream); }
    // Clears the statistics and counters.
    void reset();
    // Records a batch of `spp` camera samples per pixel starting at sample `sampleBase`, and
    // (after findEdges) edgeSamples × spp more in each edge pixel, from sample
    // sampleBase × edgeSamples of the edge streams (edgeSampleSeed).
    // `rows`: only the first that many image rows (a timed render's partial last pass; no
    // edge samples then).
    void record(VkCommandBuffer cmd, std::uint32_t sampleBase, std::uint32_t spp, std::uint32_t seed,
                vk::GpuTimer* timer, std::uint32_t rows = UINT32_MAX) override;
    // Records the gather into the resolved buffer (after the batches).
    void resolve(VkCommandBuffer cmd, vk::GpuTimer* timer);
    // Reads the counters written since the last call and clears them (after the fence).
    gpu::Counters takeCounters() override;
    // Reads the resolved images (after the fence of a resolve()).
    [[nodiscard]] GptImages readback() const;
    // Only the resolved primal, and dx and dy `withGradients` (in that order; not demodulated):
    // what a sample group records (integrator/sample_groups.h), without the other five images.
    [[nodiscard]] std::vector<Image> readbackMeans(bool withGradients) const;
    // The raw per-pixel statistics of the 10 buffers, in binding order, then the supersampled
    // visible emission's, then (with demodulation) the modulation's (after the fence), and
    // their replacement (before the next record()) to continue a checkpointed render.
    [[nodiscard]] std::vector<std::vector<gpu::PixelStats>> downloadStats() const override;
    void uploadStats(const std::vector<std::vector<gpu::PixelStats>>& stats) override;
    // Whether the kernel is the split bounce loop build (gpt_split, see gpt.comp).
    [[nodiscard]] bool splitBounceCompiled() const { return splitBounce_; }
    // The split build (its node-step form traces bundles).
    [[nodiscard]] bool tracesBundles() const override { return splitBounce_; }
    // Whether the kernel traces the offsets' occlusion rays as beams and the five primary rays as
    // one fan (GDPT_GPT_BEAMS, shaders/lib/gpt_trace.glsl: the split build in node steps).
    [[nodiscard]] bool occlusionBeamsCompiled() const { return occlusionBeams_; }
    [[nodiscard]] bool demodulating() const { return options_.demodulate; }
    // Pixels marked for demodulation by the last findEdges() (0 before).
    [[nodiscard]] std::uint32_t demodulatedPixels() const { return demodulatedPixels_; }
    [[nodiscard]] const EmitterSupersamplingPass& emitterSupersampling() const override {
        return emitterSupersampling_;
    }
    [[nodiscard]] const EdgePass& edges() const { return edges_; }

private:
    // The push constants every dispatch of this pass shares (threshold, image size).
    [[nodiscard]] gpu::GptFrameParams frameParams() const;

    const vk::Context& ctx_;
    std::uint32_t width_, height_;
    float shiftThreshold_;  // the spec's (SceneGpuOptions::shiftThreshold)
    GptPassOptions options_;
    bool halfVector_ = false;
    bool splitBounce_ = false;
    bool occlusionBeams_ = false;
    PixelBuffersChecked checked_;  // before any buffer below exists
    vk::Buffer counters_;
    EmitterSupersamplingPass emitterSupersampling_;
    EdgePass edges_;
    vk::Kernel kernel_;
    vk::Kernel resolveKernel_;
    // central, neighbor 0..3, gradient 0..3, direct (binding kBindGptCentral + index).
    std::array<vk::Buffer, 10> stats_;
    vk::Buffer resolved_;
    vk::Buffer demodMask_;   // uint per pixel (16-byte placeholder without demodulation)
    vk::Buffer modulation_;  // PixelStats per pixel (placeholder without demodulation)
    vk::Buffer streams_;     // PixelStream per pixel (16-byte placeholder without)
    std::uint32_t demodulatedPixels_ = 0;
};

}  // namespace gdpt
