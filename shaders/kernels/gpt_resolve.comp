// gpt_resolve.comp — gathers the per-pixel statistics of gpt.comp into the G-PT images: the
// primal and gradient estimates of Kettunen et al. 2015 and their variances. One invocation
// = one pixel p; it only reads its own and its four neighbours' statistics and writes its
// own GptResolved: deterministic, no atomics.
//
// Notation: m_X(p) = mean of quantity X at pixel p over its N samples, v_X(p) = variance of
// that mean = M2 / (N − 1) / N; δ_i = right, down, left, up.
//   primal(p) = [m_central(p) + Σ_{i: p−δ_i in image} m_neighbor_i(p − δ_i)] / k(p)
// where k(p) = number of neighbours of p inside the image (1 to 4; in a 1x1 image 0, and
// central holds the one pair of gptPairCounted there, so k = 1). Each pixel pair
// (p, q) gives one unbiased estimator of I(p): the base part from p's samples plus the
// offset part from q's samples (their MIS weights sum to 1, shift.glsl). central(p) holds
// the base parts of the k(p) pairs and p receives exactly k(p) neighbour parts, so the
// average of the k(p) pair estimators is unbiased at borders and corners too. (The
// authors' implementation always divides by 4N; it has no border rule because Mitsuba
// films splat off the image with a weight.)
//   dx(p) = m_gradient_right(p) − m_gradient_left(p + (1,0))   estimates I(x+1,y) − I(x,y)
//   dy(p) = m_gradient_down(p)  − m_gradient_up(p + (0,1))     estimates I(x,y+1) − I(x,y)
// (both endpoints' estimators of the pair, MIS weights summing to 1); zero in the last
// column / row, whose gradient rows the Poisson solver drops.
// Variances: every term comes from a different pixel's samples, and distinct pixels use
// independent random streams (rngInit(pixel, sample, seed)), so the terms are independent
// and their variances add: var_primal = [v_central(p) + Σ v_neighbor_i(p − δ_i)] / k(p)²,
// var_dx = v_gradient_right(p) + v_gradient_left(p + (1,0)), likewise var_dy.
#version 460
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require

#include "gpt_shared.h"
#include "lib/pixel_stats.glsl"

layout(local_size_x_id = kSpecWorkgroupX, local_size_y_id = kSpecWorkgroupY) in;

#include "lib/pixel_buffers.glsl"
GDPT_PIXEL_BUFFER(kBindGptCentral, PixelStatsArray, statCentral);
#define statCentral statCentral_.v
GDPT_PIXEL_BUFFER(kBindGptNeighbor0, PixelStatsArray, statNeighbor0);
#define statNeighbor0 statNeighbor0_.v
GDPT_PIXEL_BUFFER(kBindGptNeighbor1, PixelStatsArray, statNeighbor1);
#define statNeighbor1 statNeighbor1_.v
GDPT_PIXEL_BUFFER(kBindGptNeighbor2, PixelStatsArray, statNeighbor2);
#define statNeighbor2 statNeighbor2_.v
GDPT_PIXEL_BUFFER(kBindGptNeighbor3, PixelStatsArray, statNeighbor3);
#define statNeighbor3 statNeighbor3_.v
GDPT_PIXEL_BUFFER(kBindGptGradient0, PixelStatsArray, statGradient0);
#define statGradient0 statGradient0_.v
GDPT_PIXEL_BUFFER(kBindGptGradient1, PixelStatsArray, statGradient1);
#define statGradient1 statGradient1_.v
GDPT_PIXEL_BUFFER(kBindGptGradient2, PixelStatsArray, statGradient2);
#define statGradient2 statGradient2_.v
GDPT_PIXEL_BUFFER(kBindGptGradient3, PixelStatsArray, statGradient3);
#define statGradient3 statGradient3_.v
GDPT_PIXEL_BUFFER(kBindGptDirect, PixelStatsArray, statDirect);
#define statDirect statDirect_.v
#include "lib/visible_emission.glsl"
layout(buffer_reference, scalar, buffer_reference_align = 4) buffer GptResolvedArray { GptResolved v[]; };
GDPT_PIXEL_BUFFER(kBindGptResolved, GptResolvedArray, resolved);
#define resolved resolved_.v
layout(push_constant, scalar) uniform Push { GptFrameParams frame; };

void main() {
    uint x = gl_GlobalInvocationID.x;
    uint y = gl_GlobalInvocationID.y + frame.rowOffset;
    if (x >= frame.width || y >= frame.height || gl_GlobalInvocationID.y >= frame.rowCount) return;
    uint w = frame.width;
    uint p = y * w + x;

    PixelStats c = statCentral[p];
    vec3 sum = c.mean;
    vec3 var = varianceOfMean(c);
    float k = 0.0;
    // Neighbour q = p − δ_i sent its offset i to p.
    if (x > 0u) {  // q = left neighbour, its offset "right"
        PixelStats s = statNeighbor0[p - 1u];
        sum += s.mean; var += varianceOfMean(s); k += 1.0;
    }
    if (y > 0u) {  // q = upper neighbour, its offset "down"
        PixelStats s = statNeighbor1[p - w];
        sum += s.mean; var += varianceOfMean(s); k += 1.0;
    }
    if (x + 1u < w) {  // q = right neighbour, its offset "left"
        PixelStats s = statNeighbor2[p + 1u];
        sum += s.mean; var += varianceOfMean(s); k += 1.0;
    }
    if (y + 1u < frame.height) {  // q = lower neighbour, its offset "up"
        PixelStats s = statNeighbor3[p + w];
        sum += s.mean; var += varianceOfMean(s); k += 1.0;
    }

    GptResolved r;
    // k = 0 only in a 1x1 image, whose central holds one pair: the lone base path's
    // (gptPairCounted in gpt_path.glsl), an estimate of I(p) by itself.
    k = max(k, 1.0);
    r.primal = sum / k;
    r.varPrimal = var / (k * k);
    r.dx = vec3(0.0);
    r.varDx = vec3(0.0);
    if (x + 1u < w) {
        PixelStats a = statGradient0[p];
        PixelStats b = statGradient2[p + 1u];
        r.dx = a.mean - b.mean;
        r.varDx = varianceOfMean(a) + varianceOfMean(b);
    }
    r.dy = vec3(0.0);
    r.varDy = vec3(0.0);
    if (y + 1u < frame.height) {
        PixelStats a = statGradient1[p];
        PixelStats b = statGradient3[p + w];
        r.dy = a.mean - b.mean;
        r.varDy = varianceOfMean(a) + varianceOfMean(b);
    }
    // emitter supersampling estimated this pixel's very-direct emission instead
    // (emitter_supersampling.comp; gpt.comp then left statDirect zero here).
    PixelStats dir = statDirect[p];
    if (emissionSupersampled(p)) dir = visibleStats[p];
    r.direct = dir.mean;
    r.varDirect = varianceOfMean(dir);
    resolved[p] = r;
}
