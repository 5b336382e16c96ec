// tgpt_reconnect.comp — temporal differences by the reconnection shift: a path sampled in one
// frame of an animation and its offset path in the other frame, reconnected at the first
// vertex (docs/animation.md, "The reconnection shift", states the estimator and why it is
// unbiased). One invocation = one pixel p of the base frame; a batch of camera samples per
// dispatch, the structure of pt.comp.
//
// Both frames are bound at once (GDPT_TWO_FRAMES: FramePairGpu; selectFrame switches every
// scene access). The base path x̄ = (x1, x2, ...) is the path tracer's (pt_estimator.glsl: next-event
// estimation and BSDF sampling at every vertex, power heuristic between them, Russian roulette),
// with the same random numbers. Its offset ȳ in the other frame:
//   - y1 is the first hit of the camera ray through p's partner q at the same sub-pixel position
//     (shifted toroidally by the motion's sub-pixel part: TemporalPartner);
//   - every later vertex is the base's, carried by the animation: the same barycentric point of
//     the same triangle with the other frame's vertex positions (a miss keeps its direction, the
//     environment being static), and a light point likewise (a punctual light: the same light);
//   - where x1 and y1 are both mirrors (Dirac-only), the offset reflects on its own with the
//     base's numbers and traces its own ray, until both paths reach non-Dirac vertices: the
//     reconnection is at the first rough vertex, as G-PT's;
//   - the shift fails (no offset beyond) where one own vertex is a mirror and the other not, where
//     the base sampled a Dirac lobe elsewhere, and where the offset is not a path the other frame
//     samples: an occluded segment, a direction under a surface, a one-sided back face.
// In area measure every carried vertex has the Jacobian |A'(t)| / |A(t)| of its triangle
// (1 for rigid motion); y1 and x1 share the camera sample (Jacobian 1). Each contribution of the
// base (strategy s) and its offset are combined by the balance heuristic over the shift's two
// directions (Kettunen et al. 2015, eq. 11 with the temporal shift in place of the spatial one):
//   w = p(x̄) / (p(x̄) + p'(ȳ)·J),   D(p) = Σ w · (f'(ȳ)·J − f(x̄)) / p(x̄),
// where p' is the density with which the other frame samples ȳ and the offset's own strategy
// weight is in f'. The host dispatches the kernel with each frame as the base frame:
// dt(p → q) = D_forward(p) − D_reverse(q).
#version 460
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#define GDPT_TWO_FRAMES
#include "gdpt_shared.h"
#include "temporal_shared.h"
#include "lib/common.glsl"
#include "lib/rng.glsl"
#include "lib/ray.glsl"

layout(local_size_x_id = kSpecWorkgroupX, local_size_y_id = kSpecWorkgroupY) in;

#include "lib/scene_buffers.glsl"
#include "lib/pixel_buffers.glsl"
layout(buffer_reference, scalar, buffer_reference_align = 4) buffer TemporalPartnerArray { TemporalPartner v[]; };
GDPT_PIXEL_BUFFER(kBindTemporalPartner, TemporalPartnerArray, partners);
GDPT_PIXEL_BUFFER(kBindTemporalDifference, PixelStatsArray, statDifference);
GDPT_PIXEL_BUFFER(kBindTemporalBase, PixelStatsArray, statBase);
#define partners partners_.v
#define statDifference statDifference_.v
#define statBase statBase_.v
layout(set = 0, binding = kBindCounters, scalar) buffer CounterBuf { Counters counters; };
layout(push_constant, scalar) uniform Push { TemporalParams params; };

#include "lib/scene_access.glsl"
#define GDPT_ANYHIT_FILTER(tri, u, v) alphaPasses(tri, u, v)
#include "lib/bvh_traverse.glsl"
#include "lib/camera.glsl"
#include "lib/sampler.glsl"
#include "lib/pt_estimator.glsl"
#include "lib/pixel_stats.glsl"

