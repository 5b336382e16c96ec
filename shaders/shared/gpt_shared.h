// gpt_shared.h — host/shader interface of gradient-domain path tracing (gpt.comp and
// gpt_resolve.comp). Same rules as gdpt_shared.h, which it extends: C++17 and GLSL 460,
// layout(scalar), no bool, append-only structs, units/space of every field in its comment,
// and binding numbers / spec ids defined only here (they do not collide with
// gdpt_shared.h's, which this file checks under C++).
#ifndef GDPT_GPT_SHARED_H
#define GDPT_GPT_SHARED_H

#include "gdpt_shared.h"

#ifdef __cplusplus
namespace gdpt::gpu {
#endif

// Neighbour order of the offset paths: right, down, left, up, with +y = next image row.
// Offset i starts at the base's sub-pixel position + δ_i (gpt.comp's kOffsetDelta).
GDPT_CONST uint kGptRight = 0u;
GDPT_CONST uint kGptDown = 1u;
GDPT_CONST uint kGptLeft = 2u;
GDPT_CONST uint kGptUp = 3u;
GDPT_CONST uint kGptNumOffsets = 4u;

// Per-batch push constants of gpt.comp and gpt_resolve.comp (<= 128 bytes). 44 bytes.
struct GptFrameParams {
    uint sampleBase;       // index of the first sample of this batch (per pixel)
    uint samplesPerPixel;  // samples per pixel in this batch
    uint seed;             // user seed
    uint rowOffset;        // first image row of this dispatch (dispatch tiling)
    uint rowCount;         // rows in this dispatch
    float shiftThreshold;  // roughness (perceptual, sqrt of GGX alpha) at or below which a
                           // vertex is glossy/specular (half-vector shift); reference 0.001
    uint width;            // image width in pixels (gpt_resolve.comp, which has no scene)
    uint height;           // image height in pixels
    uint listCount;        // 0: the dispatch covers image rows; > 0: edge-list mode, the
                           // dispatch's (x, row) is entry row·width + x of kBindGptEdgeList
                           // (rowOffset/rowCount tile those virtual rows), listCount entries
    uint streamKeys;       // 1: pixel p's camera samples draw their random numbers from the
                           // stream kBindGptStreamKey[p] names instead of stream p, and shift
                           // their position in the pixel by its jitter shift (temporal G-PT's
                           // motion-carried shift, motion_map.h); 0: stream p, unshifted
    uint sampleRates;      // 1: pixels take different numbers of samples (edge samples), in the
                           // proportions kBindGptSampleRate holds, and each pair's MIS weights
                           // count them (shift.glsl); 0: every pixel the same number
};

// Where pixel p's camera samples come from when GptFrameParams::streamKeys is 1. 8 bytes.
struct PixelStream {
    uint key;          // the random stream (any uint; pixel p's own is p)
    uint jitterShift;  // s in [0,1)^2 in 1/65536 pixels, x in the low 16 bits, y in the high:
                       // each sample's position in the pixel is fract(u + s) for its uniform
                       // u (a toroidal shift: still uniform over the pixel)
};

// Resolved per-pixel output of gpt_resolve.comp (linear RGB radiance, W/(m^2 sr)). 96 bytes;
// 88 MB for 1280x720, below lavapipe's 128 MiB maxStorageBufferRange.
struct GptResolved {
    vec3 primal;     // indirect ("throughput") estimate of I(p): average of the pair estimators
    vec3 dx;         // forward difference I(x+1,y) - I(x,y); 0 in the last column
    vec3 dy;         // forward difference I(x,y+1) - I(x,y); 0 in the last row
    vec3 direct;     // emission seen directly by the camera ("very direct")
    vec3 varPrimal;  // variance of the primal estimate (of the mean, not per sample)
    vec3 varDx;      // variance of the dx estimate
    vec3 varDy;      // variance of the dy estimate
    vec3 varDirect;  // variance of the direct estimate
};

// Where edge.comp sees an edge between two probe points (and the host between two pixels'
// probes, demodulationMask): normals further apart than ~26° are a crease; a point further off
// the other's tangent plane than this fraction of its in-plane distance is a step in depth.
GDPT_CONST float kEdgeNormalCos = 0.9f;
GDPT_CONST float kEdgeTangentSlope = 0.25f;

// What the edge probe (edge.comp) saw at a pixel's first probe point: the host compares it
// with the neighbours' to keep first-hit demodulation away from edges that lie between two
// pixels' probe points (demodulationMask, gpt_pass.h). 32 bytes.
struct EdgeProbe {
    vec3 position;  // world-space first hit (0 on a miss)
    uint material;  // material index of the hit (0 on a miss)
    vec3 normal;    // unit geometric normal facing the camera ray's side (0 on a miss)
    uint hit;       // 1 = the probe ray hit a surface, 0 = it missed
};

// Descriptor bindings of the G-PT pipelines (set 0). The scene uses kBindTriGeom ..
// kBindSceneConst and the counters kBindCounters of gdpt_shared.h; the per-pixel statistics
// (PixelStats each, one buffer per quantity so none exceeds 128 MiB) follow here, above
// every number gdpt_shared.h uses (its scene list grows from 12 up, tests use 32..34).
GDPT_ENUM_BEGIN(GptBinding)
kBindGptCentral = 40u,        // base's MIS-weighted radiance summed over the pairs of pixel p
    kBindGptNeighbor0 = 41u,  // offset i's MIS-weighted radiance (belongs to pixel p + δ_i), i = 0..3
    kBindGptNeighbor1 = 42u, kBindGptNeighbor2 = 43u, kBindGptNeighbor3 = 44u,
    kBindGptGradient0 = 45u,  // MIS-weighted f_offset − f_base of direction i, i = 0..3
    kBindGptGradient1 = 46u, kBindGptGradient2 = 47u, kBindGptGradient3 = 48u,
    kBindGptDirect = 49u,    // very-direct emission (first hit seen from the camera)
    kBindGptResolved = 50u,  // GptResolved[] written by gpt_resolve.comp
    kBindGptEdgeMask = 51u,  // uint per pixel written by edge.comp: 1 = a geometric edge
                             // crosses the pixel, else 0
    kBindGptEdgeList = 52u,  // uint pixel indices (y·width + x) of the edge pixels, ascending
    // First-hit texture demodulation (kSpecGptDemodulate; gpt_pass.h): a path whose camera
    // sample lies in a pixel with kBindGptDemodMask 1 divides its contributions by the
    // modulation m = the base-colour texture at its first hit (Lambertian-only materials;
    // else 1), so that pixel's statistics estimate J = I / m̄ (m̄ = the pixel mean of m).
    kBindGptDemodMask = 53u,   // uint per pixel: 1 = demodulate the paths that start in it
    kBindGptModulation = 54u,  // PixelStats per pixel: m at the base paths' first hits (1 where
                               // not demodulated, also on a miss)
    kBindGptEdgeProbe = 55u,   // EdgeProbe per pixel written by edge.comp
    kBindGptStreamKey = 56u,   // PixelStream per pixel: where its camera samples come from (read
                               // when GptFrameParams::streamKeys is 1)
    kBindGptSampleRate = 57u   // uint per pixel: its camera samples per camera sample of the
                               // image, 1 + edge factor in the listed pixels, else 1 (read when
                               // GptFrameParams::sampleRates is 1)
    GDPT_ENUM_END();

#ifdef __cplusplus
static_assert(sizeof(GptFrameParams) == 44, "GptFrameParams layout");
static_assert(sizeof(GptResolved) == 96, "GptResolved layout (scalar)");
static_assert(sizeof(EdgeProbe) == 32, "EdgeProbe layout (scalar)");
static_assert(sizeof(PixelStream) == 8, "PixelStream layout (scalar)");
static_assert(std::uint32_t{kBindGptCentral} > std::uint32_t{kBindTestOutput2},
              "G-PT bindings must not collide with gdpt_shared.h's");
}  // namespace gdpt::gpu
#endif
#endif  // GDPT_GPT_SHARED_H
