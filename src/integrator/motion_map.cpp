// motion_map.cpp — motion between frames and the streams it carries (motion_map.h).
#include "integrator/motion_map.h"

#include <cmath>
#include <limits>
#include <optional>

#include "bvh/builder.h"
#include "bvh/traverse_cpu.h"
#include "poisson/poisson_spacetime.h"
#include "render/device_scene/camera_ray.h"
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

// Where a hit carried into `scene` lands in its image.
struct Landing {
    glm::vec2 position;  // continuous pixel position
    glm::ivec2 at;       // the pixel it lies in
    float distance;      // from the camera (infinite for a miss)
    [[nodiscard]] std::uint32_t pixel(std::uint32_t width) const {
        return std::uint32_t(at.y) * width + std::uint32_t(at.x);
    }
};

// The landing of a hit carried into `scene`, or nothing if it is behind the camera or off the
// image.
std::optional<Landing> landing(const Scene& scene, const gpu::SceneConstants& c, const PrimaryHit& h) {
    Landing l{};
    if (!projectToPixel(c, carried(scene, c, h, l.distance), l.position)) return std::nullopt;
    const glm::vec2 pos = l.position;
    if (!(pos.x >= 0.0f && pos.y >= 0.0f && pos.x < float(c.width) && pos.y < float(c.height)))
        return std::nullopt;
    l.at = glm::ivec2(int(pos.x), int(pos.y));
    return l;
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
            const std::optional<Landing> l = landing(to, cTo, fromHits[p]);
            if (!l) continue;
            lands[p] = l->pixel(cTo.width);
            distance[p] = l->distance;
            // Clamped: a float position just below a pixel's far edge may round onto it.
            map.subpixel[p] =
                glm::clamp(l->position - glm::vec2(l->at) - 0.5f, glm::vec2(-0.5f), glm::vec2(0.49999f));
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
        const std::optional<Landing> back = landing(from, cFrom, toHits[q]);
        if (!back) continue;
        const glm::ivec2 source(int(p % std::uint32_t(width)), int(p / std::uint32_t(width)));
        if (std::abs(back->at.x - source.x) > 1 || std::abs(back->at.y - source.y) > 1) continue;
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
