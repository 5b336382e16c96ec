// motion_map.cpp — motion between frames and the streams it carries (motion_map.h).
#include "integrator/motion_map.h"

#include <cmath>
#include <limits>

#include "bvh/builder.h"
#include "bvh/traverse_cpu.h"
#include "poisson/poisson_spacetime.h"
#include "render/device_scene/scene_gpu.h"
#include "render/device_scene/scene_spec.h"
#include "util/error.h"
#include "util/parallel.h"

namespace gdpt {
namespace {

gpu::SceneConstants cameraConstants(const Scene& scene, int camera, int width, int height) {
    gpu::SceneConstants c{};
    setCamera(c, renderCamera(scene, camera), width, height);
    return c;
}

// camera.glsl's cameraRay for a continuous pixel position.
glm::vec3 cameraRay(const gpu::SceneConstants& c, glm::vec2 pixelPos) {
    const float nx = 2.0f * pixelPos.x / float(c.width) - 1.0f;
    const float ny = 1.0f - 2.0f * pixelPos.y / float(c.height);
    return glm::normalize(c.camForward + nx * c.tanHalfFovY * c.aspect * c.camRight +
                          ny * c.tanHalfFovY * c.camUp);
}

// The continuous pixel position at which the camera sees a point in direction d from its
// position (the inverse of cameraRay), or false if d points behind the camera.
bool project(const gpu::SceneConstants& c, glm::vec3 d, glm::vec2& pixelPos) {
    const float z = glm::dot(d, c.camForward);
    if (!(z > 0.0f)) return false;
    const float nx = glm::dot(d, c.camRight) / (z * c.tanHalfFovY * c.aspect);
    const float ny = glm::dot(d, c.camUp) / (z * c.tanHalfFovY);
    pixelPos = glm::vec2(0.5f * (nx + 1.0f) * float(c.width), 0.5f * (1.0f - ny) * float(c.height));
    return std::isfinite(pixelPos.x) && std::isfinite(pixelPos.y);
}

// Where a hit lies in `scene` (its triangle's vertices there), as the direction from the
// camera and the distance to it; a miss is its direction at infinite distance.
glm::vec3 carried(const Scene& scene, const gpu::SceneConstants& c, const PrimaryHit& h, float& distance) {
    if (h.triangle == gpu::kInvalidIndex) {
        distance = std::numeric_limits<float>::infinity();
        return h.direction;
    }
    const glm::uvec3 t = scene.triangles[h.triangle];
    const glm::vec3 x =
        (1.0f - h.u - h.v) * scene.positions[t.x] + h.u * scene.positions[t.y] + h.v * scene.positions[t.z];
    const glm::vec3 d = x - c.camPosition;
    distance = glm::length(d);
    return d;
}

// The pixel (index) that a hit carried into `scene` lands in, or false off the image; `pos`
// the continuous position.
bool landsIn(const Scene& scene, const gpu::SceneConstants& c, const PrimaryHit& h, std::uint32_t& pixel,
             float& distance, glm::ivec2& at, glm::vec2& pos) {
    if (!project(c, carried(scene, c, h, distance), pos)) return false;
    if (!(pos.x >= 0.0f && pos.y >= 0.0f && pos.x < float(c.width) && pos.y < float(c.height))) return false;
    at = glm::ivec2(int(pos.x), int(pos.y));
    pixel = std::uint32_t(at.y) * c.width + std::uint32_t(at.x);
    return true;
}

}  // namespace

std::vector<PrimaryHit> primaryHits(const Scene& scene, int camera, int width, int height,
                                    std::uint32_t threads) {
    const gpu::SceneConstants c = cameraConstants(scene, camera, width, height);
    const SceneBvh bvh = buildSceneBvh(scene);
    const std::vector<gpu::TriangleGeom> geoms =
        makeTriangleGeoms(scene.positions, scene.triangles, bvh.binary.triangleOrder);
    std::vector<PrimaryHit> hits(std::size_t(width) * std::size_t(height));
    parallelFor(defaultThreads(threads), std::size_t(height), [&](std::size_t y) {
        for (int x = 0; x < width; ++x) {
            PrimaryHit& out = hits[y * std::size_t(width) + std::size_t(x)];
            out.direction = cameraRay(c, glm::vec2(float(x) + 0.5f, float(y) + 0.5f));
            const gpu::Hit h = traceClosestWideCpu(bvh.wide.nodes, geoms, c.camPosition, out.direction, 0.0f,
                                                   std::numeric_limits<float>::infinity());
            if (h.triangle == gpu::kInvalidIndex) continue;
            out.triangle = bvh.binary.triangleOrder[h.triangle];
            out.u = h.u;
            out.v = h.v;
        }
    });
    return hits;
}

MotionMap motionBetween(const Scene& from, const std::vector<PrimaryHit>& fromHits, const Scene& to,
                        const std::vector<PrimaryHit>& toHits, int camera, int width, int height) {
    const std::size_t np = std::size_t(width) * std::size_t(height);
    GDPT_CHECK(fromHits.size() == np && toHits.size() == np);
    MotionMap map;
    if (from.triangles != to.triangles || from.positions.size() != to.positions.size()) {
        map.sameTopology = false;
        map.partner.resize(np);
        for (std::size_t i = 0; i < np; ++i) map.partner[i] = std::uint32_t(i);
        map.partnered = np;
        return map;
    }
    const gpu::SceneConstants cFrom = cameraConstants(from, camera, width, height);
    const gpu::SceneConstants cTo = cameraConstants(to, camera, width, height);
    // Forward: each pixel's landing pixel in `to` and its distance there.
    std::vector<std::uint32_t> lands(np, kNoTemporalPartner);
    std::vector<float> distance(np, 0.0f);
    map.subpixel.assign(np, glm::vec2(0.0f));
    parallelRanges(defaultThreads(), np, 4096, [&](std::size_t begin, std::size_t end) {
        for (std::size_t p = begin; p < end; ++p) {
            glm::ivec2 at;
            glm::vec2 pos;
            if (!landsIn(to, cTo, fromHits[p], lands[p], distance[p], at, pos)) {
                lands[p] = kNoTemporalPartner;
                continue;
            }
            // Clamped: a float position just below a pixel's far edge may round onto it.
            map.subpixel[p] = glm::clamp(pos - glm::vec2(at) - 0.5f, glm::vec2(-0.5f), glm::vec2(0.49999f));
        }
    });
    // The nearest pixel of `from` landing in each pixel of `to` (the lowest index among equals).
    std::vector<std::uint32_t> winner(np, kNoTemporalPartner);
    for (std::size_t p = 0; p < np; ++p) {
        const std::uint32_t q = lands[p];
        if (q == kNoTemporalPartner) continue;
        if (winner[q] == kNoTemporalPartner || distance[p] < distance[winner[q]])
            winner[q] = std::uint32_t(p);
    }
    // Backward: the winner is kept if q's own hit, carried back, lands within a pixel of it.
    map.partner.assign(np, kNoTemporalPartner);
    for (std::size_t q = 0; q < np; ++q) {
        const std::uint32_t p = winner[q];
        if (p == kNoTemporalPartner) continue;
        std::uint32_t back;
        float d;
        glm::ivec2 at;
        glm::vec2 pos;
        if (!landsIn(from, cFrom, toHits[q], back, d, at, pos)) continue;
        const glm::ivec2 source(int(p % std::uint32_t(width)), int(p / std::uint32_t(width)));
        if (std::abs(at.x - source.x) > 1 || std::abs(at.y - source.y) > 1) continue;
        map.partner[p] = std::uint32_t(q);
        ++map.partnered;
    }
    return map;
}

std::vector<gpu::PixelStream> carriedStreams(const MotionMap& map) {
    const std::size_t np = map.partner.size();
    GDPT_CHECK(np < std::size_t(kNoTemporalPartner) / 2);
    GDPT_CHECK(map.subpixel.empty() || map.subpixel.size() == np);
    std::vector<gpu::PixelStream> streams(np);
    for (std::size_t q = 0; q < np; ++q) streams[q] = {std::uint32_t(np + q), 0u};
    for (std::size_t p = 0; p < np; ++p) {
        if (map.partner[p] == kNoTemporalPartner) continue;
        const glm::vec2 d = map.subpixel.empty() ? glm::vec2(0.0f) : map.subpixel[p];
        // The shift fract(δ) in [0, 1) in 1/65536 pixels (gpt_shared.h); a δ a rounding below 0
        // is no shift.
        const glm::vec2 s = d - glm::floor(d);
        const auto fixed = [](float v) { return std::uint32_t(std::lround(double(v) * 65536.0)) & 0xFFFFu; };
        streams[map.partner[p]] = {std::uint32_t(p), fixed(s.x) | (fixed(s.y) << 16)};
    }
    return streams;
}

}  // namespace gdpt
