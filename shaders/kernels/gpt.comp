// gpt.comp — gradient-domain path tracing megakernel, sampling half (Kettunen et al. 2015;
// the reference algorithm is GPT_REFERENCE §1). One invocation = one pixel p, a batch of
// camera samples per dispatch, the structure of pt.comp.
//
// Per camera sample: the base path (exactly pt.comp's path for the same random stream:
// same RNG consumption, NEE + BSDF sampling with the power heuristic, RR) and four offset
// paths starting at the same sub-pixel position ±1 pixel (right, down, left, up; +y = next
// row), built by the shift mapping (shift.glsl): reconnection when base current, base next
// and offset current vertices are rough, else the half-vector copy; NEE shifted with the
// same light point. Each pixel pair (p, p+δ_i) is estimated with MIS between the forward and
// reverse shift (power heuristic, ratio form, GPT_REFERENCE §1.6 and §7.1).
//
// Offset state (ratio form, GPT_REFERENCE §7.1): beta' = f'/p (offset contribution over the
// BASE path's pdf, Jacobians included) and r = J·p'/p (offset density in the base's measure
// over the base's density), rLight = the prefix ratio that applies to the light strategy at
// the next vertex. RR: q from the base; p and every p' get the factor q (beta and every
// beta' are divided by q, r is unchanged).
//
// Output per pixel p, per batch folded by Welford and merged by Chan (as pt.comp):
//   central(p)      Σ over the pairs of p of the base's MIS-weighted radiance
//   neighbor_i(p)   offset i's MIS-weighted radiance (an estimate for pixel p + δ_i)
//   gradient_i(p)   MIS-weighted (f_offset − f_base) of direction i
//   direct(p)       emission seen directly from the camera (never shifted)
// Each invocation writes only its own pixel: no races, no float atomics, deterministic.
// gpt_resolve.comp gathers the neighbours' terms.
#version 460
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require

#include "gpt_shared.h"
#include "lib/common.glsl"
#include "lib/rng.glsl"
#include "lib/ray.glsl"

layout(local_size_x_id = kSpecWorkgroupX, local_size_y_id = kSpecWorkgroupY) in;

#include "lib/scene_buffers.glsl"
layout(set = 0, binding = kBindCounters, scalar) buffer CounterBuf { Counters counters; };
layout(set = 0, binding = kBindGptCentral, scalar) buffer CentralBuf { PixelStats statCentral[]; };
layout(set = 0, binding = kBindGptNeighbor0, scalar) buffer Neighbor0Buf { PixelStats statNeighbor0[]; };
layout(set = 0, binding = kBindGptNeighbor1, scalar) buffer Neighbor1Buf { PixelStats statNeighbor1[]; };
layout(set = 0, binding = kBindGptNeighbor2, scalar) buffer Neighbor2Buf { PixelStats statNeighbor2[]; };
layout(set = 0, binding = kBindGptNeighbor3, scalar) buffer Neighbor3Buf { PixelStats statNeighbor3[]; };
layout(set = 0, binding = kBindGptGradient0, scalar) buffer Gradient0Buf { PixelStats statGradient0[]; };
layout(set = 0, binding = kBindGptGradient1, scalar) buffer Gradient1Buf { PixelStats statGradient1[]; };
layout(set = 0, binding = kBindGptGradient2, scalar) buffer Gradient2Buf { PixelStats statGradient2[]; };
layout(set = 0, binding = kBindGptGradient3, scalar) buffer Gradient3Buf { PixelStats statGradient3[]; };
layout(set = 0, binding = kBindGptDirect, scalar) buffer DirectBuf { PixelStats statDirect[]; };
layout(push_constant, scalar) uniform Push { GptFrameParams frame; };

#include "lib/scene_access.glsl"
#define GDPT_ANYHIT_FILTER(tri, u, v) alphaPasses(tri, u, v)
#include "lib/bvh_traverse.glsl"
#include "lib/shift.glsl"
#include "lib/gpt_light.glsl"

const float kInf = 1.0 / 0.0;
const ivec2 kOffsetDelta[4] = ivec2[4](ivec2(1, 0), ivec2(0, 1), ivec2(-1, 0), ivec2(0, -1));

