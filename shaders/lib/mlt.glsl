// mlt.glsl — the Metropolis-Hastings steps of primary-sample-space MLT (mlt.comp), shared by
// the kernel and the CPU tests (detailed balance on an analytic target,
// tests/unit/sampling/test_mlt_chain.cpp).
//
// A chain walks the unit hypercube of the path's decisions (Kelemen, Szirmay-Kalos, Antal,
// Csonka 2002, "A Simple and Robust Mutation Strategy for the Metropolis Light Transport
// Algorithm", Computer Graphics Forum 21(3)):
//   large step  every coordinate drawn afresh, uniform;
//   small step  every coordinate moved by ±s2·exp(−ln(s2/s1)·ξ), wrapped into [0, 1) (§3.1,
//               s1 = 1/1024, s2 = 1/64);
// both proposals are symmetric (q(x→y) = q(y→x)), so the acceptance probability is
// a = min(1, T(y)/T(x)) for the target T.
//
// Splatting (Kelemen et al. 2002, §4): every mutation contributes its current state x with
// acceptance share 1 − a and its proposal y with share a (expected values), and a large step's
// proposal, a uniform sample of the hypercube, is also an independent sample of the image.
// The two sampling techniques, N Metropolis samples of density T/b and (in expectation) N·p
// uniform ones (p the large-step probability), are combined by the balance heuristic, so a
// state of target T contributes its value g times
//     Metropolis share:  share / (N · (T/b + p))
//     large step:        1 / (N · (T/b + p))
// where the image is dark (T/b ≪ p) the large steps carry the estimate, as a path tracer's
// samples would, and where it is bright the chains do. The weights may use any b' > 0 in
// place of b (the balance heuristic's weights sum to one for any), but the Metropolis
// samples' density is T/b with the true b: with b' in the weights the shares become
//     Metropolis:  b · share / (N · (T + b'·p))      (b: the final estimate b̂, applied by the host)
//     large step:  b' / (N · (T + b'·p))
// (mltSplatWeight and mltLargeStepWeight without the common 1/N). b' is the bootstrap's b̂,
// known before the chains start; b̂ pools the large steps' targets too. p = 0 is plain
// Metropolis splatting, share / T.
#ifndef GDPT_LIB_MLT
#define GDPT_LIB_MLT

#include "common.glsl"

GDPT_NAMESPACE_BEGIN

GDPT_CONST float kMltSmallStepMin = 1.0f / 1024.0f;  // s1
GDPT_CONST float kMltSmallStepMax = 1.0f / 64.0f;    // s2

// Kelemen's small step of one coordinate u in [0, 1), driven by two uniforms: xiSign picks
// the direction, xiSize the size (log-uniform between s1 and s2). Result in [0, 1).
GDPT_INLINE float mltSmallStep(float u, float xiSign, float xiSize) {
    float dv = kMltSmallStepMax * exp(-log(kMltSmallStepMax / kMltSmallStepMin) * xiSize);
    float v = xiSign < 0.5f ? u + dv : u - dv;
    v = v - floor(v);                   // wrap: the hypercube is a torus for the small step
    return min(v, kOneMinusEpsilon);    // v - floor(v) may round to 1 for v just below 0
}

// Metropolis-Hastings acceptance probability of a symmetric proposal from target tCurrent
// to tProposed. A current state of target 0 (never the case for a chain started by the
// bootstrap) accepts anything.
GDPT_INLINE float mltAcceptance(float tCurrent, float tProposed) {
    if (!(tCurrent > 0.0f)) return 1.0f;
    return min(1.0f, tProposed / tCurrent);
}

// Metropolis splat weight of a state with target t and acceptance share w (a for the
// proposal, 1 − a for the current state): w / (t + bLarge), bLarge = b'·p; 0 for a state no
// technique sees.
GDPT_INLINE float mltSplatWeight(float w, float t, float bLarge) {
    float d = t + bLarge;
    return d > 0.0f ? w / d : 0.0f;
}

// Large-step weight of a large step's proposal of target t: b' / (t + b'·p).
GDPT_INLINE float mltLargeStepWeight(float t, float bWeights, float largeStep) {
    float d = t + bWeights * largeStep;
    return d > 0.0f ? bWeights / d : 0.0f;
}

// The target of gradient-domain MLT (Lehtinen et al. 2013, §4: the sum of the absolute
// finite differences plus α times the image) for one G-PT sample: the luminance of the four
// gradients' absolute values (per channel) plus alpha times the luminance of the sample's
// radiance, (central + Σ neighbor_i) / 4, which for a sample whose offsets see what the base
// sees is the path's own contribution (the pair weights of each pixel pair sum to one).
// Every quantity the sample carries is non-zero only where this is (radiance is non-negative
// and alpha > 0), so the chain misses nothing that it splats.
GDPT_INLINE float gmltTarget(float gradientAbsLuminance, vec3 central, vec3 neighborSum, float alpha) {
    return gradientAbsLuminance + alpha * 0.25f * luminance(central + neighborSum);
}

// The tempered target T^γ that the chains walk, for the method's target T and γ = `exponent`
// (`--target-exponent`; 1 leaves T as it is, to the bit). Any function that is positive
// wherever a sample carries something is a valid target: the splat weights above divide by the
// target the chains walk, so the estimate stays unbiased whatever γ > 0, and only its variance
// changes. With γ < 1 the chains care less about how much brighter a state is than another:
// the heavy tail of the gradient target (paths whose offsets fail, whose gradients are their
// whole contribution) holds a chain less long, the chains move between regions more often and
// splat fewer blotches, and the large steps' proposals are accepted more often (a tempered
// target, as tempered Markov chain Monte Carlo uses: here the chains walk it alone and the
// splat weights reweight their samples). T = 0 stays 0: a chain never enters a state that
// carries nothing.
GDPT_INLINE float mltTemperedTarget(float t, float exponent) {
    if (exponent == 1.0f) return t;
    return t > 0.0f ? pow(t, exponent) : 0.0f;
}

// Index of the image block (`block` pixels square, `columns` per row, row major) that pixel
// (x, y) lies in: the entry of the target's divisor (mlt.comp, mlt_estimate.h
// MltBlockNormaliser).
GDPT_INLINE uint mltBlockIndex(uint x, uint y, uint block, uint columns) {
    return (y / block) * columns + x / block;
}

GDPT_NAMESPACE_END

#endif  // GDPT_LIB_MLT
