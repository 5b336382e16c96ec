// embree_scene.h — the independent ray tracer `gdpt bench` compares against (built only with
// -DGDPT_EMBREE=ON; Debian's libembree-dev): an Embree 3 scene of the same triangles
// (Wald et al. 2014, "Embree: A Kernel Framework for Efficient CPU Ray Tracing", ACM TOG 33(4)),
// its BVH build time, and bench_rays.comp's rays (bench_paths.h) traced on the CPU with
// rtcIntersect1 on every usable core.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <memory>
#include <vector>

#include "baseline/bench_paths.h"
#include "gdpt_shared.h"

namespace gdpt {

struct EmbreeHit {
    float t = 0.0f;
    std::uint32_t triangle = gpu::kInvalidIndex;  // index into the triangles given; invalid on a miss
    float u = 0.0f;                               // barycentric weight of the second vertex
    float v = 0.0f;                               // barycentric weight of the third vertex
};

class EmbreeScene {
public:
    // Copies the triangles into an Embree scene and builds its BVH (RTC_BUILD_QUALITY_MEDIUM,
    // Embree's default: binned SAH) on `threads` threads; throws Error with Embree's message.
    // traceBenchPaths reads `positions` and `triangles` again: they must outlive the scene.
    EmbreeScene(const std::vector<glm::vec3>& positions, const std::vector<glm::uvec3>& triangles,
                std::uint32_t threads);
    ~EmbreeScene();
    EmbreeScene(const EmbreeScene&) = delete;
    EmbreeScene& operator=(const EmbreeScene&) = delete;

    // Wall time of rtcCommitScene (the BVH build), milliseconds.
    [[nodiscard]] double buildMs() const;

    // Closest hit with tMin <= t <= tMax.
    [[nodiscard]] EmbreeHit intersect(glm::vec3 origin, glm::vec3 direction, float tMin, float tMax) const;

    // bench_rays.comp's paths for every pixel of `constants` (spp samples from sample 0, `seed`),
    // traced on `threads` threads, rows handed out in order (util/parallel.h).
    struct RayRun {
        BenchPathCount count;
        double seconds = 0.0;     // wall time
        double cpuSeconds = 0.0;  // process CPU time meanwhile
    };
    [[nodiscard]] RayRun traceBenchPaths(const gpu::SceneConstants& constants, std::uint32_t spp,
                                         bool incoherent, std::uint32_t seed, std::uint32_t threads) const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace gdpt