vec3 cameraRay(vec2 pixelPos) {
    vec2 ndc = vec2(2.0 * pixelPos.x / float(scene.width) - 1.0,
                    1.0 - 2.0 * pixelPos.y / float(scene.height));
    vec3 d = scene.camForward + ndc.x * scene.tanHalfFovY * scene.aspect * scene.camRight +
             ndc.y * scene.tanHalfFovY * scene.camUp;
    return normalize(d);
}

#include "lib/gpt_path.glsl"

// Base + 4 offsets for one camera sample at pixelPos (continuous pixel coordinates).
void traceSample(inout Rng rng, vec2 pixelPos, uint px, uint py, inout uint rays, out vec3 direct,
                 inout OffsetPath offs[4]) {
    direct = vec3(0.0);
    for (uint i = 0u; i < 4u; ++i) {
        offs[i].alive = gptPairExists(px, py, i);
        offs[i].shifted = false;
        offs[i].baseSum = vec3(0.0);
        offs[i].offSum = vec3(0.0);
        offs[i].beta = vec3(1.0);  // pinhole, box filter: camera weight 1 for every pixel
        offs[i].r = 1.0;           // image-plane translation: Jacobian 1, same pixel pdf
        offs[i].rLight = 1.0;
        offs[i].state = kShiftNotConnected;
    }

    // Primary rays. Emission at the base's first hit is "very direct": direct buffer only.
    vec3 o = scene.camPosition;
    vec3 d = cameraRay(pixelPos);
    Hit hit = traceClosest(o, d, 0.0, kInf);
    rays++;
    if (hit.triangle == kInvalidIndex) {
        if (kHasEnv) direct += scene.envRadiance;
        return;  // nothing is shifted (GPT_REFERENCE §1.2)
    }
    SurfaceHit sh = makeSurfaceHit(hit.triangle, hit.u, hit.v, d);
    if (kHasLightTris) direct += surfaceEmission(sh);
    for (uint i = 0u; i < 4u; ++i) {
        offs[i].shifted = offs[i].alive;
        if (!offs[i].alive) continue;
        vec3 di = cameraRay(pixelPos + vec2(kOffsetDelta[i]));
        Hit hi = traceClosest(o, di, 0.0, kInf);
        rays++;
        if (hi.triangle == kInvalidIndex) {
            offs[i].alive = false;  // base hit, offset missed: no shift
            continue;
        }
        offs[i].hit = makeSurfaceHit(hi.triangle, hi.u, hi.v, di);
        offs[i].woWorld = -di;
    }

    vec3 beta = vec3(1.0);  // base f/p
    for (uint depth = 0u; depth < kMaxDepth && depth < scene.maxDepth; ++depth) {
        // One-sided back faces absorb: the base path ends; an offset there cannot continue
        // (its reverse shift does not exist), so its pair falls back to the base alone.
        if (oneSidedBack(sh)) break;
        for (uint i = 0u; i < 4u; ++i) {
            if (offs[i].alive && offs[i].state == kShiftNotConnected && oneSidedBack(offs[i].hit))
                offs[i].alive = false;
        }

        BsdfParams bsdf = materialBsdf(sh.material, sh.uv);
        vec3 t, b;
        makeBasis(sh.ns, t, b);
        vec3 woLocal = toLocal(-d, t, b, sh.ns);
        vec3 origin = offsetRayOriginScaled(sh.p, sh.ng, scene.sceneRadius);

        // Offsets' own BSDFs and frames (NOT_CONNECTED only).
        BsdfParams offBsdf[4];
        vec3 offT[4], offB[4], offWo[4];
        for (uint i = 0u; i < 4u; ++i) {
            offBsdf[i] = bsdf;  // placeholder for shared / dead offsets (never read)
            if (!offs[i].alive) continue;
            if (offs[i].state == kShiftNotConnected) {
                SurfaceHit oh = offs[i].hit;
                offBsdf[i] = materialBsdf(oh.material, oh.uv);
                makeBasis(oh.ns, offT[i], offB[i]);
                offWo[i] = toLocal(offs[i].woWorld, offT[i], offB[i], oh.ns);
            } else {
                offWo[i] = toLocal(offs[i].woWorld, t, b, sh.ns);  // shared vertex, own wo
            }
        }

        // Whether the light strategy exists for each pair at this vertex (GPT_REFERENCE §1.5):
        // always for a lone base (failed shift) and a shared vertex; for separate vertices
        // only if both are rough (area lights; the BSDF never hits a punctual light). The
        // BSDF-sampled emission of the next vertex then competes with it or not. Rough means
        // rough over ALL components (not only the smooth ones NEE evaluates, the reference's
        // choice): only then does the BSDF step reconnect to the light point, so NEE and BSDF
        // sampling use the same shift and their pair weights sum to one (the smooth-only rule,
        // combined with the all-components classification above, made a diffuse lobe under
        // a mirror coat count its light twice: NEE with four strategies, and again through
        // the half-vector branch, which has no light strategy).
        bool baseRoughNee = roughAll(bsdf);
        bool lightActive[4];
        for (uint i = 0u; i < 4u; ++i) {
            // A Dirac-only offset vertex fails every shift of both techniques, so its pair is
            // the lone base's (PT weights, light strategy included).
            lightActive[i] = !offs[i].alive || offs[i].state != kShiftNotConnected ||
                             bsdfIsDeltaOnly(offBsdf[i]) || (baseRoughNee && roughAll(offBsdf[i]));
        }

        // ---- Next-event estimation with the same light point for all (§1.5) ----
        // Densities are visibility-aware: a path whose last segment is occluded cannot be
        // produced by BSDF sampling (its BSDF density is 0) but can by light sampling. This
        // keeps the four weights of a path equal whichever technique sampled it.
        vec3 ul = rngNext3(rng);
        LightSample ls;
        if (!bsdfIsDeltaOnly(bsdf) && sampleLight(sh.p, ul, ls) && dot(ls.wi, sh.ng) > 0.0) {
            vec3 wiLocal = toLocal(ls.wi, t, b, sh.ns);
            vec3 f = bsdfEval(bsdf, woLocal, wiLocal);
            float pdfBsdf = ls.isDelta != 0u ? 0.0 : bsdfPdf(bsdf, woLocal, wiLocal);
            rays++;
            bool visible = !traceAny(origin, ls.wi, 0.0, ls.dist * (1.0 - 1e-4));
            vec3 fBase = visible ? beta * f * ls.Li / ls.pdf : vec3(0.0);
            float pdfBsdfV = visible ? pdfBsdf : 0.0;  // BSDF density including visibility
            for (uint i = 0u; i < 4u; ++i) {
                if (!gptPairExists(px, py, i)) continue;
                if (!offs[i].alive) {
                    // Failed shift: the base alone, with PT's weight.
                    addPair(offs[i], gptMisWeight(ls.pdf, pdfBsdfV, 0.0, 0.0), fBase, vec3(0.0));
                    continue;
                }
                if (offs[i].state != kShiftNotConnected) {
                    // Shared vertex: same light point and visibility; the offset's own
                    // incoming direction only changes the BSDF (§1.5 RECENTLY_CONNECTED).
                    vec3 fo = f;
                    float pdfBsdfO = pdfBsdfV;
                    if (offs[i].state == kShiftRecentlyConnected) {
                        fo = bsdfEval(bsdf, offWo[i], wiLocal);
                        pdfBsdfO = (ls.isDelta != 0u || !visible) ? 0.0 : bsdfPdf(bsdf, offWo[i], wiLocal);
                    }
                    vec3 fOff = visible ? offs[i].beta * fo * ls.Li / ls.pdf : vec3(0.0);
                    float w = gptMisWeight(ls.pdf, pdfBsdfV, offs[i].r * ls.pdf, offs[i].r * pdfBsdfO);
                    addPair(offs[i], w, fBase, fOff);
                    continue;
                }
                // NOT_CONNECTED: reconnect the offset vertex to the same light point, only if
                // both vertices are rough or the light is punctual; otherwise this NEE sample
                // counts for neither (weight 0, the reference's choice).
                if (ls.isDelta == 0u && !lightActive[i]) continue;
                BsdfParams ob = offBsdf[i];
                SurfaceHit oh = offs[i].hit;
                vec3 toLight = ls.pLight - oh.p;
                float distO = length(toLight);
                vec3 wiO = toLight / distO;
                // Densities of the offset path under the reverse technique: zero where the
                // base sampler at p+δ would have rejected it (light behind the surface, light
                // facing away, Dirac-only vertex), which makes the shift fail.
                vec3 liO;
                float jacobianLight;
                bool valid = distO > 0.0 && dot(wiO, oh.ng) > 0.0 && !bsdfIsDeltaOnly(ob) &&
                             gptOffsetLight(ls, ul, sh.p, oh.p, wiO, distO, liO, jacobianLight);
                if (!valid) {
                    addPair(offs[i], gptMisWeight(ls.pdf, pdfBsdfV, 0.0, 0.0), fBase, vec3(0.0));
                    continue;
                }
                vec3 wiLocalO = toLocal(wiO, offT[i], offB[i], oh.ns);
                vec3 fo = bsdfEval(ob, offWo[i], wiLocalO) * liO;
                float pdfBsdfO = ls.isDelta != 0u ? 0.0 : bsdfPdf(ob, offWo[i], wiLocalO);
                vec3 fOff = vec3(0.0);
                // The offset's visibility matters for its contribution and for its BSDF
                // density (which enters the base's weight).
                if (maxComponent(fo) > 0.0 || (pdfBsdfO > 0.0 && maxComponent(fBase) > 0.0)) {
                    rays++;
                    if (!traceAny(offsetRayOriginScaled(oh.p, oh.ng, scene.sceneRadius), wiO, 0.0, distO * (1.0 - 1e-4)))
                        fOff = offs[i].beta * fo * (jacobianLight / ls.pdf);
                    else
                        pdfBsdfO = 0.0;
                }
                // Light strategy of the offset in the base's measure: p'_L J = p_L (same light
                // point, area measure); BSDF strategy p'_B J.
                float w = gptMisWeight(ls.pdf, pdfBsdfV, offs[i].r * ls.pdf,
                                       offs[i].r * pdfBsdfO * jacobianLight);
                addPair(offs[i], w, fBase, fOff);
            }
        }

        // ---- BSDF sampling continues the base path ----
        BsdfSample bs;
        if (!bsdfSample(bsdf, woLocal, rngNext3(rng), bs)) break;
        vec3 wi = toWorld(bs.wi, t, b, sh.ns);
        if (dot(wi, sh.ng) <= 0.0) break;
        beta *= bs.weight;
        bool prevSpecular = bs.lobe == kLobeSpecular;
        vec3 prevP = sh.p;

        // Russian roulette from the base, shared by the offsets (§1.4).
        float rrInv = 1.0;
        if (depth + 1u >= scene.rrDepth) {
            float q = min(maxComponent(beta), 0.95);
            if (rngNext(rng) >= q) break;
            rrInv = 1.0 / q;
            beta *= rrInv;
        }
        if (depth + 1u >= kMaxDepth) break;  // pt.comp would not trace this segment either

        Hit next = traceClosest(origin, wi, 0.0, kInf);
        rays++;
        bool baseMissed = next.triangle == kInvalidIndex;
        if (baseMissed && !kHasEnv) break;
        SurfaceHit nextSh;
        bool baseNextRough = true;
        if (!baseMissed) {
            nextSh = makeSurfaceHit(next.triangle, next.u, next.v, wi);
            if (kHasGlossy) baseNextRough = roughAll(materialBsdf(nextSh.material, nextSh.uv));
        }
        bool baseCurRough = roughAll(bsdf);

        // ---- Shift every live offset over this segment (§1.4) ----
        for (uint i = 0u; i < 4u; ++i) {
            if (!offs[i].alive) continue;
            if (offs[i].state == kShiftConnected) {
                offs[i].beta *= bs.weight * rrInv;  // shares the vertex: same f and p
                offs[i].rLight = offs[i].r;
                continue;
            }
            if (offs[i].state == kShiftRecentlyConnected) {
                // Shared vertex, own incoming direction: re-evaluate f and p (never Dirac: a
                // reconnection target has no Dirac lobe, shiftRoughnessAll).
                vec3 fo = bsdfEval(bsdf, offWo[i], bs.wi);
                float po = bsdfPdf(bsdf, offWo[i], bs.wi);
                offs[i].beta *= fo * (rrInv / bs.pdf);
                offs[i].r *= po / bs.pdf;
                offs[i].rLight = offs[i].r;
                offs[i].state = kShiftConnected;
                continue;
            }
            SurfaceHit oh = offs[i].hit;
            BsdfParams ob = offBsdf[i];
            vec3 ohOrigin = offsetRayOriginScaled(oh.p, oh.ng, scene.sceneRadius);
            bool offCurRough = roughAll(ob);
            if (shiftUseReconnection(baseCurRough, baseNextRough, offCurRough)) {
                // Reconnection shift: connect to the base's next vertex (or the environment
                // in the same direction, J = 1); occlusion = failure.
                vec3 wiO = wi;
                float jacobianShift = 1.0;
                bool ok;
                float dist = kInf;
                if (baseMissed) {
                    ok = dot(wiO, oh.ng) > 0.0;
                } else {
                    vec3 e = nextSh.p - oh.p;
                    dist = length(e);
                    wiO = e / dist;
                    jacobianShift = reconnectionJacobian(sh.p, oh.p, nextSh.p, nextSh.ng);
                    // Same side of the target as the base (else it is another surface point
                    // for BSDF and emission), leaving above the offset's geometric surface.
                    ok = dist > 0.0 && jacobianShift > 0.0 && dot(wiO, oh.ng) > 0.0 &&
                         dot(wiO, nextSh.ng) < 0.0;
                }
                if (!ok) {
                    offs[i].alive = false;  // no offset path: the reverse never maps here
                    continue;
                }
                float rPrefix = offs[i].r;
                // Light strategy at the target: p'_L J = p_L, so the offset's light density in
                // the base's measure is rPrefix·p_L (zero if the offset vertex cannot do NEE).
                offs[i].rLight = bsdfIsDeltaOnly(ob) ? 0.0 : rPrefix;
                offs[i].woWorld = -wiO;
                offs[i].state = kShiftRecentlyConnected;
                // Visibility from the offset vertex (for the environment too: the 2019 fix).
                rays++;
                if (traceAny(ohOrigin, wiO, 0.0, baseMissed ? kInf : dist * (1.0 - 1e-4))) {
                    // Occluded: the offset path has no BSDF density and no contribution, but
                    // light sampling could still produce it, so its light density stays in
                    // this vertex's emission weight. r = 0 and beta' = 0 then act as a failed
                    // shift for everything after.
                    offs[i].beta = vec3(0.0);
                    offs[i].r = 0.0;
                    continue;
                }
                vec3 wiLocalO = toLocal(wiO, offT[i], offB[i], oh.ns);
                vec3 fo = bsdfEval(ob, offWo[i], wiLocalO);
                float po = bsdfPdf(ob, offWo[i], wiLocalO);
                offs[i].beta *= fo * (jacobianShift * rrInv / bs.pdf);
                offs[i].r *= po * jacobianShift / bs.pdf;
                continue;
            }
            if (!kHasGlossy) {
                offs[i].alive = false;  // unreachable when every vertex is rough
                continue;
            }
            // Half-vector copy shift (reflection only: gdpt has no transmission).
            bool baseDirac = bs.lobe == kLobeSpecular;
            if (baseDirac ? !bsdfHasDelta(ob) : bsdfIsDeltaOnly(ob)) {
                offs[i].alive = false;  // Dirac and smooth never shift into each other
                continue;
            }
            vec3 wiLocalO;
            vec3 fo;
            float po;
            float jacobianShift = 1.0;
            if (baseDirac) {
                // Mirror: h = n; Dirac weight F(cos_o) and discrete pdf P(mirror lobe), J = 1.
                wiLocalO = vec3(-offWo[i].x, -offWo[i].y, offWo[i].z);
                fo = glossyFresnel(ob, offWo[i].z);
                po = offWo[i].z > 0.0 ? glossySelectProb(ob, offWo[i]) : 0.0;
            } else {
                if (!halfVectorReflect(woLocal, bs.wi, offWo[i], wiLocalO, jacobianShift)) {
                    offs[i].alive = false;
                    continue;
                }
                fo = bsdfEval(ob, offWo[i], wiLocalO);
                po = bsdfPdf(ob, offWo[i], wiLocalO);
            }
            vec3 wiO = toWorld(wiLocalO, offT[i], offB[i], oh.ns);
            if (!(po > 0.0) || !(wiLocalO.z > 0.0) || dot(wiO, oh.ng) <= 0.0) {
                offs[i].alive = false;
                continue;
            }
            offs[i].beta *= fo * (jacobianShift * rrInv / bs.pdf);
            offs[i].r *= po * jacobianShift / bs.pdf;
            Hit ho = traceClosest(ohOrigin, wiO, 0.0, kInf);
            rays++;
            bool offMissed = ho.triangle == kInvalidIndex;
            if (offMissed != baseMissed) {
                offs[i].alive = false;  // environment / surface mismatch
                continue;
            }
            bool offNextRough = true;
            if (!offMissed) {
                offs[i].hit = makeSurfaceHit(ho.triangle, ho.u, ho.v, wiO);
                offNextRough = roughAll(materialBsdf(offs[i].hit.material, offs[i].hit.uv));
            }
            // Invertibility: the reverse shift would have reconnected (§1.4).
            if (!shiftHalfVectorInvertible(baseCurRough, offCurRough, offNextRough)) {
                offs[i].alive = false;
                continue;
            }
            offs[i].woWorld = -wiO;
        }

        // ---- Emission reached by the BSDF sample: environment or an emitter (§1.6) ----
        if (baseMissed) {
            vec3 le = scene.envRadiance;
            for (uint i = 0u; i < 4u; ++i) {
                if (!gptPairExists(px, py, i)) continue;
                if (!offs[i].alive) {
                    addPair(offs[i], 1.0, beta * le, vec3(0.0));
                } else {
                    // Not light-sampled: two strategies, base and offset.
                    addPair(offs[i], gptMisWeightPair(offs[i].r), beta * le, offs[i].beta * le);
                }
            }
            break;
        }
        if (kHasLightTris) {
            vec3 le = surfaceEmission(nextSh);
            float pdfLight = 0.0;
            if (!prevSpecular && maxComponent(le) > 0.0) {
                vec3 nl = normalize(cross(triGeoms[nextSh.triangle].e1, triGeoms[nextSh.triangle].e2));
                pdfLight = lightTrianglePdf(nextSh.triangle, prevP, nextSh.p, nl);
            }
            for (uint i = 0u; i < 4u; ++i) {
                if (!gptPairExists(px, py, i)) continue;
                // The light strategy competes only where NEE counted for this pair.
                float pdfLightPair = lightActive[i] ? pdfLight : 0.0;
                if (!offs[i].alive) {
                    // Failed shift (before or at this bounce): the base alone. After a failed
                    // half-vector step the pair had no NEE, so the base takes full weight.
                    if (maxComponent(le) > 0.0)
                        addPair(offs[i], gptMisWeight(bs.pdf, pdfLightPair, 0.0, 0.0), beta * le, vec3(0.0));
                } else if (offs[i].state == kShiftNotConnected) {
                    // Half-vector branch: BSDF sampling only, w = p²/(p² + (J p')²).
                    vec3 leO = surfaceEmission(offs[i].hit);
                    if (maxComponent(le) > 0.0 || maxComponent(leO) > 0.0)
                        addPair(offs[i], gptMisWeightPair(offs[i].r), beta * le, offs[i].beta * leO);
                } else if (maxComponent(le) > 0.0) {
                    // Reconnected (this bounce or before): four strategies.
                    float w = gptMisWeight(bs.pdf, pdfLightPair, offs[i].r * bs.pdf,
                                           offs[i].rLight * pdfLightPair);
                    addPair(offs[i], w, beta * le, offs[i].beta * le);
                }
            }
        }
        // Nothing left to carry (e.g. the base and all offsets sit on a black emitter): every
        // later contribution of every pair would be w·0, so stop tracing.
        bool carries = maxComponent(beta) > 0.0;
        for (uint i = 0u; i < 4u; ++i) carries = carries || (offs[i].alive && maxComponent(offs[i].beta) > 0.0);
        if (!carries) break;
        sh = nextSh;
        d = wi;
    }
}

