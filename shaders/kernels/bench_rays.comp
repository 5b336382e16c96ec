// bench_rays.comp — ray-throughput benchmark kernel for `gdpt bench` (not used by renders).
// mode 0: primary rays only (one camera ray per pixel-sample, closest hit).
// mode 1: incoherent rays: camera ray, then up to three cosine-sampled diffuse bounces
//         (4 closest-hit segments per path), no shading, no light sampling.
// Each invocation counts the rays it traced; the counters feed rays/s.
#version 460
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "gdpt_shared.h"
#include "lib/common.glsl"
#include "lib/rng.glsl"
#include "lib/ray.glsl"
#include "lib/sampling.glsl"

layout(local_size_x_id = kSpecWorkgroupX, local_size_y_id = kSpecWorkgroupY) in;

#include "lib/scene_buffers.glsl"
layout(set = 0, binding = kBindCounters, scalar) buffer CounterBuf { Counters counters; };
layout(push_constant, scalar) uniform Push { FrameParams frame; };

#include "lib/bvh_traverse.glsl"
#include "lib/camera.glsl"

void main() {
    loadScene();
    uint x = gl_GlobalInvocationID.x;
    uint y = gl_GlobalInvocationID.y + frame.rowOffset;
    if (x >= scene.width || y >= scene.height || gl_GlobalInvocationID.y >= frame.rowCount) return;
    uint pixel = y * scene.width + x;
    uint rays = 0u;
    uint hits = 0u;
    bool incoherent = frame.pad0 == 1u;
    for (uint s = 0u; s < frame.samplesPerPixel; ++s) {
        Rng rng = rngInit(pixel, frame.sampleBase + s, frame.seed);
        vec2 pos = vec2(x, y) + rngNext2(rng);
        vec3 d = cameraRay(pos);
        vec3 o = scene.camPosition;
        uint segments = incoherent ? 4u : 1u;
        for (uint k = 0u; k < segments; ++k) {
            Hit h = traceClosest(o, d, 0.0, 1.0 / 0.0);
            rays++;
            if (h.triangle == kInvalidIndex) break;
            hits++;
            TriangleGeom g = triangleGeom(h.triangle);
            vec3 n = normalize(cross(g.e1, g.e2));
            if (dot(n, d) > 0.0) n = -n;
            vec3 p = g.v0 + h.u * g.e1 + h.v * g.e2;
            vec3 t, b;
            makeBasis(n, t, b);
            d = toWorld(sampleCosineHemisphere(rngNext2(rng)), t, b, n);
            o = offsetRayOriginScaled(p, n, scene.sceneRadius);
        }
    }
    atomicAdd(counters.raysTraced, rays);
    atomicAdd(counters.pathsCompleted, hits);
}
