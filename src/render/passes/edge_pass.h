// edge_pass.h — the pixels that a geometric edge crosses (edge.comp), where GptPass adds
// `samplesPerSpp` extra camera samples per camera sample: their pixel-coverage noise sits in
// the gradients as much as in the primal, so the reconstruction cannot remove it and they
// hold most of a G-PT image's error. find() probes the image once (four rays per pixel at
// fixed positions: the choice depends on the geometry alone, so every pixel's estimate stays
// unbiased) and keeps the indices of the edge pixels and their four neighbours
// (edgeSampleList), in ascending order, in a buffer that gpt.comp reads in its edge-list mode
// (GptFrameParams::listCount).
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "gpt_shared.h"
#include "render/device_scene/scene_gpu.h"
#include "render/passes/edge_options.h"
#include "vk/buffer.h"
#include "vk/kernel.h"

namespace gdpt {

namespace vk {
class Context;
class CommandStream;
}  // namespace vk

class EdgePass {
public:
    // samplesPerSpp in [0, kMaxEdgeSamples], or kEdgeSamplesAuto: find() sets the factor from
    // the edge pixels' share (autoEdgeSamples, edge_options.h). 0 without maskNeeded disables
    // the pass (no pipeline, no pixels). maskNeeded: probe for mask() even without extra
    // samples (G-PT's first-hit demodulation keeps away from the edges).
    EdgePass(const vk::Context& ctx, const SceneSpec& spec, WorkgroupSize wg, std::uint32_t samplesPerSpp,
             vk::PipelineCreation creation, bool maskNeeded = false);
    void attach(const SceneGpu& scene);
    // Waits for a pipeline created in the background; the seconds waited.
    double waitForPipeline() const { return kernel_ ? kernel_->wait() : 0.0; }

    [[nodiscard]] bool enabled() const { return samplesPerSpp_ > 0 || maskNeeded_; }
    // The factor (with kEdgeSamplesAuto: kEdgeSamplesAuto until find() has chosen it).
    [[nodiscard]] std::uint32_t samplesPerSpp() const { return samplesPerSpp_; }
    // Adds the list and sample-rate bindings (kBindGptEdgeList, kBindGptSampleRate) to a
    // kernel's descriptor.
    static void configure(vk::KernelDesc& desc);
    // Binds the list and the rates to such a kernel (placeholders before find() or when
    // disabled); call again after find().
    void bindTo(vk::Kernel& kernel) const;
    // Probes the image on `stream` (submits and waits) and uploads the list. Once per pass;
    // later calls return at once. Nothing when disabled.
    void find(vk::CommandStream& stream);
    // Pixels that get the extra samples (edgeSampleList: the edge pixels and their four
    // neighbours; 0 before find() or when disabled).
    [[nodiscard]] std::uint32_t count() const { return count_; }
    // Whether the listed pixels take more samples than the others (after find(): some pixel
    // listed and a factor above 0): gpt.comp then reads the rates (GptFrameParams::sampleRates).
    [[nodiscard]] bool ratesDiffer() const { return count_ > 0 && samplesPerSpp_ > 0; }
    // Edge pixels the probe found (0 before find() or when disabled).
    [[nodiscard]] std::uint32_t edgeCount() const { return edgeCount_; }
    // The per-pixel mask of the last find() (1 = edge); empty before.
    [[nodiscard]] const std::vector<std::uint32_t>& mask() const { return mask_; }
    // What each pixel's first probe ray hit (with maskNeeded; empty before find() or without).
    [[nodiscard]] const std::vector<gpu::EdgeProbe>& probes() const { return probes_; }

private:
    const vk::Context& ctx_;
    std::uint32_t width_, height_;
    std::uint32_t samplesPerSpp_;
    bool maskNeeded_;
    std::optional<vk::Kernel> kernel_;
    vk::Buffer maskBuffer_;
    vk::Buffer probeBuffer_;
    vk::Buffer list_;
    vk::Buffer rates_;  // edgeSampleRates per pixel where they differ (ratesDiffer)
    std::vector<std::uint32_t> mask_;
    std::vector<gpu::EdgeProbe> probes_;
    std::uint32_t count_ = 0;
    std::uint32_t edgeCount_ = 0;
    bool found_ = false;
};

// The seed of the edge samples' random streams: independent of the camera samples' streams
// of the same seed (gpt.comp draws both through the same functions).
std::uint32_t edgeSampleSeed(std::uint32_t seed);

}  // namespace gdpt
