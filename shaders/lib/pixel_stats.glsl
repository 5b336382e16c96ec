// pixel_stats.glsl — the per-pixel sample statistics of every estimator kernel (pt.comp, gpt.comp,
// mlt.comp, tgpt_reconnect.comp, emitter_supersampling.comp) and their readers (gpt_resolve.comp), in the
// GLSL/C++ common subset so the CPU unit tests run this very code.
//
// An invocation folds its batch of n samples into a Welford accumulator (Welford 1962: running
// mean and sum of squared deviations M2, no cancellation) and merges that into the pixel's
// running PixelStats with the pairwise update of Chan, Golub and LeVeque 1979 ("Updating
// formulae and a pairwise algorithm for computing sample variances", eq. 2.1):
//   n = nA + nB,  δ = meanB − meanA,  mean = meanA + δ·nB/n,  M2 = M2A + M2B + δ²·nA·nB/n.
// mean and M2/n stay bounded as samples grow, so float32 keeps ~1e-6 relative accuracy over
// 10^5 samples.
//
// Non-finite samples (the one policy of every kernel): a sample with any channel Inf or NaN
// is counted (Counters::nanSamples) and enters the statistics as zero in all three channels,
// so n still counts it and the mean stays the estimator's mean with that sample set to 0. A
// kernel whose sample estimates several quantities jointly (gpt.comp: central, neighbours,
// gradients, direct) applies this to the whole tuple: one non-finite quantity makes every
// quantity of that sample zero, so the pairs stay consistent.
#ifndef GDPT_LIB_PIXEL_STATS
#define GDPT_LIB_PIXEL_STATS

#include "common.glsl"

GDPT_NAMESPACE_BEGIN

// Welford accumulator of one quantity over an invocation's batch; the sample count is the
// caller's (one count for all the quantities of a sample).
struct Welford {
    vec3 mean;
    vec3 m2;
};

GDPT_INLINE Welford welfordInit() {
    Welford a;
    a.mean = vec3(0.0f);
    a.m2 = vec3(0.0f);
    return a;
}

// The non-finite policy: x itself if `finite`, else zero.
GDPT_INLINE vec3 statsSample(vec3 x, bool finite) {
    return finite ? x : vec3(0.0f);
}

// Folds the n-th sample x (n counts from 1, x already through statsSample) into a.
GDPT_INLINE void welfordAdd(GDPT_INOUT(Welford) a, vec3 x, uint n) {
    vec3 delta = x - a.mean;
    a.mean += delta / float(n);
    a.m2 += delta * (x - a.mean);
}

// Chan et al. 1979 pairwise merge of a batch (n samples, Welford a) into stored statistics.
// Merging an empty batch (n = 0) leaves acc as it is. (One exit, so that spirv-opt inlines it.)
GDPT_INLINE PixelStats chanMerge(PixelStats acc, Welford a, uint n) {
    if (n > 0u) {
        uint total = acc.count + n;
        vec3 delta = a.mean - acc.mean;
        float fb = float(n) / float(total);
        acc.mean += delta * fb;
        acc.m2 += a.m2 + delta * delta * float(acc.count) * fb;
        acc.count = total;
    }
    return acc;
}

// Variance of the mean of one statistic: the unbiased sample variance M2/(N − 1) over N;
// zero below two samples.
GDPT_INLINE vec3 varianceOfMean(PixelStats s) {
    if (s.count < 2u) {
        return vec3(0.0f);
    }
    float n = float(s.count);
    return s.m2 / ((n - 1.0f) * n);
}

GDPT_NAMESPACE_END

#endif  // GDPT_LIB_PIXEL_STATS
