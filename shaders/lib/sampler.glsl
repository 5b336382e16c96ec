// sampler.glsl — the sample values of the path tracers' decisions (pixel position, light
// sample, BSDF sample of every bounce): Owen-scrambled Sobol' points, one independently
// shuffled and scrambled 2-D (or 1-D) pattern per decision ("padding"), shared by the
// kernels and the CPU tests. Russian roulette draws from the path's Rng (ldRoulette).
//
// Why: with independent random numbers the error of an N-sample pixel estimate falls as
// N^-1/2 whatever the integrand; scrambled (0,m,2)-nets keep every estimate unbiased and
// converge faster where the integrand is smooth in the decision (the pixel footprint, the
// point on an area light, the first bounce's direction), which is much of a diffuse scene's
// noise at a few dozen samples per pixel (Owen 1997; Burley 2020). G-PT's offset paths
// reuse the base path's values through the shift, so both get the same points.
//
// Construction (Burley 2020, "Practical Hash-based Owen Scrambling", JCGT 9(4)), from the
// primitives of sobol.glsl: per pixel and decision, the sample index is shuffled by a
// nested uniform scramble of its digits, then the first two Sobol' dimensions of the
// shuffled index are scrambled with seeds of their own. A shuffle of digits maps the first
// 2^m indices onto one aligned block of 2^m, so every power-of-two prefix of a pixel's
// samples is a scrambled (0,m,2)-net in every decision; other counts stay unbiased.
// Pixels use unrelated seeds (pcg hashes of pixel and render seed), so they are mutually
// independent; a pixel's samples are not, which makes the Welford variance over them an
// overestimate of the variance of their mean (the safe side for the statistical tests and
// the inverse-variance weights).
//
// Decision ids: 0 = pixel position; bounce k uses kLdBounceStride ids from 1 + k·stride:
// +0 light choice (1-D), +1 light point (2-D), +2 BSDF lobe choice (1-D), +3 BSDF direction.
#ifndef GDPT_LIB_SAMPLER
#define GDPT_LIB_SAMPLER

#include "common.glsl"
#include "rng.glsl"
#include "sobol.glsl"

GDPT_NAMESPACE_BEGIN

GDPT_CONST uint kLdDimPixel = 0u;
GDPT_CONST uint kLdBounceStride = 4u;
GDPT_CONST uint kLdLightChoice = 1u;
GDPT_CONST uint kLdLightPoint = 2u;
GDPT_CONST uint kLdBsdfChoice = 3u;
GDPT_CONST uint kLdBsdfDirection = 4u;

// One camera sample's handle: the pixel's scramble seed and the sample's index in the pixel.
struct LdSample {
    uint seed;
    uint index;
};

GDPT_INLINE LdSample ldSampleInit(uint pixelIndex, uint sampleIndex, uint seed) {
    LdSample s;
    // Not rngInit's chain (the odd constant keeps the two hashes of one pixel unrelated).
    s.seed = pcgHash(pixelIndex + pcgHash(seed ^ 0x9E3779B9u));
    s.index = sampleIndex;
    return s;
}

GDPT_INLINE float ldToFloat(uint x) {
    return float(x >> 8u) * (1.0f / 16777216.0f);  // top 24 bits: exact, never 1
}

GDPT_INLINE uint ldDimSeed(LdSample s, uint dim) {
    return pcgHash(s.seed + pcgHash(dim));
}

// The sample's shuffled index for decision `dim`: the same nested scramble as a fraction's,
// read from the most significant bit, so indices that share their high bits (an aligned
// block) stay in one aligned block.
GDPT_INLINE uint ldShuffledIndex(LdSample s, uint h) {
    return owenScramble(s.index, h);
}

// Primary-sample-space Metropolis (mlt.comp) defines GDPT_PSS_SAMPLER and, before including
// this file, `bool pssLookup(uint dim, uint component, out float value)`: the decisions its
// chain state holds are read from there, the others drawn as below.
GDPT_INLINE float ldGet1(LdSample s, uint dim) {
#ifdef GDPT_PSS_SAMPLER
    float held;
    if (pssLookup(dim, 0u, held)) return held;
#endif
    uint h = ldDimSeed(s, dim);
    uint i = ldShuffledIndex(s, h);
    return ldToFloat(owenScramble(sobolReverseBits(i), pcgHash(h + 1u)));
}

GDPT_INLINE vec2 ldGet2(LdSample s, uint dim) {
#ifdef GDPT_PSS_SAMPLER
    float a, b;
    if (pssLookup(dim, 0u, a) && pssLookup(dim, 1u, b)) return vec2(a, b);
#endif
    uint h = ldDimSeed(s, dim);
    uint i = ldShuffledIndex(s, h);
    return vec2(ldToFloat(owenScramble(sobolReverseBits(i), pcgHash(h + 1u))),
                ldToFloat(owenScramble(sobolDim1(i), pcgHash(h + 2u))));
}

// The number Russian roulette compares with its survival probability after the BSDF sample
// of bounce `depth`: the path's Rng, except in primary-sample-space Metropolis, whose chain
// state holds it (mlt.comp's `pssRouletteLookup(uint depth, out float value)`), so that a
// state's value is a function of the state (a chain whose target were redrawn at every
// evaluation would stick to the states a lucky survival made bright).
#ifdef GDPT_PSS_SAMPLER
GDPT_INLINE float ldRoulette(uint depth, GDPT_INOUT(Rng) rng) {
    float held;
    if (pssRouletteLookup(depth, held)) return held;
    return rngNext(rng);
}
#else
#define ldRoulette(depth, rng) rngNext(rng)
#endif

// The three numbers of a light sample (choice, then the point) at bounce `depth`.
GDPT_INLINE vec3 ldLight(LdSample s, uint depth) {
    uint base = depth * kLdBounceStride;
    vec2 p = ldGet2(s, base + kLdLightPoint);
    return vec3(ldGet1(s, base + kLdLightChoice), p.x, p.y);
}

// The three numbers of a BSDF sample (lobe choice, then the direction) at bounce `depth`.
GDPT_INLINE vec3 ldBsdf(LdSample s, uint depth) {
    uint base = depth * kLdBounceStride;
    vec2 p = ldGet2(s, base + kLdBsdfDirection);
    return vec3(ldGet1(s, base + kLdBsdfChoice), p.x, p.y);
}

GDPT_NAMESPACE_END

#endif  // GDPT_LIB_SAMPLER
