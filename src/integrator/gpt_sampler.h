// gpt_sampler.h — the sampling stage of gradient-domain path tracing (Kettunen et al. 2015):
// GptPass (gpt.comp: a base path and four offset paths per camera sample) driven by the
// shared sampling stage (pixel_sampling.h). Returns the images the screened Poisson
// reconstruction consumes (primal, dx, dy), the very-direct image added after it, and the
// per-pixel variances of the estimates. The G-PT integrator (gpt_integrator.h) reconstructs.
#pragma once

#include <cstdint>
#include <nlohmann/json_fwd.hpp>
#include <string>

#include "integrator/render_options.h"
#include "integrator/sample_groups.h"
#include "render/passes/gpt_pass.h"

namespace gdpt {

// Pixel-samples per batch of G-PT (maxBatchSppFor): a camera sample costs about four times
// a path tracer's.
inline constexpr std::uint64_t kGptBatchPixelSamples = std::uint64_t{1} << 16;

// First-hit texture demodulation (render/passes/gpt_pass.h): Auto = on where it can act
// (demodulationApplies: a base-colour texture on a Lambertian-only material).
enum class Demodulation { Auto, On, Off };

// The settings of G-PT's sampling (the rest is RenderOptions).
struct GptSamplingOptions {
    // The split bounce loop of gpt.comp: same image, chosen per device (splitBounceDefault).
    GptPassOptions::SplitBounce splitBounce = GptPassOptions::SplitBounce::Auto;
    // Compile the half-vector shift in even if no vertex can be glossy (measurement only).
    bool forceHalfVector = false;
    // Extra camera samples per camera sample in the pixels a geometric edge crosses
    // (render/passes/edge_pass.h); 0 = off.
    std::uint32_t edgeSamples = kEdgeSamplesAuto;
    Demodulation demodulate = Demodulation::Auto;
    // Where each pixel's camera samples come from, or null for the pixel's own stream
    // (GptPassOptions::streams).
    std::shared_ptr<const std::vector<gpu::PixelStream>> streams;
    // If set, the resolved primal (and with groupGradients dx, dy) is recorded at the batch
    // ends it wants (sample_groups.h: tgpt's groups of paired samples); not owned.
    SampleGroupRecorder* groups = nullptr;
    bool groupGradients = false;
};

struct RenderResultGpt {
    Image primal;     // indirect estimate ("throughput"), average of the pair estimators
    Image dx;         // I(x+1,y) - I(x,y), stored at (x,y); 0 in the last column
    Image dy;         // I(x,y+1) - I(x,y), stored at (x,y); 0 in the last row
    Image direct;     // emission seen directly by the camera; final = reconstruction + direct
    Image varPrimal;  // variance of the primal estimate (of the mean)
    Image varDx;      // variance of the dx estimate
    Image varDy;      // variance of the dy estimate
    Image varDirect;  // variance of the direct estimate
    // With demodulation (stats.demodulated): m̄, the pixel mean of the first-hit modulation;
    // primal, dx, dy and their variances are then of J = I / m̄, and final = modulation ×
    // reconstruction + direct (gptFinal). Empty without.
    Image modulation;
    Image varModulation;  // its variance (of the mean); empty without demodulation
    RenderStats stats;    // spp = camera samples per pixel (each = 1 base + 4 offset paths)
};

// Renders with options exactly as renderPt interprets them (maxBatchSpp 0: the default for
// the size, kGptBatchPixelSamples); per-kernel ms in stats.kernels ("gpt", "gpt_resolve", ...).
RenderResultGpt renderGpt(const vk::Context& ctx, const Scene& scene, const RenderOptions& options,
                          const GptSamplingOptions& gpt = {});

// `render --json`'s "edge_samples" of a G-PT-family render (gpt, tgpt): the factor, the pixels
// that got the edge samples and the probe's edge pixels.
nlohmann::json edgeSamplesJson(const RenderStats& stats);

// "auto" | "on" | "off"; throws gdpt::UsageError otherwise.
Demodulation parseDemodulation(const std::string& text);

// Whether renderGpt demodulates with these options on this scene.
bool demodulates(const Scene& scene, Demodulation d);

// modulation × image + direct, per pixel and channel; a null modulation or direct is left out.
// The final image from a reconstruction (or the primal) of a G-PT render's layers.
Image gptFinal(const Image& image, const Image* modulation, const Image* direct);
// The same for a reconstruction of result's primal/dx/dy, with its modulation (if any) and direct.
Image gptFinal(const RenderResultGpt& result, const Image& recon);

}  // namespace gdpt
