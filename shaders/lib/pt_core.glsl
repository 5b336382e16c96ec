// pt_core.glsl — one vertex of the unidirectional path tracer, shared by pt.comp and mlt.comp
// (PSSMLT's paths), built from the rules of pt_estimator.glsl, which tgpt_reconnect.comp's base
// path uses too. GLSL only; the including kernel has declared the scene buffers and included
// scene_access.glsl and bvh_traverse.glsl.
//
// Estimator (Veach 1997 ch. 9; pbrt-v4 PathIntegrator): at every non-Dirac vertex one light
// sample (NEE to an emissive triangle chosen in proportion to power, or to a punctual
// light) and one BSDF sample; emission found by the BSDF sample is weighted against NEE by
// the power heuristic. Russian roulette from scene.rrDepth segments on with survival
// probability min(max(throughput), 0.95). The constant environment is reached only by BSDF
// sampling. Depth convention (pbrt): vertex `depth` is reached after depth bounces; paths end
// after scene.maxDepth bounces.
#ifndef GDPT_LIB_PT_CORE
#define GDPT_LIB_PT_CORE

#include "lib/camera.glsl"
#include "lib/pixel_stats.glsl"
#include "lib/sampler.glsl"
#include "lib/pt_estimator.glsl"
#include "lib/visible_emission.glsl"

// Starts a camera path through the continuous pixel position `pixelPos` of pixel `pixel`,
// with the random numbers of `rng` and the sampler's decisions of `lds`.
PathState ptBeginAt(uint pixel, vec2 pixelPos, Rng rng, LdSample lds) {
    PathState s;
    s.pixel = pixel;
    s.origin = scene.camPosition;
    s.dir = cameraRay(pixelPos);
    s.prevPdf = 0.0;
    s.beta = vec3(1.0);
    s.flags = kPathFlagAlive | kPathFlagPrevSpecular;
    s.radiance = vec3(0.0);
    s.rng = rng.state;
    s.prevP = s.origin;
    s.depth = 0u;
    s.rays = 0u;
    s.ldSeed = lds.seed;
    s.sampleIndex = lds.index;
    return s;
}

// Starts the path of sample `sampleIndex` of pixel (x, y): box filter, so the sample
// position is uniform over the pixel square.
PathState ptBegin(uint x, uint y, uint sampleIndex, uint seed) {
    uint pixel = y * scene.width + x;
    LdSample lds = ldSampleInit(pixel, sampleIndex, seed);
    return ptBeginAt(pixel, vec2(x, y) + ldGet2(lds, kLdDimPixel), rngInit(pixel, sampleIndex, seed), lds);
}

// Consumes the closest hit of the current segment; updates the state to the next segment
// or clears kPathFlagAlive.
void ptProcessHit(inout PathState s, Hit hit) {
    Rng rng;
    rng.state = s.rng;
    LdSample lds;
    lds.seed = s.ldSeed;
    lds.index = s.sampleIndex;
    s.rays++;
    s.flags &= ~kPathFlagAlive;  // set again below if the path continues
    // Emission seen by the camera ray itself: left to emitter supersampling in
    // the pixels it covers (visible_emission.glsl).
    bool countEmission = s.depth > 0u || !emissionSupersampled(s.pixel);
    if (hit.triangle == kInvalidIndex) {
        if (kHasEnv && countEmission) s.radiance += s.beta * scene.envRadiance;
        return;
    }
    vec3 d = s.dir;
    SurfaceHit sh = makeSurfaceHit(hit.triangle, hit.u, hit.v, d);
    vec3 Le = surfaceEmission(sh);
    if (kHasLightTris && countEmission && maxComponent(Le) > 0.0)
        s.radiance +=
            s.beta * Le *
            ptEmissionWeight((s.flags & kPathFlagPrevSpecular) != 0u, s.prevPdf, s.prevP, sh.triangle, sh.p);
    Material mat = material(sh.material);
    // One-sided materials: the back face is an opaque black absorber.
    if (!sh.frontFace && (mat.flags & kMatFlagDoubleSided) == 0u) return;
    if (s.depth >= scene.maxDepth || s.depth + 1u >= kMaxDepth) return;  // no further segment

    BsdfParams bsdf = materialBsdf(sh.material, sh.uv);
    vec3 t, b;
    makeBasis(sh.ns, t, b);
    vec3 woLocal = toLocal(-d, t, b, sh.ns);
    vec3 origin = offsetRayOriginScaled(sh.p, sh.ng, scene.sceneRadius);

    // Next-event estimation (its numbers are this bounce's decision of the sampler,
    // sampler.glsl, used or not).
    vec3 ul = ldLight(lds, s.depth);
    if (!bsdfIsDeltaOnly(bsdf)) {
        LightSample ls;
        if (sampleLight(sh.p, ul, ls) && dot(ls.wi, sh.ng) > 0.0)
            ptAddNee(ls, bsdf, woLocal, toLocal(ls.wi, t, b, sh.ns), origin, s.beta, s.radiance, s.rays);
    }

    // BSDF sampling continues the path.
    BsdfSample bs;
    bool sampled = bsdfSample(bsdf, woLocal, ldBsdf(lds, s.depth), bs);
    vec3 wi = sampled ? toWorld(bs.wi, t, b, sh.ns) : vec3(0.0);
    // A sample below the geometric surface (shading-normal leak) ends the path.
    if (sampled && dot(wi, sh.ng) > 0.0) {
        s.beta *= bs.weight;
        s.prevPdf = bs.pdf;
        s.flags = (s.flags & ~kPathFlagPrevSpecular) | (bs.lobe == kLobeSpecular ? kPathFlagPrevSpecular : 0u);
        s.prevP = sh.p;
        s.origin = origin;
        s.dir = wi;
        float q;
        if (ptRoulette(s.depth, s.beta, rng, q)) s.flags |= kPathFlagAlive;
        s.depth++;
    }
    s.rng = rng.state;
}

// Traces the path to its end (s.radiance, s.rays). The test comes after the body (do-while):
// lavapipe before Mesa 23 runs a loop's body under an empty lane mask rather than skip it, so
// a loop that its last lane leaves at the head costs one more bounce (PT 1-4 % per sample,
// bench/RESULTS.md).
void ptTrace(inout PathState s) {
    if ((s.flags & kPathFlagAlive) != 0u) {
        do {
            Hit hit = traceClosest(s.origin, s.dir, 0.0, 1.0 / 0.0);
            ptProcessHit(s, hit);
        } while ((s.flags & kPathFlagAlive) != 0u);
    }
}

#endif  // GDPT_LIB_PT_CORE
