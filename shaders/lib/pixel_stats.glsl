// pixel_stats.glsl — per-invocation Welford statistics of a batch of samples and their Chan
// et al. 1979 merge into a pixel's running PixelStats, shared by gpt.comp and visible.comp.
// GLSL only.
#ifndef GDPT_LIB_PIXEL_STATS
#define GDPT_LIB_PIXEL_STATS

// Welford accumulator of one quantity over this batch.
struct Welford {
    vec3 mean;
    vec3 m2;
};

void welfordAdd(inout Welford a, vec3 x, uint n) {
    vec3 delta = x - a.mean;
    a.mean += delta / float(n);
    a.m2 += delta * (x - a.mean);
}

// Chan et al. 1979 pairwise merge of a batch (n samples) into stored statistics.
PixelStats chanMerge(PixelStats acc, Welford a, uint n) {
    uint total = acc.count + n;
    vec3 delta = a.mean - acc.mean;
    float fb = float(n) / float(total);
    acc.mean += delta * fb;
    acc.m2 += a.m2 + delta * delta * float(acc.count) * fb;
    acc.count = total;
    return acc;
}

#endif  // GDPT_LIB_PIXEL_STATS
