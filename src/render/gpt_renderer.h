// gpt_renderer.h — gradient-domain path tracing (Kettunen et al. 2015), sampling half: the
// render loop of renderPt with GptPass instead of PtPass. Returns the images the Poisson
// reconstruction consumes (primal, dx, dy), the very-direct image added after it, and the
// per-pixel variances of the estimates.
#pragma once

#include <string>

#include "render/gpt_pass.h"
#include "render/renderer.h"

namespace gdpt {

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
    RenderStats stats;  // spp = camera samples per pixel (each = 1 base + 4 offset paths)
};

// Renders with options.scene (resolution, depths, env, shiftThreshold), options.spp or
// options.timeBudget, seed, profile (per-kernel ms in stats.kernels: "gpt", "gpt_resolve"),
// quiet, workgroup, maxBatchSpp and cancel, exactly as renderPt interprets them.
RenderResultGpt renderGpt(const vk::Context& ctx, const Scene& scene, const RenderOptions& options);

// "auto" | "on" | "off"; throws gdpt::UsageError otherwise.
Demodulation parseDemodulation(const std::string& text);

// Whether renderGpt demodulates with these options on this scene.
bool demodulates(const Scene& scene, Demodulation d);

// modulation × image + direct, per pixel and channel; a null modulation or direct is left out.
// The final image from a reconstruction (or the primal) of a G-PT render's layers.
Image gptFinal(const Image& image, const Image* modulation, const Image* direct);
// The same for a reconstruction of result's primal/dx/dy, with its modulation (if any) and direct.
Image gptFinal(const RenderResultGpt& result, const Image& recon);

// Same, with G-PT-only settings (e.g. forcing the half-vector branch in for measurement).
// gpt.shiftThreshold is overridden by options.scene.shiftThreshold.
RenderResultGpt renderGpt(const vk::Context& ctx, const Scene& scene, const RenderOptions& options,
                          GptPassOptions gpt);

}  // namespace gdpt
