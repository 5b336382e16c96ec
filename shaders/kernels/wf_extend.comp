// wf_extend.comp — wavefront schedule, stage 1: closest hit of every live path's next
// segment (a small kernel: traversal only). Dead paths are skipped.
#version 460
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require

#include "gdpt_shared.h"
#include "lib/common.glsl"

layout(local_size_x_id = kSpecWorkgroupX, local_size_y_id = kSpecWorkgroupY) in;

#include "lib/scene_buffers.glsl"
layout(set = 0, binding = kBindPathState, scalar) readonly buffer StateBuf { PathState paths[]; };
layout(set = 0, binding = kBindPathHits, scalar) writeonly buffer HitBuf { vec4 pathHits[]; };
layout(push_constant, scalar) uniform Push { FrameParams frame; };

#include "lib/scene_access.glsl"
#define GDPT_ANYHIT_FILTER(tri, u, v) alphaPasses(tri, u, v)
#include "lib/bvh_traverse.glsl"

void main() {
    loadScene();
    uint i = gl_GlobalInvocationID.y * scene.width + gl_GlobalInvocationID.x;
    if (gl_GlobalInvocationID.x >= scene.width || gl_GlobalInvocationID.y >= scene.height) return;
    if ((paths[i].flags & kPathFlagAlive) == 0u) return;
    Hit h = traceClosest(paths[i].origin, paths[i].dir, 0.0, 1.0 / 0.0);
    pathHits[i] = vec4(h.t, h.u, h.v, uintBitsToFloat(h.triangle));
}
