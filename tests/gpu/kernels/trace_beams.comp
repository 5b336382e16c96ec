// trace_beams.comp — test kernel: occlusion beams (traceAnyBeam, shaders/lib/bvh_coherent.glsl)
// against the same rays traced one by one (occludedTowards, traceAny). Beam i is rays 4i..4i+3:
// their origins, and in tMin whether each is wanted (0) or not (1); ray 4i's dir is the shared
// end, a target point where its tMax is finite, else the shared direction (rays to infinity).
// Output per ray: x the beam's answer, y the single ray's (1 = occluded).
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
// noGrowth != 0: the beam's boxes are not grown (the power check: the beam then misses
// occluders that its rays meet off the centre ray).
layout(push_constant, scalar) uniform Push {
    uint beamCount;
    uint noGrowth;
};

#include "lib/bvh_coherent.glsl"

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= beamCount) return;
    TestRay r0 = rays[4u * i], r1 = rays[4u * i + 1u], r2 = rays[4u * i + 2u], r3 = rays[4u * i + 3u];
    bvec4 want = bvec4(r0.tMin == 0.0, r1.tMin == 0.0, r2.tMin == 0.0, r3.tMin == 0.0);
    bool along = isinf(r0.tMax);
    OcclusionBeam beam = along ? beamAlong(r0.origin, r1.origin, r2.origin, r3.origin, want, r0.dir)
                               : beamTowards(r0.origin, r1.origin, r2.origin, r3.origin, want, r0.dir);
    if (noGrowth != 0u) beam.grow = vec3(0.0);
    bvec4 occluded = traceAnyBeam(beam);
    vec3 origin[4] = vec3[4](r0.origin, r1.origin, r2.origin, r3.origin);
    for (uint j = 0u; j < 4u; ++j) {
        bool single = false;
        if (want[j]) single = along ? traceAny(origin[j], r0.dir, 0.0, 1.0 / 0.0) : occludedTowards(origin[j], r0.dir);
        answers[4u * i + j] = vec4(occluded[j] ? 1.0 : 0.0, single ? 1.0 : 0.0, 0.0, 0.0);
    }
}