// A vertex with what shading it needs: the surface, its BSDF and shading basis, and the unit
// direction back towards the vertex before it (world and local).
struct Vertex {
    SurfaceHit s;
    BsdfParams bsdf;
    vec3 t, b;
    vec3 wo, woLocal;
};

Vertex makeVertex(SurfaceHit s, vec3 incoming) {
    Vertex v;
    v.s = s;
    v.bsdf = materialBsdf(s.material, s.uv);
    makeBasis(s.ns, v.t, v.b);
    v.wo = -incoming;
    v.woLocal = toLocal(v.wo, v.t, v.b, s.ns);
    return v;
}

vec3 local(Vertex v, vec3 w) { return toLocal(w, v.t, v.b, v.s.ns); }

// Own vertices of a base and its offset pair up only if both are mirrors (Dirac-only) or
// neither is: a mirror's offset cannot reconnect to a rough vertex, nor the reverse.
bool mirrorMismatch(Vertex base, Vertex offset) {
    return bsdfIsDeltaOnly(base.bsdf) != bsdfIsDeltaOnly(offset.bsdf);
}

// Whether a one-sided material's back face was hit (an opaque black absorber: the path ends).
bool blackBackFace(SurfaceHit s) {
    return !s.frontFace && (material(s.material).flags & kMatFlagDoubleSided) == 0u;
}

// The point at barycentrics (u, v) of triangle `tri` in the selected frame.
vec3 trianglePoint(uint tri, float u, float v) {
    TriangleGeom g = triangleGeom(tri);
    return g.v0 + u * g.e1 + v * g.e2;
}

// The offset of a sample: alive while the shift holds, its throughput f'·J/p (per unit of the
// base's sampling density, its own strategy weights left out), and ratio = p'·J/p of the prefix.
struct Offset {
    bool alive;
    bool own;  // v is the offset's own vertex (its first hit, or one found through a mirror)
    Vertex v;
    vec3 throughput;
    float ratio;
};

void kill(inout Offset o) {
    o.alive = false;
    o.throughput = vec3(0.0);
    o.ratio = 0.0;
}

// Balance-heuristic weight of the base against its offset (ratio = p'·J/p; 0 where the shift
// failed, and the base then takes the whole contribution).
float pairWeight(float ratio, uint flags, uint baseFrame) {
    if ((flags & kTemporalFlagOneDirection) != 0u) return baseFrame == 0u ? 1.0 : 0.0;
    return 1.0 / (1.0 + ratio);
}

struct SampleResult {
    vec3 difference;  // Σ w · (offset − base)
    vec3 base;        // the base path's own radiance
    uint rays;
    bool paired;      // the base's camera ray hit a surface
    bool failed;      // ... and the shift failed at the first vertex
};

