// bench_paths.h — the rays of bench_rays.comp on the CPU, for a tracer other than the kernels
// (gdpt bench's Embree baseline, and the tests that check that baseline against gdpt's own
// traversal): the same random numbers (rng.glsl), camera (camera.glsl), cosine-weighted diffuse
// bounces and ray offsets (sampling.glsl, ray.glsl), so both tracers are given the same paths.
// Header only, no Embree: `trace(origin, direction)` is any closest-hit query returning a
// BenchHit.
#pragma once

#include <cmath>
#include <cstdint>

#include "gdpt_shared.h"
#include "lib/ray.glsl"
#include "lib/rng.glsl"
#include "lib/sampling.glsl"
#include "render/device_scene/camera_ray.h"

namespace gdpt {

// A closest hit as bench_rays.comp uses it: the hit point and the triangle's two edges (their
// cross product is the geometric normal).
struct BenchHit {
    bool hit = false;
    glm::vec3 point{0.0f};
    glm::vec3 e1{0.0f};
    glm::vec3 e2{0.0f};
};

struct BenchPathCount {
    std::uint64_t rays = 0;
    std::uint64_t hits = 0;
};

// bench_rays.comp's main() for pixel (x, y): `spp` samples from sample index `sampleBase`, one
// closest-hit segment each (primary) or up to four (incoherent).
template <class Trace>
BenchPathCount benchPixelPaths(const gpu::SceneConstants& c, std::uint32_t x, std::uint32_t y,
                               std::uint32_t spp, std::uint32_t sampleBase, std::uint32_t seed,
                               bool incoherent, const Trace& trace) {
    BenchPathCount count;
    const std::uint32_t pixel = y * c.width + x;
    for (std::uint32_t s = 0; s < spp; ++s) {
        gpu::Rng rng = gpu::rngInit(pixel, sampleBase + s, seed);
        const glm::vec2 pos = glm::vec2(float(x), float(y)) + gpu::rngNext2(rng);
        glm::vec3 d = cameraRay(c, pos);
        glm::vec3 o = c.camPosition;
        const std::uint32_t segments = incoherent ? 4u : 1u;
        for (std::uint32_t k = 0; k < segments; ++k) {
            const BenchHit h = trace(o, d);
            ++count.rays;
            if (!h.hit) break;
            ++count.hits;
            glm::vec3 n = glm::normalize(glm::cross(h.e1, h.e2));
            if (glm::dot(n, d) > 0.0f) n = -n;
            glm::vec3 t;
            glm::vec3 b;
            gpu::makeBasis(n, t, b);
            d = gpu::toWorld(gpu::sampleCosineHemisphere(gpu::rngNext2(rng)), t, b, n);
            o = gpu::offsetRayOriginScaled(h.point, n, c.sceneRadius);
        }
    }
    return count;
}

}  // namespace gdpt
