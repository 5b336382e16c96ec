// temporal_reconnect.h — temporal differences between two frames of an animation by the
// reconnection shift (tgpt_reconnect.comp; docs/animation.md, "The reconnection shift"): paths
// of each frame with offset paths in the other, reconnected at the first vertex and carried by
// the animation from there, combined over the two directions by multiple importance sampling.
#pragma once

#include <cstdint>

#include "gdpt_shared.h"
#include "image/image.h"
#include "integrator/motion_map.h"
#include "render/device_scene/scene_gpu.h"
#include "scene/scene.h"

namespace gdpt {

namespace vk {
class Context;
}

struct TemporalReconnectOptions {
    std::uint32_t spp = 8;    // camera samples per pixel in each direction
    std::uint32_t seed = 0;   // direction 0's seed; direction 1 uses seed + 0x9E3779B9
    std::uint32_t flags = 0;  // gpu::kTemporalFlag* (tests)
};

struct TemporalDifferences {
    // At frame a's pixels p with a partner q = map.partner[p]: the estimate of
    // I_b(q) − I_a(p) without the emission the camera sees directly (G-PT's primal's difference)
    // and the variance of that mean; 0 elsewhere.
    Image dt, varDt;
    // The base paths' mean radiance (the same part of the image) per frame at its own pixels with
    // a partner, and its variance (an independent estimate of each frame, for tests).
    Image baseA, varBaseA, baseB, varBaseB;
    // Both directions': rays, base paths whose camera ray hit a surface (pairs), those of them whose
    // shift failed at the first vertex, and samples dropped as NaN/Inf (counted as zero).
    std::uint64_t rays = 0, pairs = 0, failures = 0, nanSamples = 0;
    double seconds = 0.0;    // set-up, sampling and read-back
    bool cancelled = false;  // an interrupt stopped the pass (nothing else is set)
};

// The differences from frame `a` to frame `b` (the same triangles moved) along `map`
// (motionBetween(a, ..., b, ...)), the scenes seen as `sceneOptions` says (size, camera, depth).
// Throws gdpt::Error for frames whose triangles differ (SceneGpu's frame pair).
TemporalDifferences reconnectDifferences(const vk::Context& ctx, const Scene& a, const Scene& b,
                                         const MotionMap& map, const SceneGpuOptions& sceneOptions,
                                         const TemporalReconnectOptions& options);

}  // namespace gdpt
