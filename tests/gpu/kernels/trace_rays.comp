// trace_rays.comp — test kernel: closest-hit and any-hit queries for a list of rays, using
// the product's traversal (shaders/lib/bvh_traverse.glsl), for comparison with brute force.
#version 460
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "gdpt_shared.h"
#include "lib/common.glsl"

layout(local_size_x = 64) in;
#include "lib/scene_geometry.glsl"
layout(set = 0, binding = kBindTestInput, scalar) readonly buffer RayBuf { TestRay rays[]; };
layout(set = 0, binding = kBindTestOutput, scalar) writeonly buffer HitBuf { vec4 hits[]; };
layout(set = 0, binding = kBindTestOutput2, scalar) writeonly buffer AnyBuf { uint anyHits[]; };
layout(push_constant, scalar) uniform Push { uint rayCount; };

#include "lib/bvh_traverse.glsl"

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= rayCount) return;
    TestRay r = rays[i];
    Hit h = traceClosest(r.origin, r.dir, r.tMin, r.tMax);
    hits[i] = vec4(h.t, h.u, h.v, uintBitsToFloat(h.triangle));
    anyHits[i] = traceAny(r.origin, r.dir, r.tMin, r.tMax) ? 1u : 0u;
}
