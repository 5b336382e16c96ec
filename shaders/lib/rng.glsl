// rng.glsl — counter-based random numbers shared by the kernels and the CPU tests.
//
// Each (pixel, sample, seed) triple gets an independent-looking stream whose whole state is
// one uint, so that gradient-domain offset paths can copy the base path's Rng by value and
// replay the same random numbers (Kettunen et al. 2015 shift mappings rely on this).
//
// Generator: the PCG-RXS-M-XS 32 permutation (O'Neill 2014) applied to a 32-bit LCG state,
// i.e. pcg32 "rxs m xs"; used as a stateless hash it is the `pcg` hash recommended by
// Jarzynski & Olano 2020, "Hash Functions for GPU Rendering" (JCGT 9(3)).
#ifndef GDPT_LIB_RNG
#define GDPT_LIB_RNG

#include "common.glsl"

GDPT_NAMESPACE_BEGIN

// Small value type on purpose: copyable, comparable, no hidden state.
struct Rng {
    uint state;  // LCG state; the next output is the RXS-M-XS permutation of the advanced state
};

// PCG LCG constants (O'Neill 2014, Table 4 multiplier for 32-bit state; odd increment).
GDPT_CONST uint kPcgMultiplier = 747796405u;
GDPT_CONST uint kPcgIncrement = 2891336453u;

// RXS-M-XS output permutation of a 32-bit state: a bijection on uint.
GDPT_INLINE uint pcgPermute(uint state) {
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// Jarzynski & Olano 2020, listing "pcg": one LCG step then the output permutation.
GDPT_INLINE uint pcgHash(uint v) {
    return pcgPermute(v * kPcgMultiplier + kPcgIncrement);
}

// Stream start for a pixel/sample/seed. Nested hashing (each coordinate added to the hash of
// the previous ones) decorrelates adjacent pixels and sample indices: a change of one in any
// input changes the start state by a full avalanche of the pcg hash, so neighbouring streams
// start at unrelated points of the 2^32-long LCG cycle.
GDPT_INLINE Rng rngInit(uint pixelIndex, uint sampleIndex, uint seed) {
    Rng r;
    r.state = pcgHash(pixelIndex + pcgHash(sampleIndex + pcgHash(seed)));
    return r;
}

// Next raw 32-bit output.
GDPT_INLINE uint rngNextUint(GDPT_INOUT(Rng) r) {
    r.state = r.state * kPcgMultiplier + kPcgIncrement;
    return pcgPermute(r.state);
}

// Uniform float in [0, 1): the top 24 bits times 2^-24 are exactly representable, so the
// result is never rounded up to 1.0 (the largest value is 1 - 2^-24).
GDPT_INLINE float rngNext(GDPT_INOUT(Rng) r) {
    return float(rngNextUint(r) >> 8u) * (1.0f / 16777216.0f);
}

GDPT_INLINE vec2 rngNext2(GDPT_INOUT(Rng) r) {
    float a = rngNext(r);
    float b = rngNext(r);
    return vec2(a, b);
}

GDPT_INLINE vec3 rngNext3(GDPT_INOUT(Rng) r) {
    float a = rngNext(r);
    float b = rngNext(r);
    float c = rngNext(r);
    return vec3(a, b, c);
}

GDPT_NAMESPACE_END

#endif  // GDPT_LIB_RNG
