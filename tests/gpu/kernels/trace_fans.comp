// trace_fans.comp — test kernel: primary fans (traceClosestFan, shaders/lib/bvh_traverse.glsl)
// against the same rays traced one by one (traceClosest). Fan i is rays 5i..5i+4: ray 5i's
// origin is the fan's, every ray's dir is its direction (normalised here, as the camera's rays
// are unit), and tMin says whether rays 5i+1..5i+4 are wanted (0) or not (1). Output per ray:
// [2j] the fan's hit (t, triangle bits, u, v), [2j+1] the single ray's (a ray not wanted: a miss).
#version 460
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require
#include "gdpt_shared.h"
#include "lib/common.glsl"

layout(local_size_x = 64) in;
#include "lib/scene_geometry.glsl"
layout(set = 0, binding = kBindTestInput, scalar) readonly buffer RayBuf { TestRay rays[]; };
layout(set = 0, binding = kBindTestOutput, scalar) writeonly buffer OutBuf { vec4 answers[]; };
// noGrowth != 0: the fan's boxes are not grown (the power check: the fan then misses the
// closest hits of rays off the centre ray).
layout(push_constant, scalar) uniform Push {
    uint fanCount;
    uint noGrowth;
};

#include "lib/bvh_traverse.glsl"

vec4 packHit(Hit h) { return vec4(h.t, uintBitsToFloat(h.triangle), h.u, h.v); }

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= fanCount) return;
    vec3 o = rays[5u * i].origin;
    vec3 d[5];
    for (uint j = 0u; j < 5u; ++j) d[j] = normalize(rays[5u * i + j].dir);
    bvec4 want = bvec4(rays[5u * i + 1u].tMin == 0.0, rays[5u * i + 2u].tMin == 0.0,
                       rays[5u * i + 3u].tMin == 0.0, rays[5u * i + 4u].tMin == 0.0);
    PrimaryFan fan = fanFrom(o, d[0], d[1], d[2], d[3], d[4], want);
    if (noGrowth != 0u) fan.grow = vec3(0.0);
    Hit h[5];
    traceClosestFan(fan, h[0], h[1], h[2], h[3], h[4]);
    for (uint j = 0u; j < 5u; ++j) {
        bool wanted = j == 0u || want[j - 1u];
        Hit single = wanted ? traceClosest(o, d[j], 0.0, 1.0 / 0.0) : missHit(1.0 / 0.0);
        answers[2u * (5u * i + j)] = packHit(h[j]);
        answers[2u * (5u * i + j) + 1u] = packHit(single);
    }
}
