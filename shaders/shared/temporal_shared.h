// temporal_shared.h — host/shader interface of the temporal reconnection shift
// (tgpt_reconnect.comp; src/render/passes/temporal_reconnect_pass.h). Same rules as
// gdpt_shared.h, which it extends (C++17 and GLSL 460, layout(scalar), no bool, append-only
// structs), with the bindings above mlt_shared.h's.
#ifndef GDPT_TEMPORAL_SHARED_H
#define GDPT_TEMPORAL_SHARED_H

#include "mlt_shared.h"

#ifdef __cplusplus
namespace gdpt::gpu {
#endif

// Push constants of tgpt_reconnect.comp (<= 128 bytes). 32 bytes.
struct TemporalParams {
    uint sampleBase;       // index of the first sample of this batch (per pixel)
    uint samplesPerPixel;  // samples per pixel in this batch
    uint seed;             // user seed (of this direction: each direction samples its own paths)
    uint rowOffset;        // first image row of this dispatch (dispatch tiling)
    uint rowCount;         // rows in this dispatch
    uint baseFrame;        // 0 or 1: the frame (FramePairGpu's order) the base paths are sampled in;
                           // the offset paths are in the other one
    uint flags;            // kTemporalFlag* bits
    uint pad;
};

// Test only: every pair weight 1 in the dispatch of base frame 0 and 0 in the other's, i.e. the
// shift without multiple importance sampling over its two directions, which misses the paths
// of frame 1 that no path of frame 0 shifts to (the tests show that it is biased).
GDPT_CONST uint kTemporalFlagOneDirection = 1u;

// Where pixel p of the base frame has its partner in the other frame. 16 bytes.
struct TemporalPartner {
    uint pixel;    // the partner pixel's index (y·width + x), or kInvalidIndex: no difference here
    float shiftX;  // a camera sample at p + u has its offset at partner + fract(u + shift)
    float shiftY;  // (a toroidal shift of the sub-pixel position, in pixels, each in (−1, 1))
    uint pad;
};

// Descriptor bindings of tgpt_reconnect.comp (set 0), above mlt_shared.h's. Each holds the
// address of a per-pixel buffer (pixel_buffers.glsl) with both directions' entries, the
// direction of base frame 0's first (entry baseFrame·width·height + pixel).
GDPT_ENUM_BEGIN(TemporalBinding)
kBindTemporalPartner = 70u,         // TemporalPartner per pixel of the base frame
    kBindTemporalDifference = 71u,  // PixelStats per pixel: Σ pair weight · (offset − base)
    kBindTemporalBase = 72u         // PixelStats per pixel: the base path's own radiance (no
                                    // emission seen directly from the camera)
    GDPT_ENUM_END();

#ifdef __cplusplus
static_assert(sizeof(TemporalParams) == 32, "TemporalParams layout");
static_assert(sizeof(TemporalPartner) == 16, "TemporalPartner layout (scalar)");
static_assert(std::uint32_t{kBindTemporalPartner} > std::uint32_t{kBindMltDirect},
              "temporal bindings must not collide with mlt_shared.h's");
}  // namespace gdpt::gpu
#endif

#endif  // GDPT_TEMPORAL_SHARED_H
