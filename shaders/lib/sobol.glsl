// sobol.glsl — the first two dimensions of the Sobol' sequence with nested uniform (Owen)
// scrambling by hashing, shared by the kernels and the CPU tests.
//
// The two dimensions form a (0,2)-sequence in base 2: every aligned block of 2^m points
// (indices k·2^m .. (k+1)·2^m − 1) is a (0,m,2)-net, i.e. it puts exactly one point into each
// of the 2^m elementary intervals of every shape 2^a × 2^(m−a). Any prefix of length 2^m is
// such a block, so the points stratify progressively as a render adds samples.
//
// Dimension 0 is the van der Corput radical inverse (bit reversal of the index); dimension 1
// is Sobol's second generator matrix, whose columns are v_0 = 2^31, v_{k+1} = v_k ^ (v_k >> 1)
// (Bratley & Fox 1988), i.e. the Pascal matrix mod 2. Scrambling: the hash permutation of Laine & Karras 2011 with the
// constants of Burley 2020 ("Practical Hash-based Owen Scrambling", JCGT 9(4)), applied to
// the bit-reversed value. Each output bit then depends only on itself and the bits above it
// (as in the fraction's leading digits), which makes it a nested uniform scramble: it keeps
// the net property and makes every single point uniform on [0,1)^2, so an estimator that
// averages these points is unbiased.
#ifndef GDPT_LIB_SOBOL
#define GDPT_LIB_SOBOL

#include "common.glsl"

#ifdef __cplusplus
#include <glm/integer.hpp>
#endif

GDPT_NAMESPACE_BEGIN

GDPT_INLINE uint sobolReverseBits(uint v) {
    return bitfieldReverse(v);  // GLSL built-in; glm's in the C++ view
}

// Sobol' dimension 1 of `index` as a 0.32 fixed-point fraction. By Lucas' theorem the
// generator matrix has a one at (fraction bit j, index bit k) iff j's bits are a subset of
// k's (C(k, j) odd), so fraction bit j is the XOR of the index bits k ⊇ j: a superset XOR
// transform over the five bits of k, five masked shift-XOR steps instead of a loop over the
// 32 columns.
GDPT_INLINE uint sobolDim1(uint index) {
    uint a = index;
    a ^= (a >> 1u) & 0x55555555u;
    a ^= (a >> 2u) & 0x33333333u;
    a ^= (a >> 4u) & 0x0F0F0F0Fu;
    a ^= (a >> 8u) & 0x00FF00FFu;
    a ^= (a >> 16u) & 0x0000FFFFu;
    return sobolReverseBits(a);
}

// Nested uniform scramble of a 0.32 fraction (Burley 2020, listing 3's constants).
GDPT_INLINE uint owenScramble(uint fraction, uint seed) {
    uint x = sobolReverseBits(fraction);
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return sobolReverseBits(x);
}

// Point `index` of the scrambled sequence in [0,1)^2; seedX and seedY choose the scramble
// (one per pixel and purpose; the two dimensions need different seeds).
GDPT_INLINE vec2 sobolScrambled2(uint index, uint seedX, uint seedY) {
    uint x = owenScramble(sobolReverseBits(index), seedX);
    uint y = owenScramble(sobolDim1(index), seedY);
    // Top 24 bits: exactly representable, never rounded up to 1.
    return vec2(float(x >> 8u) * (1.0f / 16777216.0f), float(y >> 8u) * (1.0f / 16777216.0f));
}

GDPT_NAMESPACE_END

#endif  // GDPT_LIB_SOBOL
