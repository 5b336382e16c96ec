// motion_map.h — where the scene's motion carries each pixel from one frame to the next, and
// the random streams that make temporal G-PT replay a path on the same surface point in both
// frames (Manzi, Kettunen, Durand, Zwicker, Lehtinen 2016, "Temporal Gradient-Domain Path
// Tracing": the shift re-seeds the next frame's pixel with the random numbers of the pixel its
// content came from, by motion vectors rounded to whole pixels).
//
//   1. primaryHits: the hit of the ray through each pixel's centre (triangle and barycentrics,
//      or the direction of a miss), traced on the host against the frame's BVH.
//   2. motionBetween: each hit of frame A carried to frame B's time (the same barycentrics on
//      the same triangle with B's vertex positions; a miss keeps its direction, the
//      environment being static) and projected with B's camera: the pixel q it lands in is
//      pixel p's partner if (a) p is the nearest to B's camera of the pixels of A landing in
//      q, and (b) q's own hit in B, carried back to A, lands within one pixel of p (else
//      the point was hidden in B, or q sees something else). Frames whose triangle lists
//      differ (not one mesh topology) cannot be matched: every pixel is then its own
//      partner, the same-pixel replay.
//   3. carriedStreams: frame B's pixel q draws the stream of the pixel p of A whose partner
//      it is, and a stream of its own (W·H + q, used by no pixel of A) otherwise. The streams
//      of B's pixels are all different, so B's pixels stay independent. The sub-pixel part δ
//      of p's motion (where p's centre lands in B, less q's centre) shifts the samples'
//      positions in q toroidally, u → fract(u + δ): to first order in the motion, a sample
//      at p + u in A and its replay in B see the same surface point (except the fraction |δ|
//      that wraps around), and u stays uniform over the pixel.
//
// Whatever the map, each pixel's estimate uses a valid stream and stays unbiased; the map
// decides only which pairs of estimates are correlated (docs/animation.md).
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "gpt_shared.h"
#include "scene/scene.h"

namespace gdpt {

struct PrimaryHit {
    std::uint32_t triangle = gpu::kInvalidIndex;  // index into Scene::triangles; kInvalidIndex: missed
    float u = 0.0f, v = 0.0f;                     // barycentric weights of the triangle's 2nd and 3rd vertex
    glm::vec3 direction{0.0f};                    // the ray's unit direction
};

// The primary hits through the centres of a width × height image's pixels (row by row) seen
// by the render camera `camera` of `scene` (SceneGpuOptions::camera). Alpha masks are not
// consulted. `threads` 0: every core.
std::vector<PrimaryHit> primaryHits(const Scene& scene, int camera, int width, int height,
                                    std::uint32_t threads = 0);

struct MotionMap {
    // Per pixel of the earlier frame: the pixel index of the later frame it moves to, or
    // kNoTemporalPartner (poisson_spacetime.h).
    std::vector<std::uint32_t> partner;
    // Per pixel with a partner: where its centre lands in the later frame less the partner's
    // centre, in pixels (each component in [-0.5, 0.5)).
    std::vector<glm::vec2> subpixel;
    std::size_t partnered = 0;  // pixels with a partner
    bool sameTopology = true;   // false: the frames' triangle lists differ; partner = the same pixel
};

// The motion from frame `from` to frame `to` (steps 2 of the file comment); the hits are
// primaryHits of each frame with the same camera index and image size.
MotionMap motionBetween(const Scene& from, const std::vector<PrimaryHit>& fromHits, const Scene& to,
                        const std::vector<PrimaryHit>& toHits, int camera, int width, int height);

// Where each pixel of the later frame draws its samples from (step 3 of the file comment).
std::vector<gpu::PixelStream> carriedStreams(const MotionMap& map);

}  // namespace gdpt
