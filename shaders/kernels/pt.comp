// pt.comp — unidirectional path tracing megakernel (one invocation = one pixel, a batch of
// samples per dispatch).
//
// Estimator (Veach 1997 ch. 9; pbrt-v4 PathIntegrator): at every non-specular vertex one
// light sample (next-event estimation to an emissive triangle chosen in proportion to power,
// or to a punctual light) and one BSDF sample; emission found by the BSDF sample is weighted
// against NEE by the power heuristic. Russian roulette from scene.rrDepth on with survival
// probability min(max(throughput), 0.95). The environment is a constant radiance reached only
// by BSDF sampling. Box pixel filter: the sample position is uniform over the pixel square.
//
// Accumulation: each invocation folds its batch into per-pixel (mean, M2, count) with
// Welford's update and merges that into the running PixelStats by Chan et al.'s pairwise
// formula, so the stored values stay bounded and float32 keeps ~1e-6 relative accuracy over
// 10^5 samples; the variance feeds the statistical tests.
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
layout(push_constant, scalar) uniform Push { FrameParams frame; };

#include "lib/scene_access.glsl"
#define GDPT_ANYHIT_FILTER(tri, u, v) alphaPasses(tri, u, v)
#include "lib/bvh_traverse.glsl"

const float kInf = 1.0 / 0.0;

vec3 cameraRay(vec2 pixelPos) {
    vec2 ndc = vec2(2.0 * pixelPos.x / float(scene.width) - 1.0,
                    1.0 - 2.0 * pixelPos.y / float(scene.height));
    vec3 d = scene.camForward + ndc.x * scene.tanHalfFovY * scene.aspect * scene.camRight +
             ndc.y * scene.tanHalfFovY * scene.camUp;
    return normalize(d);
}

// One path sample; returns radiance. rays counts traced rays.
vec3 tracePath(inout Rng rng, vec2 pixelPos, inout uint rays) {
    vec3 o = scene.camPosition;
    vec3 d = cameraRay(pixelPos);
    vec3 L = vec3(0.0);
    vec3 beta = vec3(1.0);
    float prevPdf = 0.0;       // solid-angle pdf of the BSDF sample that produced d
    bool prevSpecular = true;  // camera ray or Dirac bounce: no MIS on emission
    vec3 prevP = o;
    for (uint depth = 0u; depth < kMaxDepth && depth <= scene.maxDepth; ++depth) {
        Hit hit = traceClosest(o, d, 0.0, kInf);
        rays++;
        if (hit.triangle == kInvalidIndex) {
            if (kHasEnv) L += beta * scene.envRadiance;
            break;
        }
        SurfaceHit sh = makeSurfaceHit(hit.triangle, hit.u, hit.v, d);
        vec3 Le = surfaceEmission(sh);
        if (kHasLightTris && maxComponent(Le) > 0.0) {
            float w = 1.0;
            if (!prevSpecular) {
                vec3 nl = normalize(cross(triGeoms[sh.triangle].e1, triGeoms[sh.triangle].e2));
                float lightPdf = lightTrianglePdf(sh.triangle, prevP, sh.p, nl);
                w = powerHeuristic(1.0, prevPdf, 1.0, lightPdf);
            }
            L += beta * Le * w;
        }
        Material mat = materials[sh.material];
        // One-sided materials: the back face is an opaque black absorber.
        if (!sh.frontFace && (mat.flags & kMatFlagDoubleSided) == 0u) break;
        if (depth == scene.maxDepth) break;  // no further segment allowed

        BsdfParams bsdf = materialBsdf(sh.material, sh.uv);
        vec3 t, b;
        makeBasis(sh.ns, t, b);
        vec3 woLocal = toLocal(-d, t, b, sh.ns);
        vec3 origin = offsetRayOrigin(sh.p, sh.ng);

        // Next-event estimation.
        vec3 ul = rngNext3(rng);
        if (!bsdfIsDeltaOnly(bsdf)) {
            LightSample ls;
            if (sampleLight(sh.p, ul, ls) && dot(ls.wi, sh.ng) > 0.0) {
                vec3 wiLocal = toLocal(ls.wi, t, b, sh.ns);
                vec3 f = bsdfEval(bsdf, woLocal, wiLocal);
                if (maxComponent(f) > 0.0) {
                    rays++;
                    float tMax = ls.dist * (1.0 - 1e-4);
                    if (!traceAny(origin, ls.wi, 0.0, tMax)) {
                        float w = 1.0;
                        if (ls.isDelta == 0u) w = powerHeuristic(1.0, ls.pdf, 1.0, bsdfPdf(bsdf, woLocal, wiLocal));
                        L += beta * f * ls.Li * (w / ls.pdf);
                    }
                }
            }
        }

        // BSDF sampling continues the path.
        BsdfSample bs;
        if (!bsdfSample(bsdf, woLocal, rngNext3(rng), bs)) break;
        vec3 wi = toWorld(bs.wi, t, b, sh.ns);
        if (dot(wi, sh.ng) <= 0.0) break;  // shading-normal leak below the geometric surface
        beta *= bs.weight;
        prevPdf = bs.pdf;
        prevSpecular = bs.lobe == kLobeSpecular;
        prevP = sh.p;
        o = origin;
        d = wi;

        if (depth + 1u >= scene.rrDepth) {
            float q = min(maxComponent(beta), 0.95);
            if (rngNext(rng) >= q) break;
            beta /= q;
        }
    }
    return L;
}

void main() {
    uint x = gl_GlobalInvocationID.x;
    uint y = gl_GlobalInvocationID.y + frame.rowOffset;
    if (x >= scene.width || y >= scene.height || gl_GlobalInvocationID.y >= frame.rowCount) return;
    uint pixel = y * scene.width + x;

    // Welford over this batch.
    vec3 mean = vec3(0.0);
    vec3 m2 = vec3(0.0);
    uint n = 0u;
    uint rays = 0u;
    uint nan = 0u;
    for (uint s = 0u; s < frame.samplesPerPixel; ++s) {
        Rng rng = rngInit(pixel, frame.sampleBase + s, frame.seed);
        vec2 jitter = rngNext2(rng);
        vec3 L = tracePath(rng, vec2(x, y) + jitter, rays);
        if (!isFinite(L)) {
            nan++;
            L = vec3(0.0);  // counted, and replaced by zero so the estimate stays finite
        }
        n++;
        vec3 delta = L - mean;
        mean += delta / float(n);
        m2 += delta * (L - mean);
    }

    // Chan et al. 1979 pairwise merge into the running statistics.
    PixelStats acc = accum[pixel];
    uint total = acc.count + n;
    if (total > 0u) {
        vec3 delta = mean - acc.mean;
        float fb = float(n) / float(total);
        acc.mean += delta * fb;
        acc.m2 += m2 + delta * delta * float(acc.count) * fb;
        acc.count = total;
        accum[pixel] = acc;
    }
    atomicAdd(counters.raysTraced, rays);
    atomicAdd(counters.pathsCompleted, n);
    if (nan > 0u) atomicAdd(counters.nanSamples, nan);
}