// Next-event estimation at the offset's vertex towards the base's light sample carried into the
// offset's frame (selected): the offset's contribution, and the pair ratio in `ratio` (0 where
// the offset's own sampler would not have taken the point). pBase: the base's density of the
// point (area measure; a punctual light's selection probability); areaBase: its triangle's area
// in the base frame.
vec3 offsetLight(Offset o, LightSample ls, vec3 ul, float pBase, float areaBase, out float ratio, inout uint rays) {
    ratio = 0.0;
    vec3 pLight, Le;
    float pOff;            // the offset frame's density of the carried point
    float jacobian = 1.0;  // of the carried point (its triangle's area ratio)
    float cosLight = 1.0;
    bool valid;
    if (ls.isDelta == 0u) {
        vec3 bary = sampleUniformTriangle(ul.yz);
        TriangleGeom g = triangleGeom(ls.triangle);
        pLight = g.v0 + bary.y * g.e1 + bary.z * g.e2;
        TriangleShading sh = triangleShading(ls.triangle);
        Material m = material(sh.material);
        cosLight = dot(normalize(cross(g.e1, g.e2)), normalize(o.v.s.p - pLight));
        valid = (cosLight > 0.0 || (m.flags & kMatFlagDoubleSided) != 0u) && abs(cosLight) > 1e-7;
        cosLight = abs(cosLight);
        Le = m.emissive;
        if (kHasTextures) Le *= sampleTexture(m.emissiveTex, hitUv(ls.triangle, bary.y, bary.z)).xyz;
        // (A triangle that is no light in this frame, e.g. of zero area here: no density.)
        pOff = sh.lightIndex == kInvalidIndex ? 0.0
                                              : lightTriangleSelectProb() * lightTriangle(sh.lightIndex).pmf / sh.area;
        jacobian = sh.area / areaBase;
    } else {
        PunctualLight l = punctualLight(ls.punctual);
        pLight = l.position;
        float falloff = 1.0;
        if (l.type == kPunctualSpot) {
            float c = dot(normalize(o.v.s.p - pLight), l.direction);
            falloff = clamp((c - l.cosOuter) / max(l.cosInner - l.cosOuter, 1e-4), 0.0, 1.0);
            falloff *= falloff;
        }
        Le = l.intensity * falloff;
        pOff = (1.0 - lightTriangleSelectProb()) / float(scene.numPunctualLights);
        valid = falloff > 0.0;
    }
    vec3 toLight = pLight - o.v.s.p;
    float dist2 = dot(toLight, toLight);
    vec3 wi = toLight * inversesqrt(dist2);
    // The offset's own sampler skips a point under its surface (as the base does).
    if (!valid || !(dist2 > 0.0) || !(dot(wi, o.v.s.ng) > 0.0) || !(pOff > 0.0)) return vec3(0.0);
    ratio = o.ratio * pOff * jacobian / pBase;
    vec3 wiLocal = local(o.v, wi);
    vec3 f = bsdfEval(o.v.bsdf, o.v.woLocal, wiLocal);
    if (!(maxComponent(f) > 0.0)) return vec3(0.0);
    rays++;
    if (occludedTowards(offsetRayOriginScaled(o.v.s.p, o.v.s.ng, scene.sceneRadius), pLight)) return vec3(0.0);
    float g = cosLight / dist2;
    float w = 1.0;
    if (ls.isDelta == 0u) w = powerHeuristic(1.0, pOff / g, 1.0, bsdfPdf(o.v.bsdf, o.v.woLocal, wiLocal));
    return o.throughput * f * Le * (g * jacobian * w / pBase);
}

