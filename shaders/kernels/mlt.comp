// mlt.comp — primary-sample-space Metropolis light transport (Kelemen et al. 2002) over
// gdpt's G-PT sample, in four phases (MltParams::phase; the host drives them,
// src/render/passes/mlt_pass.h):
//   bootstrap  invocation i draws a fresh state (uniform decisions), evaluates it and writes
//              its target value: the host estimates b = ∫ T and picks the chains' starting
//              states in proportion to T;
//   start      chain c takes bootstrap sample starts[c]'s state (drawn again from the same
//              numbers) as its current state;
//   mutate     chain c proposes a small or a large step (mlt.glsl), evaluates it, writes two
//              records (the current state with Metropolis share 1 − a, the proposal with a;
//              mlt.glsl's splat weights) and accepts with probability a; one step per
//              dispatch (llvmpipe's loop limit, see samplesPerDispatch in pt_pass.h), the
//              records of a batch in step order;
//   direct     one invocation per pixel: the emission the camera sees directly, by
//              stratified camera samples (G-PT's "very direct" light, which is neither in the
//              chains' target nor reconstructed).
// A state is the vector of a sample's first kMltPssDims decisions (mlt_shared.h): the film
// position over the whole image, then the light and BSDF samples of the first bounces;
// sampler.glsl reads them through pssLookup instead of its Sobol' points. G-MLT (kBaseOnly
// false) evaluates gpt.comp's sample (gpt_trace.glsl): the base path and its four offsets,
// with Lehtinen et al. 2013's gradient target (gmltTarget); PSSMLT (kBaseOnly true) traces
// the path tracer's path (pt_core.glsl) and its target is its luminance.
// No float atomics: every invocation writes only its own chain, records and pixel; the
// integer counters are order-independent sums. Deterministic per seed and device.
#version 460
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "mlt_shared.h"
#include "lib/common.glsl"
#include "lib/rng.glsl"

layout(constant_id = kSpecMltBaseOnly) const bool kBaseOnly = false;

// The chain's decisions being evaluated (gPssActive), read by sampler.glsl.
float gPss[kMltPssDims];
bool gPssActive = false;

// Slot of component `component` of decision `dim` (sampler.glsl's ids: 0 the film position,
// then per bounce +1 light choice, +2 light point, +3 BSDF lobe, +4 BSDF direction; the
// state's layout: mlt_shared.h kMltPssDims).
bool pssLookup(uint dim, uint component, out float value) {
    value = 0.0;
    if (!gPssActive) return false;
    uint slot = component;
    if (dim > 0u) {
        uint bounce = (dim - 1u) / 4u;  // sampler.glsl kLdBounceStride
        uint which = (dim - 1u) % 4u;
        uint start = which == 0u ? 0u : (which == 1u ? 1u : (which == 2u ? 3u : 4u));
        slot = 2u + kMltPssPerBounce * bounce + start + component;
    }
    if (slot >= kMltPssDims) return false;
    value = gPss[slot];
    return true;
}

// The Russian roulette number of bounce `depth` (sampler.glsl ldRoulette).
bool pssRouletteLookup(uint depth, out float value) {
    value = 0.0;
    uint slot = 2u + kMltPssPerBounce * depth + 6u;
    if (!gPssActive || slot >= kMltPssDims) return false;
    value = gPss[slot];
    return true;
}
#define GDPT_PSS_SAMPLER
#include "lib/sampler.glsl"
#include "lib/ray.glsl"
#include "lib/mlt.glsl"

layout(local_size_x_id = kSpecWorkgroupX, local_size_y_id = kSpecWorkgroupY) in;

#include "lib/scene_buffers.glsl"
layout(set = 0, binding = kBindCounters, scalar) buffer CounterBuf { Counters counters; };
layout(set = 0, binding = kBindMltChains, scalar) buffer ChainBuf { MltChain chains[]; };
layout(set = 0, binding = kBindMltPss, scalar) buffer PssBuf { float pss[]; };
layout(set = 0, binding = kBindMltRecords, scalar) writeonly buffer RecordBuf { MltRecord records[]; };
layout(set = 0, binding = kBindMltBootstrap, scalar) writeonly buffer BootstrapBuf { MltBootstrapSample bootstrap[]; };
layout(set = 0, binding = kBindMltStarts, scalar) readonly buffer StartBuf { uint starts[]; };
layout(set = 0, binding = kBindMltDirect, scalar) writeonly buffer DirectBuf { vec4 directOut[]; };
layout(set = 0, binding = kBindMltNormalise, scalar) readonly buffer NormaliseBuf { float normaliser[]; };
layout(push_constant, scalar) uniform Push { MltParams frame; };

#include "lib/scene_access.glsl"
#define GDPT_ANYHIT_FILTER(tri, u, v) alphaPasses(tri, u, v)
#include "lib/bvh_coherent.glsl"
#include "lib/shift.glsl"
#include "lib/gpt_light.glsl"

const ivec2 kOffsetDelta[kGptNumOffsets] =
    ivec2[kGptNumOffsets](ivec2(1, 0), ivec2(0, 1), ivec2(-1, 0), ivec2(0, -1));

