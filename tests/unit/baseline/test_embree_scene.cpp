// The Embree baseline (built with -DGDPT_EMBREE=ON) against gdpt's own traversal: two
// independent ray tracers must find the same closest hits on the same triangles, and trace the
// same bench paths, or `gdpt bench`'s ratios would compare different work.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "../bvh/bvh_test_scenes.h"
#include "baseline/bench_paths.h"
#include "baseline/embree_scene.h"
#include "bvh/builder.h"
#include "bvh/traverse_cpu.h"
#include "bvh/wide_bvh.h"

namespace gdpt {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

struct GdptTracer {
    Bvh bvh;
    WideBvh wide;
    std::vector<gpu::TriangleGeom> geoms;
    explicit GdptTracer(const test::Mesh& m)
        : bvh(buildBvh(m.positions, m.triangles)),
          wide(collapseToWide(bvh.nodes)),
          geoms(makeTriangleGeoms(m.positions, m.triangles, bvh.triangleOrder)) {}
};

// Closest hits of random rays: the same triangle, or (at a tie or an edge shared by two
// triangles) the same distance to 1e-5 relative. gdpt's triangle test widens edges by about
// 2^-20 of the distance (kEdgeTolerance in bvh_intersect.glsl) and Embree's does not, so a ray
// grazing an unshared edge may hit in gdpt and miss in Embree (3 in 10^5 on the soup, each at an
// edge: a barycentric coordinate within 1e-4 of 0, found by brute force too); the test allows
// 1 in 10^4.
void compareClosestHits(const test::Mesh& m, uint32_t rays, uint32_t seed) {
    const GdptTracer g(m);
    const EmbreeScene e(m.positions, m.triangles, 2);
    std::mt19937 rng(seed);
    uint32_t hits = 0;
    uint32_t disagree = 0;
    std::string examples;
    for (uint32_t i = 0; i < rays; ++i) {
        const glm::vec3 o = test::uniformInBox(rng, glm::vec3(-1.2f), glm::vec3(1.2f));
        const glm::vec3 d = test::uniformOnSphere(rng);
        const Hit a = traceClosestWideCpu(g.wide.nodes, g.geoms, o, d, 0.0f, 1e30f);
        const EmbreeHit b = e.intersect(o, d, 0.0f, kInf);
        const bool aHit = a.triangle != gpu::kInvalidIndex;
        const bool bHit = b.triangle != gpu::kInvalidIndex;
        hits += aHit ? 1u : 0u;
        bool same = aHit == bHit;
        if (same && aHit) {
            same = g.bvh.triangleOrder[a.triangle] == b.triangle || std::abs(a.t - b.t) <= 1e-5f * b.t;
        }
        if (!same && ++disagree <= 5) {
            examples += "\n  ray " + std::to_string(i) + ": gdpt triangle " +
                        std::to_string(aHit ? g.bvh.triangleOrder[a.triangle] : gpu::kInvalidIndex) + " t " +
                        std::to_string(a.t) + " u " + std::to_string(a.u) + " v " + std::to_string(a.v) +
                        ", Embree triangle " + std::to_string(b.triangle) + " t " + std::to_string(b.t);
        }
    }
    EXPECT_LE(disagree, rays / 10000) << "rays whose closest hits differ:" << examples;
    EXPECT_GT(hits, rays / 10) << "too few hits to compare the tracers";
}

TEST(EmbreeBaseline, SameClosestHitsAsGdptOnASoup) {
    compareClosestHits(test::randomSoup(20000, 0.05f, 31), 100000, 1);
}

TEST(EmbreeBaseline, SameClosestHitsAsGdptOnATerrain) {
    compareClosestHits(test::terrain(100, 32), 100000, 2);
}

// bench_rays.comp's paths through both tracers: the same paths, so the same ray and hit counts
// (up to the rare edge disagreements above, each of which changes one path).
TEST(EmbreeBaseline, BenchPathsTraceTheSameRaysAsGdpt) {
    const test::Mesh m = test::terrain(64, 33);
    const GdptTracer g(m);
    const EmbreeScene e(m.positions, m.triangles, 2);
    // Looking straight down at the terrain (y up, over [-1, 1]^2) from y = 3: every primary
    // ray hits it, and the bounces leave it or hit its slopes.
    gpu::SceneConstants c{};
    c.camPosition = glm::vec3(0.0f, 3.0f, 0.0f);
    c.camForward = glm::vec3(0.0f, -1.0f, 0.0f);
    c.camRight = glm::vec3(1.0f, 0.0f, 0.0f);
    c.camUp = glm::vec3(0.0f, 0.0f, -1.0f);
    c.tanHalfFovY = 0.25f;
    c.width = 48;
    c.height = 32;
    c.aspect = 1.5f;
    c.sceneRadius = 1.5f;
    auto gdptTrace = [&](glm::vec3 o, glm::vec3 d) {
        const Hit h = traceClosestWideCpu(g.wide.nodes, g.geoms, o, d, 0.0f, 1.0f / 0.0f);
        BenchHit b;
        if (h.triangle == gpu::kInvalidIndex) return b;
        const gpu::TriangleGeom& t = g.geoms[h.triangle];
        b.hit = true;
        b.e1 = t.e1;
        b.e2 = t.e2;
        b.point = t.v0 + h.u * t.e1 + h.v * t.e2;
        return b;
    };
    for (const bool incoherent : {false, true}) {
        BenchPathCount expected;
        for (uint32_t y = 0; y < c.height; ++y) {
            for (uint32_t x = 0; x < c.width; ++x) {
                const BenchPathCount p = benchPixelPaths(c, x, y, 2, 0, 7, incoherent, gdptTrace);
                expected.rays += p.rays;
                expected.hits += p.hits;
            }
        }
        const EmbreeScene::RayRun run = e.traceBenchPaths(c, 2, incoherent, 7, 2);
        const double tolerance = 1e-3 * double(expected.rays);
        EXPECT_NEAR(double(run.count.rays), double(expected.rays), tolerance) << "incoherent " << incoherent;
        EXPECT_NEAR(double(run.count.hits), double(expected.hits), tolerance) << "incoherent " << incoherent;
        // Power: the terrain is hit by most primary rays, and incoherent paths bounce.
        EXPECT_GT(expected.hits, expected.rays / 2);
        if (incoherent) {
            EXPECT_GT(expected.rays, uint64_t{c.width} * c.height * 2u);
        }
    }
}

TEST(EmbreeBaseline, ReportsItsBuildTime) {
    const test::Mesh m = test::randomSoup(5000, 0.05f, 34);
    const EmbreeScene e(m.positions, m.triangles, 1);
    EXPECT_GT(e.buildMs(), 0.0);
}

}  // namespace
}  // namespace gdpt