// The offset follows the base's segment from v along wi to `hit` (a miss: the environment in
// direction wi) into the offset's frame (selected): its vertex there, or killed where the offset's
// own sampler would not reach it. Returns the emission it sees there (MIS-weighted as its own
// path tracer would); the pair ratio is o.ratio afterwards. baseDensity: the base's density of
// its new vertex (bs.pdf · cos / distance², or bs.pdf for a miss); areaBase: the hit triangle's
// area in the base frame.
vec3 offsetStep(inout Offset o, vec3 wi, Hit hit, float baseDensity, float areaBase, inout uint rays) {
    vec3 origin = offsetRayOriginScaled(o.v.s.p, o.v.s.ng, scene.sceneRadius);
    rays++;
    if (hit.triangle == kInvalidIndex) {
        vec3 wiLocal = local(o.v, wi);
        float pdf = bsdfPdf(o.v.bsdf, o.v.woLocal, wiLocal);
        if (!(dot(wi, o.v.s.ng) > 0.0) || !(pdf > 0.0) || traceAny(origin, wi, 0.0, 1.0 / 0.0)) {
            kill(o);
            return vec3(0.0);
        }
        o.throughput *= bsdfEval(o.v.bsdf, o.v.woLocal, wiLocal) / baseDensity;
        o.ratio *= pdf / baseDensity;
        return kHasEnv ? o.throughput * scene.envRadiance : vec3(0.0);
    }
    vec3 p = trianglePoint(hit.triangle, hit.u, hit.v);
    vec3 d = p - o.v.s.p;
    float dist2 = dot(d, d);
    vec3 wiOff = d * inversesqrt(dist2);
    vec3 wiLocal = local(o.v, wiOff);
    float pdf = bsdfPdf(o.v.bsdf, o.v.woLocal, wiLocal);
    if (!(dist2 > 0.0) || !(dot(wiOff, o.v.s.ng) > 0.0) || !(pdf > 0.0) || occludedTowards(origin, p)) {
        kill(o);
        return vec3(0.0);
    }
    vec3 f = bsdfEval(o.v.bsdf, o.v.woLocal, wiLocal);
    Vertex next = makeVertex(makeSurfaceHit(hit.triangle, hit.u, hit.v, wiOff), wiOff);
    o.own = false;
    // Area measure: the offset frame's cosine over distance² at the carried vertex times the
    // triangle's area ratio, per unit of the base's density.
    float g = abs(dot(next.s.ng, wiOff)) / dist2 * (triangleShading(hit.triangle).area / areaBase) / baseDensity;
    o.throughput *= f * g;
    o.ratio *= pdf * g;
    vec3 from = o.v.s.p;
    o.v = next;
    vec3 Le = vec3(0.0);
    if (kHasLightTris) {
        Le = surfaceEmission(next.s);
        if (maxComponent(Le) > 0.0) Le *= ptEmissionWeight(false, pdf, from, hit.triangle, next.s.p);
    }
    return o.throughput * Le;
}

// Both own vertices Dirac-only (mirrors): the offset samples its own reflection with the base's
// numbers and traces its own ray in its frame (selected) to its next own vertex, as G-PT's offsets
// follow the base through a mirror until both reach rough vertices, where they reconnect. In the
// camera sample's measure both steps are Dirac: their densities are the lobe choices' (pdfBase,
// the offset's). Killed where the offset's reflection fails or only one of the two rays leaves the
// scene (baseMissed: the base's did). Returns the emission it sees there (weight 1 after a Dirac
// step, as the base's).
vec3 offsetOwnStep(inout Offset o, vec3 uBsdf, float pdfBase, bool baseMissed, inout uint rays) {
    BsdfSample os;
    if (!bsdfSample(o.v.bsdf, o.v.woLocal, uBsdf, os) || os.lobe != kLobeSpecular) {
        kill(o);
        return vec3(0.0);
    }
    vec3 wi = toWorld(os.wi, o.v.t, o.v.b, o.v.s.ns);
    if (!(dot(wi, o.v.s.ng) > 0.0)) {
        kill(o);
        return vec3(0.0);
    }
    o.throughput *= os.weight * (os.pdf / pdfBase);
    o.ratio *= os.pdf / pdfBase;
    Hit h = traceClosest(offsetRayOriginScaled(o.v.s.p, o.v.s.ng, scene.sceneRadius), wi, 0.0, 1.0 / 0.0);
    rays++;
    if ((h.triangle == kInvalidIndex) != baseMissed) {
        kill(o);
        return vec3(0.0);
    }
    if (h.triangle == kInvalidIndex) return kHasEnv ? o.throughput * scene.envRadiance : vec3(0.0);
    o.v = makeVertex(makeSurfaceHit(h.triangle, h.u, h.v, wi), wi);
    return kHasLightTris ? o.throughput * surfaceEmission(o.v.s) : vec3(0.0);
}

