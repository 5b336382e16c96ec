// mlt_shared.h — host/shader interface of primary-sample-space Metropolis light transport
// (mlt.comp; Kelemen, Szirmay-Kalos, Antal, Csonka 2002) and its gradient-domain form
// (Lehtinen, Karras, Laine, Aittala, Durand, Aila 2013). Same rules as gdpt_shared.h, which
// it extends (C++17 and GLSL 460, layout(scalar), no bool, append-only structs), with the
// bindings above gpt_shared.h's, which it also includes (mlt.comp traces G-PT's sample).
#ifndef GDPT_MLT_SHARED_H
#define GDPT_MLT_SHARED_H

#include "gpt_shared.h"

#ifdef __cplusplus
namespace gdpt::gpu {
#endif

// Decisions a chain's state holds: the film position (2 numbers), then 7 per bounce (light
// choice, light point (2), BSDF lobe choice, BSDF direction (2), Russian roulette;
// sampler.glsl's decisions in that order) for the first kMltPssBounces bounces. Deeper
// decisions are drawn afresh at every proposal: an independence proposal in those
// coordinates, symmetric, so the chain stays a valid Metropolis-Hastings chain on the
// extended space.
GDPT_CONST uint kMltPssBounces = 8u;
GDPT_CONST uint kMltPssPerBounce = 7u;
GDPT_CONST uint kMltPssDims = 2u + kMltPssPerBounce * kMltPssBounces;

// Quantities a sample carries (G-PT's per-camera-sample estimator, gpt.comp): central, the
// four offsets' MIS-weighted radiance (neighbor_i) and the four gradients (gradient_i), in
// kGptRight.. order. PSSMLT traces the base path alone: central is then the path tracer's
// sample and the others are zero.
GDPT_CONST uint kMltValues = 9u;
GDPT_CONST uint kMltCentral = 0u;
GDPT_CONST uint kMltNeighbor = 1u;
GDPT_CONST uint kMltGradient = 5u;

// What one invocation of mlt.comp does (MltParams::phase).
GDPT_CONST uint kMltPhaseBootstrap = 0u;  // sample i: a fresh state, its target -> kBindMltBootstrap
GDPT_CONST uint kMltPhaseStart = 1u;      // chain c: the state of bootstrap sample starts[c]
GDPT_CONST uint kMltPhaseMutate = 2u;     // chain c: one proposal, two records, accept or not
GDPT_CONST uint kMltPhaseDirect = 3u;     // pixel: the emission the camera sees directly

// Push constants of mlt.comp (<= 128 bytes). 64 bytes.
struct MltParams {
    uint phase;              // kMltPhase*
    uint count;              // invocations that work (samples, chains or image rows x width)
    uint seed;               // user seed
    uint index;              // bootstrap: first sample index; mutate: the mutation step's index
    uint recordOffset;       // mutate: first record this dispatch writes (2 per chain)
    uint width;              // image width in pixels
    uint height;             // image height in pixels
    float shiftThreshold;    // as GptFrameParams::shiftThreshold (gpt_path.glsl reads frame.shiftThreshold)
    float largeStep;         // probability of a large step (a fresh state) per mutation
    float targetAlpha;       // G-MLT: weight of the primal term of the target (mlt.glsl)
    uint directSamples;      // direct: camera samples per pixel
    uint rowOffset;          // direct: first image row of this dispatch
    float misNormalisation;  // mutate: b' of the splat weights' multiple importance sampling (mlt.glsl)
    float targetExponent;    // the chains' target is the method's raised to this power (mltTemperedTarget)
    uint normaliseBlock;     // start, mutate: the target is divided by its image block's entry of
                             // kBindMltNormalise, blocks of this many pixels square; 0: not
    uint normaliseColumns;   // blocks per image row
};

// A bootstrap sample (kBindMltBootstrap): its target, not divided by its block's normaliser,
// and the pixel its film position lies in. 8 bytes.
struct MltBootstrapSample {
    float target;
    uint pixel;
};

// A chain's current state besides its decisions (kBindMltPss). 144 bytes.
struct MltChain {
    vec2 film;               // film position of the current sample, pixels
    float target;            // its target value (> 0: chains start where the target is)
    uint pixel;              // y·width + x of the film position
    vec3 value[kMltValues];  // its quantities
    uint proposedSmall;      // small steps proposed so far
    uint acceptedSmall;      // of which accepted
    uint proposedLarge;      // large steps proposed so far
    uint acceptedLarge;      // of which accepted
    uint pad;
};

// One splat: `weight` times `value` goes to pixel `pixel`: the Metropolis share of the
// state's contribution (mlt.glsl mltSplatWeight: the current state with acceptance share
// 1 − a, the proposal with a). The host sums them in record order. A large step's proposal
// is a fresh uniform state, so it is also an independent sample of the image (the host adds
// its share of the multiple importance sampling, mltLargeStepWeight) and its target is one
// more sample of b = ∫ T (Kelemen et al. 2002, §4): the host pools them with the
// bootstrap's. 120 bytes.
struct MltRecord {
    uint pixel;
    float weight;       // 0: nothing to splat
    float largeTarget;  // the proposal of a large step: its target (≥ 0); otherwise −1
    vec3 value[kMltValues];
};

// Descriptor bindings of mlt.comp (set 0), above gpt_shared.h's.
GDPT_ENUM_BEGIN(MltBinding)
kBindMltChains = 60u,         // MltChain per chain
    kBindMltPss = 61u,        // float per chain and decision: chain c's decision k at c·kMltPssDims + k
    kBindMltRecords = 62u,    // MltRecord, 2 per chain and mutation step of a batch
    kBindMltBootstrap = 63u,  // MltBootstrapSample per bootstrap sample
    kBindMltStarts = 64u,     // uint per chain: the bootstrap sample it starts from
    kBindMltDirect = 65u,     // vec4 per pixel: mean very-direct emission (rgb)
    kBindMltNormalise = 66u   // float per image block (MltParams::normaliseBlock): the target's divisor
    GDPT_ENUM_END();

GDPT_ENUM_BEGIN(MltSpecId)
kSpecMltBaseOnly = 20u  // 1: trace the base path alone (PSSMLT), 0: base + offsets (G-MLT)
    GDPT_ENUM_END();

#ifdef __cplusplus
static_assert(sizeof(MltParams) == 64, "MltParams layout");
static_assert(sizeof(MltBootstrapSample) == 8, "MltBootstrapSample layout");
static_assert(sizeof(MltChain) == 144, "MltChain layout (scalar)");
static_assert(sizeof(MltRecord) == 120, "MltRecord layout (scalar)");
static_assert(std::uint32_t{kBindMltChains} > std::uint32_t{kBindGptEdgeProbe},
              "MLT bindings must not collide with gpt_shared.h's");
}  // namespace gdpt::gpu
#endif
#endif  // GDPT_MLT_SHARED_H
