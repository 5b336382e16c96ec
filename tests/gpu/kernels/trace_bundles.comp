// trace_bundles.comp — test kernel: ray bundles (traceClosestBundle, shaders/lib/bvh_coherent.glsl)
// against the same rays traced one by one (traceClosest). Bundle i is rays 5i..5i+4, every ray's
// dir its direction (normalised here, as G-PT's rays are unit), tMin whether it is wanted (0) or
// not (1). Primary fans (flag 2 clear): ray 5i's origin is the fan's, ray 5i the centre ray,
// always traced, every ray to infinity. Bundles of four (flag 2 set): rays 5i+1..5i+4 from their
// own origins to their own tMax, about the centre ray (ray 5i's origin and direction, not
// traced). Output per ray: [2j] the bundle's hit (t, triangle bits, u, v), [2j+1] the single
// ray's (a ray not wanted: a miss).
#version 460
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "gdpt_shared.h"
#include "lib/common.glsl"

layout(local_size_x = 64) in;
#include "lib/scene_geometry.glsl"
layout(set = 0, binding = kBindTestInput, scalar) readonly buffer RayBuf { TestRay rays[]; };
layout(set = 0, binding = kBindTestOutput, scalar) writeonly buffer OutBuf { vec4 answers[]; };
// flags: 1 = the bundle's boxes are not grown (the power check: the bundle then misses the
// closest hits of rays off the centre ray); 2 = bundles of four instead of primary fans.
layout(push_constant, scalar) uniform Push {
    uint bundleCount;
    uint flags;
};

#include "lib/bvh_coherent.glsl"

vec4 packHit(Hit h) { return vec4(h.t, uintBitsToFloat(h.triangle), h.u, h.v); }

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= bundleCount) return;
    vec3 o[5];
    vec3 d[5];
    bool wanted[5];
    for (uint j = 0u; j < 5u; ++j) {
        TestRay r = rays[5u * i + j];
        o[j] = r.origin;
        d[j] = normalize(r.dir);
        wanted[j] = r.tMin == 0.0;
    }
    bool four = (flags & 2u) != 0u;
    RayBundle b;
    if (four) {
        vec4 tMax = vec4(0.0);
        for (uint j = 1u; j < 5u; ++j) tMax[j - 1u] = wanted[j] ? rays[5u * i + j].tMax : 0.0;
        b = bundleOfFour(o[0], d[0], o[1], d[1], o[2], d[2], o[3], d[3], o[4], d[4], tMax);
        wanted[0] = false;
    } else {
        for (uint j = 1u; j < 5u; ++j) o[j] = o[0];
        b = fanFrom(o[0], d[0], d[1], d[2], d[3], d[4], bvec4(wanted[1], wanted[2], wanted[3], wanted[4]));
        wanted[0] = true;
    }
    if ((flags & 1u) != 0u) b.grow = vec3(0.0);
    Hit h[5];
    traceClosestBundle(b, h[0], h[1], h[2], h[3], h[4]);
    for (uint j = 0u; j < 5u; ++j) {
        float tMax = four ? rays[5u * i + j].tMax : 1.0 / 0.0;
        Hit single = wanted[j] ? traceClosest(o[j], d[j], 0.0, tMax) : missHit(1.0 / 0.0);
        answers[2u * (5u * i + j)] = packHit(h[j]);
        answers[2u * (5u * i + j) + 1u] = packHit(single);
    }
}