SampleResult temporalSample(uint x, uint y, TemporalPartner partner, uint sampleIndex) {
    SampleResult r;
    r.difference = vec3(0.0);
    r.base = vec3(0.0);
    r.rays = 2u;
    r.paired = false;
    r.failed = false;
    const uint baseFrame = params.baseFrame;
    const uint offFrame = 1u - baseFrame;
    const uint flags = params.flags;
    uint width = scene.width;
    uint pixel = y * width + x;
    LdSample lds = ldSampleInit(pixel, sampleIndex, params.seed);
    Rng rng = rngInit(pixel, sampleIndex, params.seed);
    vec2 u = ldGet2(lds, kLdDimPixel);

    // The offset's camera ray, then the base's.
    selectFrame(offFrame);
    vec2 q = vec2(float(partner.pixel % width), float(partner.pixel / width));
    vec3 offDir = cameraRay(q + fract(u + vec2(partner.shiftX, partner.shiftY)));
    Hit offHit = traceClosest(scene.camPosition, offDir, 0.0, 1.0 / 0.0);
    Offset o;
    o.alive = offHit.triangle != kInvalidIndex;
    o.own = true;
    o.throughput = vec3(1.0);
    o.ratio = 1.0;
    if (o.alive) {
        o.v = makeVertex(makeSurfaceHit(offHit.triangle, offHit.u, offHit.v, offDir), offDir);
        o.alive = !blackBackFace(o.v.s);
    }

    selectFrame(baseFrame);
    vec3 dir = cameraRay(vec2(x, y) + u);
    Hit hit = traceClosest(scene.camPosition, dir, 0.0, 1.0 / 0.0);
    if (hit.triangle == kInvalidIndex) return r;  // the environment seen directly: not shifted
    Vertex v = makeVertex(makeSurfaceHit(hit.triangle, hit.u, hit.v, dir), dir);
    r.paired = true;
    if (o.alive && mirrorMismatch(v, o.v)) o.alive = false;
    r.failed = !o.alive;
    if (!o.alive) kill(o);

    vec3 beta = vec3(1.0);
    // Vertex `depth` (0: the camera's first hit) is v; the emission the camera sees directly is
    // left out (G-PT's very-direct light), the other contributions are differenced.
    for (uint depth = 0u;; ++depth) {
        if (blackBackFace(v.s)) break;
        if (depth >= scene.maxDepth || depth + 1u >= kMaxDepth) break;
        if (o.alive && o.own && mirrorMismatch(v, o.v)) kill(o);
        vec3 origin = offsetRayOriginScaled(v.s.p, v.s.ng, scene.sceneRadius);

        // Next-event estimation: the base's light sample, and the same light point carried.
        vec3 ul = ldLight(lds, depth);
        LightSample ls;
        if (!bsdfIsDeltaOnly(v.bsdf) && sampleLight(v.s.p, ul, ls) && dot(ls.wi, v.s.ng) > 0.0) {
            vec3 base = vec3(0.0);
            ptAddNee(ls, v.bsdf, v.woLocal, local(v, ls.wi), origin, beta, base, r.rays);
            vec3 offset = vec3(0.0);
            float ratio = 0.0;
            if (o.alive) {
                // The base's density of its point: area measure, or the punctual light's choice.
                float pBase = ls.isDelta == 0u ? ls.pdf * abs(dot(ls.nLight, ls.wi)) / (ls.dist * ls.dist) : ls.pdf;
                float areaBase = ls.isDelta == 0u ? triangleShading(ls.triangle).area : 1.0;
                selectFrame(offFrame);
                offset = offsetLight(o, ls, ul, pBase, areaBase, ratio, r.rays);
                selectFrame(baseFrame);
            }
            r.difference += pairWeight(ratio, flags, baseFrame) * (offset - base);
            r.base += base;
        }

        // BSDF sampling continues the base (Russian roulette before the ray, as the path tracer);
        // the offset follows to the carried vertex.
        BsdfSample bs;
        vec3 uBsdf = ldBsdf(lds, depth);
        bool sampled = bsdfSample(v.bsdf, v.woLocal, uBsdf, bs);
        vec3 wi = sampled ? toWorld(bs.wi, v.t, v.b, v.s.ns) : vec3(0.0);
        if (!sampled || !(dot(wi, v.s.ng) > 0.0)) break;
        bool specular = bs.lobe == kLobeSpecular;
        beta *= bs.weight;
        float q;
        if (!ptRoulette(depth, beta, rng, q)) break;
        o.throughput /= q;
        // Both own vertices Dirac-only: the offset reflects on its own (below); a Dirac lobe sampled
        // anywhere else ends the shift.
        bool ownStep = o.alive && o.own && bsdfIsDeltaOnly(v.bsdf);
        if (specular && !ownStep) kill(o);
        hit = traceClosest(origin, wi, 0.0, 1.0 / 0.0);
        r.rays++;

        Vertex next;
        vec3 base = vec3(0.0);
        float baseDensity = bs.pdf;
        float areaBase = 1.0;
        if (hit.triangle == kInvalidIndex) {
            if (kHasEnv) base = beta * scene.envRadiance;
        } else {
            next = makeVertex(makeSurfaceHit(hit.triangle, hit.u, hit.v, wi), wi);
            vec3 d = next.s.p - v.s.p;
            baseDensity = bs.pdf * abs(dot(next.s.ng, wi)) / dot(d, d);
            areaBase = triangleShading(hit.triangle).area;
            vec3 Le = kHasLightTris ? surfaceEmission(next.s) : vec3(0.0);
            if (maxComponent(Le) > 0.0) base = beta * Le * ptEmissionWeight(specular, bs.pdf, v.s.p, hit.triangle, next.s.p);
        }
        vec3 offset = vec3(0.0);
        if (o.alive) {
            selectFrame(offFrame);
            offset = ownStep ? offsetOwnStep(o, uBsdf, bs.pdf, hit.triangle == kInvalidIndex, r.rays)
                             : offsetStep(o, wi, hit, baseDensity, areaBase, r.rays);
            selectFrame(baseFrame);
        }
        if (maxComponent(base) > 0.0 || maxComponent(offset) > 0.0) {
            r.difference += pairWeight(o.ratio, flags, baseFrame) * (offset - base);
            r.base += base;
        }
        if (hit.triangle == kInvalidIndex) break;
        // The offset's path ends where it meets a one-sided back face (its emission was counted).
        if (o.alive && blackBackFace(o.v.s)) kill(o);
        v = next;
    }
    return r;
}