void main() {
    uint x = gl_GlobalInvocationID.x;
    uint y = gl_GlobalInvocationID.y + frame.rowOffset;
    if (x >= scene.width || y >= scene.height || gl_GlobalInvocationID.y >= frame.rowCount) return;
    uint pixel = y * scene.width + x;

    // 0 central, 1..4 neighbor_i, 5..8 gradient_i, 9 direct.
    Welford acc[10];
    for (uint k = 0u; k < 10u; ++k) {
        acc[k].mean = vec3(0.0);
        acc[k].m2 = vec3(0.0);
    }
    uint n = 0u;
    uint rays = 0u;
    uint nan = 0u;
    uint shiftPairs = 0u, shiftFailures = 0u;
    OffsetPath offs[4];
    for (uint s = 0u; s < frame.samplesPerPixel; ++s) {
        // Same stream as pt.comp's sample s: the base path is PT's path.
        Rng rng = rngInit(pixel, frame.sampleBase + s, frame.seed);
        vec2 jitter = rngNext2(rng);
        vec3 direct;
        traceSample(rng, vec2(x, y) + jitter, x, y, rays, direct, offs);
        for (uint i = 0u; i < 4u; ++i) {
            shiftPairs += offs[i].shifted ? 1u : 0u;
            shiftFailures += offs[i].shifted && !offs[i].alive ? 1u : 0u;
        }
        vec3 central = vec3(0.0);
        bool finite = isFinite(direct);
        for (uint i = 0u; i < 4u; ++i) {
            central += offs[i].baseSum;
            finite = finite && isFinite(offs[i].baseSum) && isFinite(offs[i].offSum);
        }
        n++;
        if (!finite) {
            // Counted, never written: the whole sample (all quantities) becomes zero so the
            // pairs stay consistent.
            nan++;
            for (uint k = 0u; k < 10u; ++k) welfordAdd(acc[k], vec3(0.0), n);
            continue;
        }
        welfordAdd(acc[0], central, n);
        for (uint i = 0u; i < 4u; ++i) {
            welfordAdd(acc[1u + i], offs[i].offSum, n);
            welfordAdd(acc[5u + i], offs[i].offSum - offs[i].baseSum, n);
        }
        welfordAdd(acc[9], direct, n);
    }
    if (n > 0u) {
        statCentral[pixel] = chanMerge(statCentral[pixel], acc[0], n);
        statNeighbor0[pixel] = chanMerge(statNeighbor0[pixel], acc[1], n);
        statNeighbor1[pixel] = chanMerge(statNeighbor1[pixel], acc[2], n);
        statNeighbor2[pixel] = chanMerge(statNeighbor2[pixel], acc[3], n);
        statNeighbor3[pixel] = chanMerge(statNeighbor3[pixel], acc[4], n);
        statGradient0[pixel] = chanMerge(statGradient0[pixel], acc[5], n);
        statGradient1[pixel] = chanMerge(statGradient1[pixel], acc[6], n);
        statGradient2[pixel] = chanMerge(statGradient2[pixel], acc[7], n);
        statGradient3[pixel] = chanMerge(statGradient3[pixel], acc[8], n);
        statDirect[pixel] = chanMerge(statDirect[pixel], acc[9], n);
    }
    atomicAdd(counters.raysTraced, rays);
    atomicAdd(counters.pathsCompleted, n);
    if (nan > 0u) atomicAdd(counters.nanSamples, nan);
    atomicAdd(counters.shiftPairs, shiftPairs);
    if (shiftFailures > 0u) atomicAdd(counters.shiftFailures, shiftFailures);
}