#include "lib/camera.glsl"
#include "lib/gpt_path.glsl"
#include "lib/surface_rules.glsl"
#include "lib/gpt_steps.glsl"

// No first-hit demodulation in the chains (gpt.comp's kDemodulate).
const bool kDemodulate = false;
vec3 firstHitModulation(SurfaceHit h, uint pixel) { return vec3(1.0); }

#include "lib/gpt_trace.glsl"

// PSSMLT traces the path tracer's path (pt_core.glsl), not G-PT's base path: the same
// estimator for one path, without the offsets' code, which lavapipe 22.3 would run under
// lane masks at every bounce. The emission the camera sees directly is the direct phase's:
// pt_core's "estimated elsewhere" hook says so for every pixel.
#define GDPT_LIB_VISIBLE_EMISSION
bool emissionSupersampled(uint pixel) { return true; }
#include "lib/pt_core.glsl"

// Stream tags: the numbers of one sample index in one phase never repeat another's.
const uint kTagState = 0x53544154u;     // a fresh state's decisions
const uint kTagMutation = 0x4d555441u;  // a mutation's choices (large or small, sizes, accept)
const uint kTagDirect = 0x44495245u;    // the direct phase's camera samples

// One evaluated state: where its film position lies and what it carries.
struct Evaluated {
    vec2 film;
    uint pixel;
    float target;
    vec3 value[kMltValues];
};

// Evaluates the state in gPss. `stream` and `fresh` give the decisions the state does not
// hold (deeper bounces, Russian roulette): drawn afresh for every evaluation.
Evaluated evaluate(uint stream, uint fresh, inout uint rays, inout uint nan) {
    Evaluated e;
    e.film = vec2(gPss[0] * float(frame.width), gPss[1] * float(frame.height));
    uint px = min(uint(e.film.x), frame.width - 1u);
    uint py = min(uint(e.film.y), frame.height - 1u);
    e.pixel = py * frame.width + px;
    Rng rng = rngInit(stream, fresh, frame.seed);
    LdSample lds = ldSampleInit(stream, fresh, frame.seed ^ kTagState);
    vec3 central = vec3(0.0), neighborSum = vec3(0.0);
    float gradientAbs = 0.0;
    bool finite = true;
    [[unroll]] for (uint k = 0u; k < kMltValues; ++k) e.value[k] = vec3(0.0);
    gPssActive = true;
    if (kBaseOnly) {
        PathState path = ptBeginAt(e.pixel, e.film, rng, lds);
        ptTrace(path);
        rays += path.rays;
        central = path.radiance;
        finite = isFinite(central);
    } else {
        OffsetPath offs[kGptNumOffsets];
        vec3 direct, baseModulation;
        // Every film position is one chain's: no pixel counts differ, the pairs weigh both ends
        // alike.
        traceSample(lds, rng, e.film, px, py, false, vec4(1.0), rays, direct, baseModulation, offs);
        [[unroll]] for (uint i = 0u; i < kGptNumOffsets; ++i) {
            central += offs[i].baseSum;
            neighborSum += offs[i].offSum;
            e.value[kMltNeighbor + i] = offs[i].offSum;
            e.value[kMltGradient + i] = offs[i].offSum - offs[i].baseSum;
            gradientAbs += luminance(abs(offs[i].offSum - offs[i].baseSum));
            finite = finite && isFinite(offs[i].baseSum) && isFinite(offs[i].offSum);
        }
    }
    gPssActive = false;
    e.value[kMltCentral] = central;
    e.target = mltTemperedTarget(
        kBaseOnly ? luminance(central) : gmltTarget(gradientAbs, central, neighborSum, frame.targetAlpha),
        frame.targetExponent);
    if (frame.normaliseBlock > 0u && frame.phase != kMltPhaseBootstrap)
        e.target /= normaliser[mltBlockIndex(px, py, frame.normaliseBlock, frame.normaliseColumns)];
    // pixel_stats.glsl's policy: a non-finite sample counts as zero, in every quantity.
    if (!finite || !isFinite(e.target)) {
        nan++;
        e.target = 0.0;
        [[unroll]] for (uint k = 0u; k < kMltValues; ++k) e.value[k] = vec3(0.0);
    }
    return e;
}

// The decisions of a fresh state for sample index s (bootstrap sample s, drawn again by the
// chain that starts from it).
void freshState(uint s) {
    Rng r = rngInit(s, kTagState, frame.seed);
    for (uint k = 0u; k < kMltPssDims; ++k) gPss[k] = rngNext(r);
}

void storeChain(uint c, Evaluated e) {
    chains[c].film = e.film;
    chains[c].pixel = e.pixel;
    chains[c].target = e.target;
    [[unroll]] for (uint k = 0u; k < kMltValues; ++k) chains[c].value[k] = e.value[k];
    for (uint k = 0u; k < kMltPssDims; ++k) pss[c * kMltPssDims + k] = gPss[k];
}

