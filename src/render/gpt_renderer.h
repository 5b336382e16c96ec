// gpt_renderer.h — gradient-domain path tracing (Kettunen et al. 2015), sampling half: the
// render loop of renderPt with GptPass instead of PtPass. Returns the images the Poisson
// reconstruction consumes (primal, dx, dy), the very-direct image added after it, and the
// per-pixel variances of the estimates.
#pragma once

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
    RenderStats stats;  // spp = camera samples per pixel (each = 1 base + 4 offset paths)
};

// Renders with options.scene (resolution, depths, env, shiftThreshold), options.spp or
// options.timeBudget, seed, profile (per-kernel ms in stats.kernels: "gpt", "gpt_resolve"),
// quiet, workgroup, maxBatchSpp and cancel, exactly as renderPt interprets them.
RenderResultGpt renderGpt(const vk::Context& ctx, const Scene& scene, const RenderOptions& options);

// Same, with G-PT-only settings (e.g. forcing the half-vector branch in for measurement).
// gpt.shiftThreshold is overridden by options.scene.shiftThreshold.
RenderResultGpt renderGpt(const vk::Context& ctx, const Scene& scene, const RenderOptions& options,
                          GptPassOptions gpt);

}  // namespace gdpt