void main() {
    loadScene();
    uint x = gl_GlobalInvocationID.x;
    uint y = gl_GlobalInvocationID.y + params.rowOffset;
    if (x >= scene.width || y >= scene.height || gl_GlobalInvocationID.y >= params.rowCount) return;
    uint pixel = y * scene.width + x;
    // Each direction's entries follow the other's (direction 0's first).
    uint slot = params.baseFrame * scene.width * scene.height + pixel;
    TemporalPartner partner = partners[slot];
    if (partner.pixel == kInvalidIndex) return;
    selectFrame(params.baseFrame);

    Welford difference = welfordInit();
    Welford base = welfordInit();
    uint n = 0u;
    uint nan = 0u;
    uint rays = 0u;
    uint pairs = 0u;
    uint failures = 0u;
    for (uint i = 0u; i < params.samplesPerPixel; ++i) {
        SampleResult s = temporalSample(x, y, partner, params.sampleBase + i);
        rays += s.rays;
        if (s.paired) pairs++;
        if (s.failed) failures++;
        bool finite = isFinite(s.difference) && isFinite(s.base);
        if (!finite) nan++;
        n++;
        welfordAdd(difference, statsSample(s.difference, finite), n);
        welfordAdd(base, statsSample(s.base, finite), n);
    }
    statDifference[slot] = chanMerge(statDifference[slot], difference, n);
    statBase[slot] = chanMerge(statBase[slot], base, n);
    atomicAdd(counters.raysTraced, rays);
    atomicAdd(counters.pathsCompleted, n);
    atomicAdd(counters.shiftPairs, pairs);
    atomicAdd(counters.shiftFailures, failures);
    if (nan > 0u) atomicAdd(counters.nanSamples, nan);
}