void writeRecord(uint at, uint pixel, float weight, float largeTarget, vec3 value[kMltValues]) {
    records[at].pixel = pixel;
    records[at].weight = weight;
    records[at].largeTarget = largeTarget;
    // A large step's proposal is splatted by the host even with no Metropolis share.
    bool splatted = weight > 0.0 || largeTarget > 0.0;
    [[unroll]] for (uint k = 0u; k < kMltValues; ++k) records[at].value[k] = splatted ? value[k] : vec3(0.0);
}

// Draws chain c's proposal into gPss: a large step (fresh decisions) or a small step of
// every decision, from the chain's stream of mutation choices `m`.
bool propose(uint c, inout Rng m) {
    bool large = rngNext(m) < frame.largeStep;
    for (uint k = 0u; k < kMltPssDims; ++k) {
        float u = pss[c * kMltPssDims + k];
        float a = rngNext(m);
        float b = rngNext(m);
        gPss[k] = large ? a : mltSmallStep(u, a, b);
    }
    return large;
}

// Chain c has evaluated its proposal e: two records, then accept with probability a.
void finishMutation(uint c, Evaluated e, bool large, inout Rng m) {
    MltChain cur = chains[c];
    float a = mltAcceptance(cur.target, e.target);
    uint at = frame.recordOffset + 2u * c;
    float bLarge = frame.misNormalisation * frame.largeStep;
    writeRecord(at, cur.pixel, mltSplatWeight(1.0 - a, cur.target, bLarge), -1.0, cur.value);
    writeRecord(at + 1u, e.pixel, mltSplatWeight(a, e.target, bLarge), large ? e.target : -1.0, e.value);
    bool accept = rngNext(m) < a;
    if (large) {
        chains[c].proposedLarge++;
        if (accept) chains[c].acceptedLarge++;
    } else {
        chains[c].proposedSmall++;
        if (accept) chains[c].acceptedSmall++;
    }
    if (accept) storeChain(c, e);
}

// The emission seen directly through pixel (x, y), averaged over directSamples stratified
// camera samples (gpt.comp's `direct`).
vec3 directEmission(uint x, uint y) {
    uint pixel = y * frame.width + x;
    vec3 sum = vec3(0.0);
    for (uint s = 0u; s < frame.directSamples; ++s) {
        LdSample lds = ldSampleInit(pixel, s, frame.seed ^ kTagDirect);
        vec3 d = cameraRay(vec2(x, y) + ldGet2(lds, kLdDimPixel));
        Hit hit = traceClosest(scene.camPosition, d, 0.0, kInf);
        if (hit.triangle == kInvalidIndex) {
            if (kHasEnv) sum += scene.envRadiance;
        } else if (kHasLightTris) {
            sum += surfaceEmission(makeSurfaceHit(hit.triangle, hit.u, hit.v, d));
        }
    }
    return sum / float(max(frame.directSamples, 1u));
}

void main() {
    loadScene();
    uint item = gl_GlobalInvocationID.y * (gl_NumWorkGroups.x * gl_WorkGroupSize.x) + gl_GlobalInvocationID.x;
    uint rays = 0u, nan = 0u, paths = 0u;
    if (frame.phase == kMltPhaseDirect) {
        uint x = gl_GlobalInvocationID.x;
        uint y = gl_GlobalInvocationID.y + frame.rowOffset;
        if (x >= frame.width || y >= frame.height || gl_GlobalInvocationID.y >= frame.count) return;
        vec3 e = directEmission(x, y);
        directOut[y * frame.width + x] = vec4(isFinite(e) ? e : vec3(0.0), 0.0);
        rays = frame.directSamples;
    } else {
        if (item >= frame.count) return;
        paths = 1u;
        // One call of evaluate (the whole G-PT sample) for every phase: the kernel holds one
        // copy of the path code, which lavapipe compiles in a third of the time of three.
        uint stream = 0u, fresh = 0u;
        bool large = false;
        Rng m = rngInit(item, frame.index, frame.seed ^ kTagMutation);
        if (frame.phase == kMltPhaseBootstrap) {
            stream = frame.index + item;
            freshState(stream);
        } else if (frame.phase == kMltPhaseStart) {
            stream = starts[item];
            freshState(stream);
        } else {
            large = propose(item, m);
            // Decisions beyond the state: a stream per chain and step (the chain index is
            // moved past every bootstrap sample's by the tag).
            stream = item ^ kTagMutation;
            fresh = frame.index;
        }
        Evaluated e = evaluate(stream, fresh, rays, nan);
        if (frame.phase == kMltPhaseBootstrap) {
            bootstrap[item].target = e.target;
            bootstrap[item].pixel = e.pixel;
        } else if (frame.phase == kMltPhaseStart) {
            storeChain(item, e);
            chains[item].proposedSmall = 0u;
            chains[item].acceptedSmall = 0u;
            chains[item].proposedLarge = 0u;
            chains[item].acceptedLarge = 0u;
        } else {
            finishMutation(item, e, large, m);
        }
    }
    atomicAdd(counters.raysTraced, rays);
    atomicAdd(counters.pathsCompleted, paths);
    if (nan > 0u) atomicAdd(counters.nanSamples, nan);
}
