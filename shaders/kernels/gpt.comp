// gpt.comp — gradient-domain path tracing megakernel, sampling half (Kettunen, Manzi,
// Aittala, Lehtinen, Durand and Zwicker 2015, "Gradient-Domain Path Tracing", ACM TOG 34(4),
// §4). One invocation = one pixel p, a batch of
// camera samples per dispatch, the structure of pt.comp.
//
// Per camera sample: the base path (exactly pt.comp's path for the same random stream:
// same RNG consumption, NEE + BSDF sampling with the power heuristic, RR) and four offset
// paths starting at the same sub-pixel position ±1 pixel (right, down, left, up; +y = next
// row), built by the shift mapping (shift.glsl): reconnection when base current, base next
// and offset current vertices are rough, else the half-vector copy; NEE shifted with the
// same light point. Each pixel pair (p, p+δ_i) is estimated with MIS between the forward and
// reverse shift (power heuristic, Veach 1997 eq. 9.13, in ratio form, shift.glsl), counting
// the two pixels' sample counts where the edge samples make them differ. The steps
// of a bounce are named functions (gpt_steps.glsl), put together in gpt_bounce.glsl.
//
// Offset state (ratio form, shift.glsl): beta' = f'/p (offset contribution over the
// BASE path's pdf, Jacobians included) and r = J·p'/p (offset density in the base's measure
// over the base's density), rLight = the prefix ratio that applies to the light strategy at
// the next vertex. RR: q from the base; p and every p' get the factor q (beta and every
// beta' are divided by q, r is unchanged).
//
// Output per pixel p, per batch folded by Welford and merged by Chan (as pt.comp):
//   central(p)      Σ over the pairs of p of the base's MIS-weighted radiance
//   neighbor_i(p)   offset i's MIS-weighted radiance (an estimate for pixel p + δ_i)
//   gradient_i(p)   MIS-weighted (f_offset − f_base) of direction i
//   direct(p)       emission seen directly from the camera (never shifted); zero in the
//                   pixels of emitter supersampling (emitter_supersampling.comp), whose
//                   estimate gpt_resolve.comp takes instead
//   modulation(p)   with kDemodulate only: the base paths' first-hit modulation m
//
// First-hit texture demodulation (kDemodulate, a specialisation constant): in the pixels the
// host marks in demodMask (away from geometric edges), a path divides its contributions by m,
// the base-colour texture at its first hit (Lambertian-only materials), so central,
// neighbor_i and gradient_i estimate J = I / m̄ there, with m̄ the pixel mean of m. A
// gradient between two texels then carries (J' − J), the lighting difference, instead of
// (t' − t) times the lighting estimate, and the host multiplies the reconstruction of J by
// m̄. This assumes m and J uncorrelated inside a pixel, which fails where a pixel spans two
// surfaces: hence the mask (bench/RESULTS.md).
// Each invocation writes only its own pixel: no races, no float atomics, deterministic.
// gpt_resolve.comp gathers the neighbours' terms.
#version 460
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "gpt_shared.h"
#include "lib/common.glsl"
#include "lib/rng.glsl"
#include "lib/sampler.glsl"
#include "lib/ray.glsl"

layout(local_size_x_id = kSpecWorkgroupX, local_size_y_id = kSpecWorkgroupY) in;

#include "lib/scene_buffers.glsl"
layout(set = 0, binding = kBindCounters, scalar) buffer CounterBuf { Counters counters; };
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
GDPT_PIXEL_BUFFER(kBindGptEdgeList, UintArray, edgeList);
#define edgeList edgeList_.v
GDPT_PIXEL_BUFFER(kBindGptSampleRate, UintArray, sampleRate);
#define sampleRate sampleRate_.v
GDPT_PIXEL_BUFFER(kBindGptDemodMask, UintArray, demodMask);
#define demodMask demodMask_.v
layout(buffer_reference, scalar, buffer_reference_align = 4) buffer PixelStreamArray { PixelStream v[]; };
GDPT_PIXEL_BUFFER(kBindGptStreamKey, PixelStreamArray, pixelStream);
#define pixelStream pixelStream_.v
GDPT_PIXEL_BUFFER(kBindGptModulation, PixelStatsArray, statModulation);
#define statModulation statModulation_.v
layout(constant_id = kSpecGptDemodulate) const bool kDemodulate = false;
layout(push_constant, scalar) uniform Push { GptFrameParams frame; };

