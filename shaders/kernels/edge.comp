// edge.comp — finds the pixels that a geometric edge crosses, for G-PT's extra samples there
// (EdgePass, src/render/passes/edge_pass.h). One invocation = one pixel; writes mask[p] = 1 if the
// pixel holds an edge, else 0, and probe[p] = what its first probe ray hit (EdgeProbe), which
// the host compares across neighbouring pixels for first-hit demodulation.
//
// Why: at a geometric edge (a silhouette, a crease, a change of material) the pixel's value
// depends on which surface each camera sample lands on, and so do the gradients of its four
// pairs: the offsets of a base path on one side see the other side. That pixel-coverage
// noise is in the gradients as much as in the primal, so the screened Poisson reconstruction
// cannot smooth it away, and these pixels hold most of a G-PT image's error (the Cornell box
// at 16 spp: 2 % of the pixels; doubling their samples alone took relMSE 0.0039 -> 0.0034,
// bench/RESULTS.md, edge samples).
//
// The test: four rays at the centres of the pixel's quarters; the pixel holds an edge when
// they disagree on hit or miss, on the material, on the geometric normal (more than ~26°
// apart, which a smooth mesh's neighbouring facets stay within), or, with like normals, on
// the surface (a point further off the first hit's tangent plane than a quarter of its
// distance from it: a step in depth between parallel faces). Fixed positions and no random
// numbers: the choice depends on the scene and camera alone, never on a sample's radiance,
// so more samples there keep every pixel's estimate unbiased.
#version 460
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "gpt_shared.h"
#include "lib/common.glsl"
#include "lib/rng.glsl"
#include "lib/ray.glsl"

layout(local_size_x_id = kSpecWorkgroupX, local_size_y_id = kSpecWorkgroupY) in;

#include "lib/scene_buffers.glsl"
#include "lib/pixel_buffers.glsl"
layout(buffer_reference, scalar, buffer_reference_align = 4) buffer EdgeProbeArray { EdgeProbe v[]; };
GDPT_PIXEL_BUFFER(kBindGptEdgeMask, UintArray, edgeMask);
#define edgeMask edgeMask_.v
GDPT_PIXEL_BUFFER(kBindGptEdgeProbe, EdgeProbeArray, edgeProbe);
#define edgeProbe edgeProbe_.v

#include "lib/scene_access.glsl"
#define GDPT_ANYHIT_FILTER(tri, u, v) alphaPasses(tri, u, v)
#include "lib/bvh_traverse.glsl"
#include "lib/camera.glsl"
#include "lib/surface_rules.glsl"

void main() {
    loadScene();
    uint x = gl_GlobalInvocationID.x;
    uint y = gl_GlobalInvocationID.y;
    if (x >= scene.width || y >= scene.height) return;

    bool edge = false;
    bool miss0 = false;
    uint material0 = 0u;
    vec3 n0 = vec3(0.0);
    vec3 p0 = vec3(0.0);
    for (uint i = 0u; i < 4u; ++i) {
        vec2 pos = vec2(x, y) + vec2(0.25 + 0.5 * float(i & 1u), 0.25 + 0.5 * float(i >> 1u));
        vec3 d = cameraRay(pos);
        Hit h = traceClosest(scene.camPosition, d, 0.0, 1.0 / 0.0);
        bool miss = h.triangle == kInvalidIndex;
        uint material = 0u;
        vec3 n = vec3(0.0);
        vec3 p = vec3(0.0);
        if (!miss) {
            SurfaceHit sh = makeSurfaceHit(h.triangle, h.u, h.v, d);
            material = sh.material;
            n = sh.ng;
            p = sh.p;
        }
        if (i == 0u) {
            miss0 = miss;
            material0 = material;
            n0 = n;
            p0 = p;
        } else if (miss != miss0) {
            edge = true;
        } else if (!miss) {
            edge = edge || !probeHitsAgree(material0, p0, n0, material, p, n);
        }
    }
    uint pixel = y * scene.width + x;
    edgeMask[pixel] = edge ? 1u : 0u;
    EdgeProbe probe;
    probe.position = p0;
    probe.material = material0;
    probe.normal = n0;
    probe.hit = miss0 ? 0u : 1u;
    edgeProbe[pixel] = probe;
}
