// pt.comp — unidirectional path tracing, megakernel schedule: one invocation = one pixel,
// which traces `samplesPerPixel` whole paths (estimator in lib/pt_core.glsl).
//
// Accumulation: each invocation folds its batch into a Welford accumulator and merges that
// into the pixel's running PixelStats (lib/pixel_stats.glsl, which also states the policy for
// non-finite samples); the variance feeds the statistical tests.
#version 460
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "gdpt_shared.h"
#include "lib/common.glsl"
#include "lib/rng.glsl"
#include "lib/ray.glsl"

layout(local_size_x_id = kSpecWorkgroupX, local_size_y_id = kSpecWorkgroupY) in;

#include "lib/scene_buffers.glsl"
#include "lib/pixel_buffers.glsl"
GDPT_PIXEL_BUFFER(kBindAccum, PixelStatsArray, accum);
#define accum accum_.v
layout(set = 0, binding = kBindCounters, scalar) buffer CounterBuf { Counters counters; };
layout(push_constant, scalar) uniform Push { FrameParams frame; };

#include "lib/scene_access.glsl"
#define GDPT_ANYHIT_FILTER(tri, u, v) alphaPasses(tri, u, v)
#include "lib/bvh_traverse.glsl"
#include "lib/pt_core.glsl"

void main() {
    loadScene();
    uint x = gl_GlobalInvocationID.x;
    uint y = gl_GlobalInvocationID.y + frame.rowOffset;
    if (x >= scene.width || y >= scene.height || gl_GlobalInvocationID.y >= frame.rowCount) return;

    Welford acc = welfordInit();
    uint n = 0u;
    uint nan = 0u;
    uint rays = 0u;
    for (uint i = 0u; i < frame.samplesPerPixel; ++i) {
        PathState s = ptBegin(x, y, frame.sampleBase + i, frame.seed);
        ptTrace(s);
        rays += s.rays;
        bool finite = isFinite(s.radiance);
        if (!finite) nan++;
        n++;
        welfordAdd(acc, statsSample(s.radiance, finite), n);
    }
    uint pixel = y * scene.width + x;
    accum[pixel] = chanMerge(accum[pixel], acc, n);
    atomicAdd(counters.raysTraced, rays);
    atomicAdd(counters.pathsCompleted, n);
    if (nan > 0u) atomicAdd(counters.nanSamples, nan);
}