#include "lib/scene_access.glsl"
#define GDPT_ANYHIT_FILTER(tri, u, v) alphaPasses(tri, u, v)
#include "lib/bvh_coherent.glsl"
#include "lib/shift.glsl"
#include "lib/gpt_light.glsl"

// Pixel offset δ_i of offset path i, in gpt_shared.h's order (kGptRight, kGptDown, kGptLeft,
// kGptUp; +y = next image row).
const ivec2 kOffsetDelta[kGptNumOffsets] =
    ivec2[kGptNumOffsets](ivec2(1, 0), ivec2(0, 1), ivec2(-1, 0), ivec2(0, -1));

#include "lib/camera.glsl"
#include "lib/visible_emission.glsl"
#include "lib/gpt_path.glsl"
#include "lib/surface_rules.glsl"
#include "lib/gpt_steps.glsl"

// A texture value below this (per channel) demodulates by this instead: keeps 1/m finite
// where a texel is black (its samples then underestimate J a little).
const float kMinModulation = 1.0 / 64.0;

// Demodulation factor m of a path whose camera sample lies in `pixel` and whose first hit is
// h: the base-colour texture there if the pixel is marked and the material's BSDF is that
// texture times a Lambertian lobe (no metal, no specular layer), else 1.
vec3 firstHitModulation(SurfaceHit h, uint pixel) {
    if (!kDemodulate || demodMask[pixel] == 0u) return vec3(1.0);
    Material m = material(h.material);
    if (!modulatesLambertian(m)) return vec3(1.0);
    return max(sampleTexture(m.baseColorTex, h.uv).xyz, vec3(kMinModulation));
}

#include "lib/gpt_trace.glsl"

// The quantities gpt.comp accumulates per pixel, as indices into main's accumulators: central,
// neighbor_i and gradient_i (i in kOffsetDelta's order), direct.
const uint kAccCentral = 0u;
const uint kAccNeighbor = 1u;
const uint kAccGradient = kAccNeighbor + kGptNumOffsets;
const uint kAccDirect = kAccGradient + kGptNumOffsets;
const uint kAccCount = kAccDirect + 1u;

