// bvh_bench.cpp — CPU benchmark used to choose the BvhBuildOptions defaults: builds BVHs of
// procedural scenes (random soup, height-field terrain) of 10k/100k/1M triangles for each
// maxLeafSize x binCount and traces seeded incoherent rays with the CPU closest-hit
// traversal. Prints one JSON object per line. The CPU traversal is only a proxy for the GPU
// one (different memory system and no SIMT divergence), so treat small differences as noise.
//
// Usage: gdpt_bvh_bench [maxTriangles=1000000] [rays=200000] [buildThreads=1]
//                       [traversalCost=1] [intersectCost=1]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "bvh/builder.h"
#include "bvh/traverse_cpu.h"

namespace {

struct Scene {
    std::string name;
    std::vector<glm::vec3> positions;
    std::vector<glm::uvec3> triangles;
};

glm::vec3 uniform3(std::mt19937& rng, float lo, float hi) {
    std::uniform_real_distribution<float> u(lo, hi);
    return glm::vec3(u(rng), u(rng), u(rng));
}

// Random soup in [-1, 1]^3; triangle size shrinks with count so the depth complexity stays
// comparable across sizes (about 20 triangles along a ray through the cube).
Scene soup(uint32_t count) {
    std::mt19937 rng(1);
    Scene s{"soup", {}, {}};
    const float size = 2.0f * std::sqrt(20.0f / float(count));
    for (uint32_t i = 0; i < count; ++i) {
        glm::vec3 c = uniform3(rng, -1.0f, 1.0f);
        for (int k = 0; k < 3; ++k) {
            s.positions.push_back(c + 0.5f * size * uniform3(rng, -1.0f, 1.0f));
        }
        s.triangles.emplace_back(3 * i, 3 * i + 1, 3 * i + 2);
    }
    return s;
}

// Height-field terrain over [-1, 1]^2 with count/2 quads.
Scene terrain(uint32_t count) {
    const auto n = static_cast<uint32_t>(std::sqrt(double(count) / 2.0));
    Scene s{"terrain", {}, {}};
    for (uint32_t j = 0; j <= n; ++j) {
        for (uint32_t i = 0; i <= n; ++i) {
            float x = -1.0f + 2.0f * float(i) / float(n);
            float z = -1.0f + 2.0f * float(j) / float(n);
            float y =
                0.3f * std::sin(5.0f * x) * std::cos(4.0f * z) + 0.05f * std::sin(37.0f * x + 11.0f * z);
            s.positions.emplace_back(x, y, z);
        }
    }
    for (uint32_t j = 0; j < n; ++j) {
        for (uint32_t i = 0; i < n; ++i) {
            uint32_t a = j * (n + 1) + i;
            s.triangles.emplace_back(a, a + 1, a + n + 2);
            s.triangles.emplace_back(a, a + n + 2, a + n + 1);
        }
    }
    return s;
}

}  // namespace

int main(int argc, char** argv) {
    const auto maxTriangles = static_cast<uint32_t>(argc > 1 ? std::atol(argv[1]) : 1000000);
    const auto rayCount = static_cast<uint32_t>(argc > 2 ? std::atol(argv[2]) : 200000);
    const auto buildThreads = static_cast<uint32_t>(argc > 3 ? std::atol(argv[3]) : 1);
    const float traversalCost = argc > 4 ? std::strtof(argv[4], nullptr) : 1.0f;
    const float intersectCost = argc > 5 ? std::strtof(argv[5], nullptr) : 1.0f;
    for (uint32_t size : {10000u, 100000u, 1000000u}) {
        if (size > maxTriangles) {
            continue;
        }
        for (const Scene& scene : {soup(size), terrain(size)}) {
            // Incoherent rays: origins in [-1.2, 1.2]^3, directions uniform on the sphere.
            std::mt19937 rng(7);
            std::vector<glm::vec3> origins(rayCount);
            std::vector<glm::vec3> dirs(rayCount);
            for (uint32_t i = 0; i < rayCount; ++i) {
                origins[i] = uniform3(rng, -1.2f, 1.2f);
                glm::vec3 d;
                do {
                    d = uniform3(rng, -1.0f, 1.0f);
                } while (glm::dot(d, d) > 1.0f || glm::dot(d, d) < 1e-4f);
                dirs[i] = glm::normalize(d);
            }
            for (uint32_t leaf : {1u, 2u, 4u, 8u}) {
                for (uint32_t bins : {8u, 16u, 32u}) {
                    gdpt::BvhBuildOptions opt;
                    opt.maxLeafSize = leaf;
                    opt.binCount = bins;
                    opt.buildThreads = buildThreads;
                    opt.traversalCost = traversalCost;
                    opt.intersectCost = intersectCost;
                    const gdpt::Bvh bvh = gdpt::buildBvh(scene.positions, scene.triangles, opt);
                    const auto geoms =
                        gdpt::makeTriangleGeoms(scene.positions, scene.triangles, bvh.triangleOrder);
                    uint64_t visits = 0;
                    uint32_t hits = 0;
                    const auto t0 = std::chrono::steady_clock::now();
                    for (uint32_t i = 0; i < rayCount; ++i) {
                        gdpt::Hit h =
                            gdpt::traceClosestCpu(bvh.nodes, geoms, origins[i], dirs[i], 0.0f, 1e30f);
                        hits += h.triangle != gdpt::gpu::kInvalidIndex ? 1u : 0u;
                        visits += gdpt::lastTraversalNodeVisits();
                    }
                    const double sec =
                        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
                    std::printf(
                        "{\"scene\":\"%s\",\"triangles\":%zu,\"maxLeafSize\":%u,\"binCount\":%u,\"ct\":%.2f,"
                        "\"buildMs\":%.1f,\"sahCost\":%.2f,\"nodes\":%u,\"maxDepth\":%u,"
                        "\"mraysPerS\":%.3f,\"nodesPerRay\":%.1f,\"hitFraction\":%.3f}\n",
                        scene.name.c_str(), scene.triangles.size(), leaf, bins, double(traversalCost),
                        bvh.stats.buildMs, double(bvh.stats.sahCost), bvh.stats.nodeCount, bvh.stats.maxDepth,
                        double(rayCount) / sec * 1e-6, double(visits) / double(rayCount),
                        double(hits) / double(rayCount));
                    std::fflush(stdout);
                }
            }
        }
    }
    return 0;
}
