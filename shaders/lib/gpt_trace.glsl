// gpt_trace.glsl — one camera sample of gradient-domain path tracing: the base path and its
// four offset paths through the shift mapping (Kettunen et al. 2015, §4), the estimator of
// gpt.comp (see there), shared with mlt.comp, whose Markov chains evaluate the same sample at a
// film position of their own. GLSL only: the including kernel has declared the scene buffers,
// `frame` (with shiftThreshold), kOffsetDelta, kDemodulate and firstHitModulation, and
// included bvh_coherent.glsl, gpt_path.glsl, gpt_light.glsl, shift.glsl, surface_rules.glsl and
// gpt_steps.glsl.
#ifndef GDPT_LIB_GPT_TRACE
#define GDPT_LIB_GPT_TRACE

// Split bounce loop (GDPT_GPT_SPLIT_BOUNCE: a second build of this kernel, gpt_split; the
// host picks one per device, splitBounceDefault in gpt_pass.cpp). Once every live offset
// shares the base's vertices (in a scene without glossy vertices: every bounce after the
// first), the remaining bounces run in a second loop compiled without the code for offsets
// with vertices of their own. Lavapipe with Mesa 22.3 runs every branch under lane masks,
// also one that no lane takes, so that code costs its time at every bounce there: the split
// loop is 15-25 % faster on it, neutral on Mesa 25 (which skips such branches), and its
// pipeline takes about 0.37 s longer to create. A second build rather than a specialisation
// constant, because lavapipe spends that time on the dead loop too. The image is the same
// bit for bit either way (bench/RESULTS.md).

// Occlusion beams (GDPT_GPT_BEAMS; bvh_coherent.glsl, traceAnyBeam): the offsets' own shadow
// rays, and without glossy vertices their reconnections' visibility rays, traced as one beam
// per bounce instead of one ray each, in the build for lavapipe before Mesa 23 (the split
// build) in node steps, which it takes on trees of up to 2^17 triangles (SceneSpec::
// bvhUnitSteps with bundles; bench/RESULTS.md, "Node steps for G-PT's bundles up to 2^17
// triangles"). Measured (bench/RESULTS.md, "Occlusion beams
// for the offsets' rays"): 11-18 % less time per G-PT sample there on the scene set (4 % on the
// glossy box, whose shift rays are bundles instead, below), for about 0.1 s more pipeline creation; in
// unit steps (trees of 10^5 triangles) level or slower, and on Mesa 25, which skips the
// branches no lane takes, slower on the Cornell box and a 200k-triangle terrain. The same
// images either way. The same build traces the base's and the offsets' primary rays as one
// closest-hit fan (fanFrom, traceClosestBundle): 18-29 % less time per sample on the scene set
// (the glossy box 3 %; "A primary fan for the camera rays"), the same hits up to exact ties (two
// triangles at the same t); in unit steps 12 % faster on a 110k-triangle asset but 3-13 % slower
// on a 200k-triangle terrain, so not there either. With glossy vertices it traces the offsets'
// own-vertex shift rays (reconnections and half-vector copies) as ray bundles
// (traceClosestFour, gpt_bounce.glsl): 15 % less time per sample on the glossy box, for about
// 0.2 s more pipeline creation ("Ray bundles for the glossy offsets' shifts").
#if defined(GDPT_GPT_SPLIT_BOUNCE) && !defined(GDPT_BVH_UNIT_STEPS)
#define GDPT_GPT_BEAMS
#endif

// The loops over the four offsets are unrolled before the driver ([[unroll]], which the build's
// spirv-opt pass list carries out, cmake/GdptSpirvEmbed.cmake): lavapipe 22.3 unrolls them
// itself, one nesting level per round of its optimisation loop, and each round walks the whole
// kernel (17 rounds on the Cornell box's G-PT kernel, 7 once unrolled before; bench/RESULTS.md,
// "Offset loops unrolled before the driver"). A loop that traces rays (an offset's primary,
// shadow or shift ray, in the builds without beams) holds a traversal loop, and NIR leaves a
// loop around another loop rolled; so that it keeps that form, it carries the mark only in
// the builds where it traces nothing (GDPT_UNROLL_UNLESS_TRACING). The marked loops have no
// `continue`: spirv-opt unrolls single-exit loops only (tests/gpu/vk/test_spirv_unroll.cpp).
#ifdef GDPT_GPT_BEAMS
#define GDPT_UNROLL_UNLESS_TRACING [[unroll]]
#else
#define GDPT_UNROLL_UNLESS_TRACING
#endif

// Offset i has a vertex of its own (NOT_CONNECTED); never in the fast form (general false).
bool ownVertex(OffsetPath o, bool general) { return general && o.state == kShiftNotConnected; }

// Some live offset has a vertex of its own.
bool anyOwnVertex(OffsetPath offs[kGptNumOffsets]) {
    bool own = false;
    [[unroll]] for (uint i = 0u; i < kGptNumOffsets; ++i) own = own || (offs[i].alive && ownVertex(offs[i], true));
    return own;
}