void main() {
    loadScene();
    uint x = gl_GlobalInvocationID.x;
    uint y = gl_GlobalInvocationID.y + frame.rowOffset;
    if (x >= scene.width || y >= scene.height || gl_GlobalInvocationID.y >= frame.rowCount) return;
    if (frame.listCount > 0u) {
        // Edge-list mode (EdgePass): (x, y) is entry y·width + x of the list of the pixels a
        // geometric edge crosses; the host set sampleBase, samplesPerPixel and seed to their
        // extra samples' own streams. Everything below is the same per-pixel estimator.
        uint item = y * scene.width + x;
        if (item >= frame.listCount) return;
        uint listed = edgeList[item];
        x = listed % scene.width;
        y = listed / scene.width;
    }
    uint pixel = y * scene.width + x;

    Welford acc[kAccCount];
    [[unroll]] for (uint k = 0u; k < kAccCount; ++k) acc[k] = welfordInit();
    Welford accModulation = welfordInit();  // kDemodulate only
    uint n = 0u;
    uint rays = 0u;
    uint nan = 0u;
    uint shiftPairs = 0u, shiftFailures = 0u;
    OffsetPath offs[kGptNumOffsets];
    bool countDirect = !emissionSupersampled(pixel);
    // The random stream of this pixel's samples: its own (as pt.comp's), or the one the host
    // assigned (temporal G-PT: the stream of the pixel of the previous frame whose primary hit
    // moved here, with the sub-pixel part of that motion as a toroidal shift of the position
    // in the pixel, so that the same path is replayed from the same surface point).
    uint stream = pixel;
    vec2 jitterShift = vec2(0.0);
    if (frame.streamKeys != 0u) {
        PixelStream ps = pixelStream[pixel];
        stream = ps.key;
        jitterShift = vec2(ps.jitterShift & 0xFFFFu, ps.jitterShift >> 16u) * (1.0 / 65536.0);
    }
    // n_q / n_p of each pair (p, q = p + δ_i): the two pixels' sample counts per camera sample
    // of the image, which the pair's MIS weights count (shift.glsl). 1 where every pixel takes
    // the same number, or the pair does not exist.
    vec4 countRatio = vec4(1.0);
    if (frame.sampleRates != 0u) {
        float own = float(sampleRate[pixel]);
        [[unroll]] for (uint i = 0u; i < kGptNumOffsets; ++i) {
            if (gptPairExists(x, y, i)) countRatio[i] = float(sampleRate[gptPairPixel(x, y, i)]) / own;
        }
    }
    for (uint s = 0u; s < frame.samplesPerPixel; ++s) {
        // Same stream as pt.comp's sample s: the base path is PT's path.
        Rng rng = rngInit(stream, frame.sampleBase + s, frame.seed);
        LdSample lds = ldSampleInit(stream, frame.sampleBase + s, frame.seed);
        vec2 jitter = fract(ldGet2(lds, kLdDimPixel) + jitterShift);
        vec3 direct, baseModulation;
        traceSample(lds, rng, vec2(x, y) + jitter, x, y, countDirect, countRatio, rays, direct, baseModulation,
                    offs);
        if (kDemodulate) {
            [[unroll]] for (uint i = 0u; i < kGptNumOffsets; ++i) {
                offs[i].baseSum /= baseModulation;
                offs[i].offSum /= offs[i].modulation;
            }
        }
        [[unroll]] for (uint i = 0u; i < kGptNumOffsets; ++i) {
            shiftPairs += offs[i].shifted ? 1u : 0u;
            shiftFailures += offs[i].shifted && !offs[i].alive ? 1u : 0u;
        }
        vec3 central = vec3(0.0);
        bool finite = isFinite(direct);
        [[unroll]] for (uint i = 0u; i < kGptNumOffsets; ++i) {
            central += offs[i].baseSum;
            finite = finite && isFinite(offs[i].baseSum) && isFinite(offs[i].offSum);
        }
        n++;
        if (kDemodulate) welfordAdd(accModulation, baseModulation, n);
        // The non-finite policy of pixel_stats.glsl over the whole sample: one non-finite
        // quantity makes every quantity of it zero, so the pairs stay consistent.
        if (!finite) nan++;
        welfordAdd(acc[kAccCentral], statsSample(central, finite), n);
        [[unroll]] for (uint i = 0u; i < kGptNumOffsets; ++i) {
            welfordAdd(acc[kAccNeighbor + i], statsSample(offs[i].offSum, finite), n);
            welfordAdd(acc[kAccGradient + i], statsSample(offs[i].offSum - offs[i].baseSum, finite), n);
        }
        welfordAdd(acc[kAccDirect], statsSample(direct, finite), n);
    }
    statCentral[pixel] = chanMerge(statCentral[pixel], acc[kAccCentral], n);
    statNeighbor0[pixel] = chanMerge(statNeighbor0[pixel], acc[kAccNeighbor + kGptRight], n);
    statNeighbor1[pixel] = chanMerge(statNeighbor1[pixel], acc[kAccNeighbor + kGptDown], n);
    statNeighbor2[pixel] = chanMerge(statNeighbor2[pixel], acc[kAccNeighbor + kGptLeft], n);
    statNeighbor3[pixel] = chanMerge(statNeighbor3[pixel], acc[kAccNeighbor + kGptUp], n);
    statGradient0[pixel] = chanMerge(statGradient0[pixel], acc[kAccGradient + kGptRight], n);
    statGradient1[pixel] = chanMerge(statGradient1[pixel], acc[kAccGradient + kGptDown], n);
    statGradient2[pixel] = chanMerge(statGradient2[pixel], acc[kAccGradient + kGptLeft], n);
    statGradient3[pixel] = chanMerge(statGradient3[pixel], acc[kAccGradient + kGptUp], n);
    statDirect[pixel] = chanMerge(statDirect[pixel], acc[kAccDirect], n);
    if (kDemodulate) statModulation[pixel] = chanMerge(statModulation[pixel], accModulation, n);
    atomicAdd(counters.raysTraced, rays);
    atomicAdd(counters.pathsCompleted, n);
    if (nan > 0u) atomicAdd(counters.nanSamples, nan);
    atomicAdd(counters.shiftPairs, shiftPairs);
    if (shiftFailures > 0u) atomicAdd(counters.shiftFailures, shiftFailures);
}
