// wf_shade.comp — wavefront schedule, stage 2 (and path start): frame.pad0 == 0 starts one
// path per pixel for sample frame.sampleBase; otherwise each live path consumes its hit
// (lib/pt_core.glsl: emission, NEE with its shadow ray, BSDF sampling, RR). A path that ends
// merges its radiance into the pixel's statistics (one sample, Welford). frame.pad1 counts
// paths still alive into counters.pad, so the host knows when the wave is drained.
#version 460
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require

#include "gdpt_shared.h"
#include "lib/common.glsl"
#include "lib/rng.glsl"
#include "lib/ray.glsl"

layout(local_size_x_id = kSpecWorkgroupX, local_size_y_id = kSpecWorkgroupY) in;

#include "lib/scene_buffers.glsl"
layout(set = 0, binding = kBindAccum, scalar) buffer AccumBuf { PixelStats accum[]; };
layout(set = 0, binding = kBindCounters, scalar) buffer CounterBuf { Counters counters; };
layout(set = 0, binding = kBindPathState, scalar) buffer StateBuf { PathState paths[]; };
layout(set = 0, binding = kBindPathHits, scalar) readonly buffer HitBuf { vec4 pathHits[]; };
layout(push_constant, scalar) uniform Push { FrameParams frame; };

#include "lib/scene_access.glsl"
#define GDPT_ANYHIT_FILTER(tri, u, v) alphaPasses(tri, u, v)
#include "lib/bvh_traverse.glsl"
#include "lib/pt_core.glsl"

void main() {
    loadScene();
    uint x = gl_GlobalInvocationID.x;
    uint y = gl_GlobalInvocationID.y;
    if (x >= scene.width || y >= scene.height) return;
    uint i = y * scene.width + x;
    if (frame.pad0 == 0u) {
        paths[i] = ptBegin(x, y, frame.sampleBase, frame.seed);
        return;
    }
    PathState s = paths[i];
    if ((s.flags & kPathFlagAlive) == 0u) return;
    vec4 h = pathHits[i];
    Hit hit;
    hit.t = h.x;
    hit.u = h.y;
    hit.v = h.z;
    hit.triangle = floatBitsToUint(h.w);
    ptProcessHit(s, hit);
    paths[i] = s;
    if ((s.flags & kPathFlagAlive) != 0u) {
        atomicAdd(counters.pad, 1u);
        return;
    }
    // One sample: its Welford accumulator is (L, 0).
    bool finite = isFinite(s.radiance);
    Welford one;
    one.mean = statsSample(s.radiance, finite);
    one.m2 = vec3(0.0);
    accum[i] = chanMerge(accum[i], one, 1u);
    uint nan = finite ? 0u : 1u;
    atomicAdd(counters.raysTraced, s.rays);
    atomicAdd(counters.pathsCompleted, 1u);
    if (nan > 0u) atomicAdd(counters.nanSamples, nan);
}