// Base + 4 offsets for one camera sample at pixelPos (continuous pixel coordinates).
// countDirect false: the emission seen by the camera ray is left to emitter-silhouette
// supersampling (visible_emission.glsl) and `direct` stays zero.
// countRatio[i]: n_q / n_p, the sample counts of pair i's two pixels (OffsetPath::countRatio).
// baseModulation: the base's first-hit modulation (1 unless kDemodulate; offs[i].modulation
// the offsets').
void traceSample(LdSample lds, inout Rng rng, vec2 pixelPos, uint px, uint py, bool countDirect, vec4 countRatio,
                 inout uint rays, out vec3 direct, out vec3 baseModulation,
                 inout OffsetPath offs[kGptNumOffsets]) {
    direct = vec3(0.0);
    baseModulation = vec3(1.0);
    [[unroll]] for (uint i = 0u; i < kGptNumOffsets; ++i) {
        offs[i].modulation = vec3(1.0);
        offs[i].alive = gptPairExists(px, py, i);
        offs[i].shifted = false;
        offs[i].baseSum = vec3(0.0);
        offs[i].offSum = vec3(0.0);
        offs[i].beta = vec3(1.0);  // pinhole, box filter: camera weight 1 for every pixel
        offs[i].r = 1.0;           // image-plane translation: Jacobian 1, same pixel pdf
        offs[i].rLight = 1.0;
        offs[i].countRatio = countRatio[i];
        offs[i].state = kShiftNotConnected;
    }

    // Primary rays. Emission at the base's first hit is "very direct": direct buffer only.
    vec3 o = scene.camPosition;
    vec3 d = cameraRay(pixelPos);
#ifdef GDPT_GPT_BEAMS
    // The base's and the offsets' primary rays as one fan (bvh_coherent.glsl, traceClosestBundle).
    vec3 dOff[kGptNumOffsets];
    [[unroll]] for (uint i = 0u; i < kGptNumOffsets; ++i) dOff[i] = cameraRay(pixelPos + vec2(kOffsetDelta[i]));
    Hit hit;
    Hit hOff[kGptNumOffsets];
    traceClosestBundle(fanFrom(o, d, dOff[0], dOff[1], dOff[2], dOff[3],
                            bvec4(offs[0].alive, offs[1].alive, offs[2].alive, offs[3].alive)),
                    hit, hOff[0], hOff[1], hOff[2], hOff[3]);
#else
    Hit hit = traceClosest(o, d, 0.0, kInf);
#endif
    rays++;
    if (hit.triangle == kInvalidIndex) {
        if (kHasEnv && countDirect) direct += scene.envRadiance;
        return;  // nothing is shifted: the environment seen directly is very direct
    }
    SurfaceHit sh = makeSurfaceHit(hit.triangle, hit.u, hit.v, d);
    if (kHasLightTris && countDirect) direct += surfaceEmission(sh);
    if (kDemodulate) baseModulation = firstHitModulation(sh, py * scene.width + px);
    GDPT_UNROLL_UNLESS_TRACING for (uint i = 0u; i < kGptNumOffsets; ++i) {
        offs[i].shifted = offs[i].alive;
        if (offs[i].alive) {
#ifdef GDPT_GPT_BEAMS
            vec3 di = dOff[i];
            Hit hi = hOff[i];
#else
            vec3 di = cameraRay(pixelPos + vec2(kOffsetDelta[i]));
            Hit hi = traceClosest(o, di, 0.0, kInf);
#endif
            rays++;
            if (hi.triangle == kInvalidIndex) {
                offs[i].alive = false;  // base hit, offset missed: no shift
            } else {
                offs[i].hit = makeSurfaceHit(hi.triangle, hi.u, hi.v, di);
                offs[i].woWorld = -di;
                if (kDemodulate) {
                    // The offset is alive, so its pair exists and q is inside the image.
                    offs[i].modulation = firstHitModulation(offs[i].hit, gptPairPixel(px, py, i));
                }
            }
        }
    }

    vec3 beta = vec3(1.0);  // base f/p
    uint depth = 0u;
    bool pathEnded = false;
#ifdef GDPT_GPT_SPLIT_BOUNCE
    // General bounces while some live offset has a vertex of its own, then the fast form. The
    // test comes at the end of the general body: lavapipe before Mesa 23 runs a loop's body
    // under an empty lane mask rather than skip it, so a loop that every lane leaves at its
    // head still costs a whole general bounce (2-4 % of a sample, for about 25 ms more
    // pipeline creation; bench/RESULTS.md "Loop tests after the body"). The first bounce is
    // general for every lane, which is right whatever the offsets' states.
    if (depth < kMaxDepth && depth < scene.maxDepth) {
        do {
#define GDPT_GPT_GENERAL true
#include "lib/gpt_bounce.glsl"
#undef GDPT_GPT_GENERAL
            ++depth;
        } while (depth < kMaxDepth && depth < scene.maxDepth && anyOwnVertex(offs));
    }
    if (pathEnded) return;
    for (; depth < kMaxDepth && depth < scene.maxDepth; ++depth) {
#define GDPT_GPT_GENERAL false
#include "lib/gpt_bounce.glsl"
#undef GDPT_GPT_GENERAL
    }
#else
    for (; depth < kMaxDepth && depth < scene.maxDepth; ++depth) {
#define GDPT_GPT_GENERAL true
#include "lib/gpt_bounce.glsl"
#undef GDPT_GPT_GENERAL
    }
#endif
}

#endif  // GDPT_LIB_GPT_TRACE
