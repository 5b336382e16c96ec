// test_bvh.cpp — BVH builder and CPU traversal: closest/any hit against brute force on
// seeded procedural scenes, structural invariants, depth cap, watertightness, determinism.
// Scenes are small (400-800 triangles) because every ray is also traced by brute force.
//
// Tolerance: the BVH traversal and the brute-force loop call the same ray/triangle function
// on bit-identical TriangleGeom data, so a triangle's t does not depend on the loop. The
// brute force returns the minimum t over all triangles; if the BVH tested the brute-force
// winner it accepted it (its running tMax was >= that t), so its own t is <= that minimum.
// Hence the two t must be EXACTLY equal unless the BVH culled the closest triangle, and
// differing ids are legitimate only for exact ties (duplicated / coplanar triangles). The
// "few ulps" tolerance applies only between CPU and GPU (division and dot rounding).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "bvh/builder.h"
#include "bvh/traverse_cpu.h"
#include "bvh/wide_bvh.h"
#include "bvh_test_scenes.h"

namespace gdpt {
namespace {

using test::Mesh;

// Many zero-area (repeated vertex, collinear), coplanar overlapping and duplicated triangles.
Mesh degenerateScene(uint32_t seed) {
    std::mt19937 rng(seed);
    Mesh m = test::randomSoup(100, 0.2f, seed + 1);
    for (int i = 0; i < 60; ++i) {
        glm::vec3 a = test::uniformInBox(rng, glm::vec3(-1.0f), glm::vec3(1.0f));
        glm::vec3 b = test::uniformInBox(rng, glm::vec3(-1.0f), glm::vec3(1.0f));
        m.addTriangle(a, a, b);               // repeated vertex
        m.addTriangle(a, 0.5f * (a + b), b);  // collinear
        m.addTriangle(a, a, a);               // a point
    }
    for (int i = 0; i < 100; ++i) {  // overlapping coplanar triangles in the plane z = 0.25
        glm::vec3 c = test::uniformInBox(rng, glm::vec3(-1.0f, -1.0f, 0.25f), glm::vec3(1.0f, 1.0f, 0.25f));
        glm::vec3 d1 = test::uniformInBox(rng, glm::vec3(-0.3f, -0.3f, 0.0f), glm::vec3(0.3f, 0.3f, 0.0f));
        glm::vec3 d2 = test::uniformInBox(rng, glm::vec3(-0.3f, -0.3f, 0.0f), glm::vec3(0.3f, 0.3f, 0.0f));
        m.addTriangle(c, c + d1, c + d2);
    }
    const size_t original = m.triangles.size();
    for (size_t i = 0; i < original; i += 3) {  // exact duplicates sharing vertex indices
        m.triangles.push_back(m.triangles[i]);
    }
    return m;
}

// Axis-aligned quads of zero thickness in planes x = k/4 and z = k/4 (boxes are flat).
Mesh thinAxisAlignedScene() {
    Mesh m;
    for (int k = -2; k <= 2; ++k) {
        float c = 0.25f * float(k);
        for (int i = 0; i < 5; ++i) {
            for (int j = 0; j < 5; ++j) {
                float a0 = -0.75f + 0.25f * float(i);
                float b0 = -0.75f + 0.25f * float(j);
                float a1 = a0 + 0.25f;
                float b1 = b0 + 0.25f;
                m.addTriangle({a0, b0, c}, {a1, b0, c}, {a1, b1, c});
                m.addTriangle({a0, b0, c}, {a1, b1, c}, {a0, b1, c});
                m.addTriangle({c, a0, b0}, {c, a1, b0}, {c, a1, b1});
                m.addTriangle({c, a0, b0}, {c, a1, b1}, {c, a0, b1});
            }
        }
    }
    return m;
}

std::vector<uint32_t> identityOrder(size_t n) {
    std::vector<uint32_t> order(n);
    for (size_t i = 0; i < n; ++i) {
        order[i] = static_cast<uint32_t>(i);
    }
    return order;
}

struct Ray {
    glm::vec3 orig;
    glm::vec3 dir;
    float tMax;
};

// Half the rays are uniform (origin in the enlarged bounds, direction on the sphere); half
// aim at a random point of a random triangle, a quarter of those exactly at an edge or a
// vertex; one in eight has an axis-aligned direction (zero components).
std::vector<Ray> makeRays(const Mesh& m, uint32_t count, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    glm::vec3 lo(1e30f);
    glm::vec3 hi(-1e30f);
    for (const glm::vec3& p : m.positions) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    glm::vec3 pad = 0.25f * (hi - lo) + glm::vec3(0.1f);
    std::vector<Ray> rays(count);
    for (uint32_t i = 0; i < count; ++i) {
        Ray& r = rays[i];
        r.orig = test::uniformInBox(rng, lo - pad, hi + pad);
        r.tMax = 1e30f;
        const uint32_t kind = i % 8;
        if (kind < 4 || m.triangles.empty()) {
            r.dir = test::uniformOnSphere(rng);
        } else if (kind < 7) {
            const glm::uvec3 t = m.triangles[rng() % m.triangles.size()];
            float b1 = u01(rng);
            float b2 = u01(rng);
            if (b1 + b2 > 1.0f) {
                b1 = 1.0f - b1;
                b2 = 1.0f - b2;
            }
            if (kind == 6) {  // on an edge (b2 = 0) or at a vertex
                b2 = 0.0f;
                b1 = (rng() % 4 == 0) ? 0.0f : b1;
            }
            glm::vec3 p0 = m.positions[t.x];
            glm::vec3 target = p0 + b1 * (m.positions[t.y] - p0) + b2 * (m.positions[t.z] - p0);
            r.dir = target - r.orig;
            if (rng() % 2 == 0) {
                r.tMax = 0.5f + u01(rng);  // a segment that may end before the target
            }
        } else {
            r.dir = glm::vec3(0.0f);
            r.dir[static_cast<int>(rng() % 3)] = (rng() % 2 == 0) ? 1.0f : -1.0f;
        }
    }
    return rays;
}

// Walks the tree and checks every structural invariant of gdpt_shared.h and buildBvh.
void checkStructure(const Mesh& m, const Bvh& bvh, uint32_t leafLimit) {
    const size_t n = m.triangles.size();
    ASSERT_EQ(bvh.triangleOrder.size(), n);
    std::vector<int> seenOrder(n, 0);
    for (uint32_t t : bvh.triangleOrder) {
        ASSERT_LT(t, n);
        ASSERT_EQ(seenOrder[t]++, 0) << "triangleOrder is not a permutation";
    }
    ASSERT_FALSE(bvh.nodes.empty());
    ASSERT_EQ(bvh.stats.nodeCount, bvh.nodes.size());
    std::vector<int> nodeSeen(bvh.nodes.size(), 0);
    std::vector<int> leafRef(n, 0);
    uint32_t leaves = 0;
    uint32_t maxDepth = 0;
    struct Item {
        uint32_t node;
        uint32_t depth;
        glm::vec3 lo;
        glm::vec3 hi;
    };
    std::vector<Item> todo{{0, 0, glm::vec3(-1e38f), glm::vec3(1e38f)}};
    while (!todo.empty()) {
        Item it = todo.back();
        todo.pop_back();
        ASSERT_LT(it.node, bvh.nodes.size());
        ASSERT_EQ(nodeSeen[it.node]++, 0) << "node reached twice";
        const gpu::BvhNode& nd = bvh.nodes[it.node];
        for (int side = 0; side < 2; ++side) {
            const glm::vec3 lo = side == 0 ? nd.lmin : nd.rmin;
            const glm::vec3 hi = side == 0 ? nd.lmax : nd.rmax;
            const uint32_t index = side == 0 ? nd.left : nd.right;
            const uint32_t count = side == 0 ? nd.leftCount : nd.rightCount;
            if (index == gpu::kInvalidIndex) {  // absent child: only at the root
                EXPECT_EQ(it.node, 0u);
                EXPECT_EQ(count, 0u);
                EXPECT_GT(lo.x, hi.x) << "absent child must have an empty box";
                continue;
            }
            // Nested boxes: a child box lies within its parent's box.
            EXPECT_TRUE(glm::all(glm::greaterThanEqual(lo, it.lo)) &&
                        glm::all(glm::lessThanEqual(hi, it.hi)));
            const uint32_t depth = it.depth + 1;
            EXPECT_LE(depth, gpu::kBvhMaxDepth);
            if (count == 0) {
                todo.push_back({index, depth, lo, hi});
                continue;
            }
            ++leaves;
            maxDepth = std::max(maxDepth, depth);
            EXPECT_LE(count, leafLimit);
            ASSERT_LE(uint64_t{index} + count, n);
            for (uint32_t i = index; i < index + count; ++i) {
                ++leafRef[i];
                const glm::uvec3 t = m.triangles[bvh.triangleOrder[i]];
                glm::vec3 tlo;
                glm::vec3 thi;
                triangleBounds(m.positions[t.x], m.positions[t.y], m.positions[t.z], tlo, thi);
                EXPECT_TRUE(glm::all(glm::lessThanEqual(lo, tlo)) && glm::all(glm::greaterThanEqual(hi, thi)))
                    << "leaf box does not contain triangle " << bvh.triangleOrder[i];
            }
        }
    }
    for (size_t i = 0; i < n; ++i) {
        ASSERT_EQ(leafRef[i], 1) << "leaf position " << i << " referenced " << leafRef[i];
    }
    for (size_t i = 0; i < nodeSeen.size(); ++i) {
        ASSERT_EQ(nodeSeen[i], 1) << "node " << i << " unreachable";
    }
    EXPECT_EQ(bvh.stats.leafCount, leaves);
    EXPECT_EQ(bvh.stats.maxDepth, maxDepth);
}

// The wide tree: every wide node reachable once, every triangle in exactly one leaf slot
// (the binary tree's leaf ranges, so the leaf count matches), each triangle inside the
// decoded (quantised) box of every slot on its path from the root, and the stack bound
// within the kernels' stack.
void checkWideStructure(const Mesh& m, const Bvh& bvh, const WideBvh& wide) {
    std::vector<int> seen(m.triangles.size(), 0);
    std::vector<int> nodeSeen(wide.nodes.size(), 0);
    uint32_t leaves = 0;
    const auto contains = [](const WideChildBox& b, const glm::vec3& p) {
        return p.x >= b.min.x && p.y >= b.min.y && p.z >= b.min.z && p.x <= b.max.x && p.y <= b.max.y &&
               p.z <= b.max.z;
    };
    struct Visit {
        uint32_t node;
        std::vector<WideChildBox> ancestors;  // decoded boxes of the slots leading here
    };
    std::vector<Visit> todo = {{0, {}}};
    while (!todo.empty()) {
        const Visit visit = todo.back();
        todo.pop_back();
        const uint32_t ni = visit.node;
        ASSERT_LT(ni, wide.nodes.size());
        ++nodeSeen[ni];
        const gpu::BvhWideNode& n = wide.nodes[ni];
        const glm::uvec4 count = gpu::wideCounts(n);
        for (glm::length_t k = 0; k < 4; ++k) {
            if (n.child[k] == gpu::kInvalidIndex) continue;
            std::vector<WideChildBox> path = visit.ancestors;
            path.push_back(wideChildBox(n, k));
            if (count[k] > 0) {
                ++leaves;
                for (uint32_t i = n.child[k]; i < n.child[k] + count[k]; ++i) {
                    ASSERT_LT(i, seen.size());
                    const uint32_t orig = bvh.triangleOrder[i];
                    ++seen[orig];
                    for (const WideChildBox& b : path)
                        for (int c = 0; c < 3; ++c)
                            EXPECT_TRUE(contains(b, m.positions[m.triangles[orig][c]]))
                                << "triangle " << orig << " outside a decoded box on its path";
                }
            } else {
                todo.push_back({n.child[k], path});
            }
        }
    }
    for (size_t i = 0; i < seen.size(); ++i) ASSERT_EQ(seen[i], 1) << "triangle " << i;
    for (size_t i = 0; i < nodeSeen.size(); ++i)
        ASSERT_EQ(nodeSeen[i], 1) << "wide node " << i << " unreachable";
    EXPECT_EQ(leaves, bvh.stats.leafCount);
    EXPECT_LE(wide.maxStack, gpu::kBvhWideStackSize);
    EXPECT_LE(wide.maxDepth, bvh.stats.maxDepth);
    if (bvh.stats.leafCount > 4) {
        EXPECT_LT(wide.nodes.size(), bvh.nodes.size()) << "collapsing should merge nodes";
    }
}

// Closest and any hit of the BVH against brute force over the triangles in ORIGINAL order
// (so triangleOrder and makeTriangleGeoms are checked as well).
void compareWithBruteForce(const Mesh& m, const BvhBuildOptions& opt, uint32_t rayCount, uint32_t seed) {
    const Bvh bvh = buildBvh(m.positions, m.triangles, opt);
    checkStructure(m, bvh, std::min(opt.maxLeafSize, gpu::kMaxLeafTriangles));
    const auto leafGeoms = makeTriangleGeoms(m.positions, m.triangles, bvh.triangleOrder);
    const auto origGeoms = makeTriangleGeoms(m.positions, m.triangles, identityOrder(m.triangles.size()));
    const std::vector<Ray> rays = makeRays(m, rayCount, seed);
    const WideBvh wide = collapseToWide(bvh.nodes);
    checkWideStructure(m, bvh, wide);
    uint32_t hits = 0;
    uint32_t failures = 0;
    for (const Ray& r : rays) {
        const Hit f = traceClosestBruteForce(origGeoms, r.orig, r.dir, 0.0f, r.tMax);
        const bool anyF = traceAnyBruteForce(origGeoms, r.orig, r.dir, 0.0f, r.tMax);
        // The binary tree, then the four-wide tree the kernels traverse: the same checks.
        for (int tree = 0; tree < 2; ++tree) {
            const Hit b = tree == 0 ? traceClosestCpu(bvh.nodes, leafGeoms, r.orig, r.dir, 0.0f, r.tMax)
                                    : traceClosestWideCpu(wide.nodes, leafGeoms, r.orig, r.dir, 0.0f, r.tMax);
            const bool anyB = tree == 0 ? traceAnyCpu(bvh.nodes, leafGeoms, r.orig, r.dir, 0.0f, r.tMax)
                                        : traceAnyWideCpu(wide.nodes, leafGeoms, r.orig, r.dir, 0.0f, r.tMax);
            bool ok = (b.triangle == gpu::kInvalidIndex) == (f.triangle == gpu::kInvalidIndex) &&
                      anyB == anyF && anyF == (f.triangle != gpu::kInvalidIndex);
            if (ok && f.triangle != gpu::kInvalidIndex) {
                ++hits;
                ok = b.t == f.t;  // exact, see the file comment
                if (ok && bvh.triangleOrder[b.triangle] != f.triangle) {
                    // A tie: the BVH's triangle alone must give the same t.
                    float t = r.tMax;
                    float u;
                    float v;
                    ok =
                        intersectTriangleCpu(leafGeoms[b.triangle], r.orig, r.dir, 0.0f, t, u, v) && t == f.t;
                } else if (ok) {
                    ok = b.u == f.u && b.v == f.v;
                }
            }
            if (!ok && ++failures <= 5) {
                ADD_FAILURE() << (tree == 0 ? "binary" : "wide") << " ray o=(" << r.orig.x << "," << r.orig.y
                              << "," << r.orig.z << ") d=(" << r.dir.x << "," << r.dir.y << "," << r.dir.z
                              << ") bvh tri " << b.triangle << " t " << b.t << " brute tri " << f.triangle
                              << " t " << f.t << " any " << anyB << "/" << anyF;
            }
        }
    }
    EXPECT_EQ(failures, 0u);
    // The test is only meaningful if a good share of rays hit something.
    if (!m.triangles.empty()) {
        EXPECT_GT(hits, 2 * (rayCount / 10)) << "too few hits to exercise the traversal (counted per tree)";
    }
}

const BvhBuildOptions kDeepOptions{1, 4, 1.0f, 1.0f, gpu::kBvhMaxDepth,
                                   1};  // tiny leaves, few bins: deep tree

TEST(BvhTraversal, RandomSoupMatchesBruteForce) {
    const Mesh m = test::randomSoup(400, 0.25f, 11);
    compareWithBruteForce(m, BvhBuildOptions{}, 100000, 1);
    compareWithBruteForce(m, kDeepOptions, 5000, 2);
}

TEST(BvhTraversal, TerrainMatchesBruteForce) {
    const Mesh m = test::terrain(14, 12);
    compareWithBruteForce(m, BvhBuildOptions{}, 100000, 3);
    compareWithBruteForce(m, kDeepOptions, 5000, 4);
}

TEST(BvhTraversal, DegenerateCoplanarDuplicatesMatchBruteForce) {
    const Mesh m = degenerateScene(13);
    compareWithBruteForce(m, BvhBuildOptions{}, 100000, 5);
    compareWithBruteForce(m, kDeepOptions, 5000, 6);
}

TEST(BvhTraversal, ThinAxisAlignedMatchesBruteForce) {
    const Mesh m = thinAxisAlignedScene();
    compareWithBruteForce(m, BvhBuildOptions{}, 100000, 7);
    compareWithBruteForce(m, kDeepOptions, 5000, 8);
}

// The wide tree's 8-bit child boxes (BvhWideNode) where their rounding is most at risk: a
// small detailed scene far from the origin (origin + q·scale rounds at a coarse float
// spacing) and a huge one (large scale exponents; 1e10 keeps the triangle test's cubic
// products within float range).
Mesh transformed(Mesh m, float scale, glm::vec3 offset) {
    for (glm::vec3& p : m.positions) p = p * scale + offset;
    return m;
}

TEST(BvhTraversal, SmallSceneFarFromOriginMatchesBruteForce) {
    const Mesh m = transformed(test::randomSoup(300, 0.25f, 21), 1e-2f, glm::vec3(3.0e4f, -7.5e4f, 1.25e5f));
    compareWithBruteForce(m, BvhBuildOptions{}, 50000, 22);
    compareWithBruteForce(m, kDeepOptions, 5000, 23);
}

TEST(BvhTraversal, HugeSceneMatchesBruteForce) {
    const Mesh m = transformed(test::terrain(10, 13), 1e10f, glm::vec3(-2e10f, 0.0f, 5e9f));
    compareWithBruteForce(m, BvhBuildOptions{}, 50000, 24);
}

TEST(BvhTraversal, SingleTriangle) {
    Mesh m;
    m.addTriangle({0.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f});
    compareWithBruteForce(m, BvhBuildOptions{}, 100000, 9);
    const Bvh bvh = buildBvh(m.positions, m.triangles);
    ASSERT_EQ(bvh.nodes.size(), 1u);
    EXPECT_EQ(bvh.nodes[0].leftCount, 1u);
    EXPECT_EQ(bvh.nodes[0].right, gpu::kInvalidIndex);
    const auto geoms = makeTriangleGeoms(m.positions, m.triangles, bvh.triangleOrder);
    const Hit h = traceClosestCpu(bvh.nodes, geoms, {0.25f, 0.5f, 1.0f}, {0.0f, 0.0f, -2.0f}, 0.0f, 1e30f);
    EXPECT_EQ(h.triangle, 0u);
    EXPECT_EQ(h.t, 0.5f);
    EXPECT_EQ(h.u, 0.25f);
    EXPECT_EQ(h.v, 0.5f);
}

// The depth cap (median fallback near the limit) must hold for any limit; a low limit makes
// it engage on an ordinary scene, where unlimited SAH would go deeper.
TEST(BvhBuilder, DepthCapHoldsAndStaysCorrect) {
    const Mesh m = test::randomSoup(1000, 0.2f, 16);  // >= 10 levels with leaves of 1
    BvhBuildOptions capped = kDeepOptions;
    capped.maxDepth = 11;
    const Bvh free = buildBvh(m.positions, m.triangles, kDeepOptions);
    ASSERT_GT(free.stats.maxDepth, capped.maxDepth) << "cap would not be exercised";
    const Bvh bvh = buildBvh(m.positions, m.triangles, capped);
    checkStructure(m, bvh, 1);
    EXPECT_LE(bvh.stats.maxDepth, capped.maxDepth);
    compareWithBruteForce(m, capped, 20000, 17);
}

TEST(BvhBuilder, EmptyMeshHasAbsentRootChildren) {
    const Bvh bvh = buildBvh({}, {});
    ASSERT_EQ(bvh.nodes.size(), 1u);
    EXPECT_EQ(bvh.nodes[0].left, gpu::kInvalidIndex);
    EXPECT_EQ(bvh.nodes[0].right, gpu::kInvalidIndex);
    EXPECT_GT(bvh.nodes[0].lmin.x, bvh.nodes[0].lmax.x);
    EXPECT_FALSE(traceAnyCpu(bvh.nodes, {}, glm::vec3(0.0f), {0.0f, 0.0f, 1.0f}, 0.0f, 1e30f));
    EXPECT_EQ(traceClosestCpu(bvh.nodes, {}, glm::vec3(0.0f), {1.0f, 0.0f, 0.0f}, 0.0f, 1e30f).triangle,
              gpu::kInvalidIndex);
}

TEST(BvhBuilder, RejectsOutOfRangeVertexIndex) {
    const std::vector<glm::vec3> p{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    EXPECT_THROW(buildBvh(p, {{0, 1, 3}}), std::invalid_argument);
}

// The references are made in parallel chunks of 65536 triangles: the error still names the
// first bad triangle, whichever chunk finishes first.
TEST(BvhBuilder, NamesTheFirstBadTriangleOfAnyChunk) {
    Mesh m = test::randomSoup(140000, 0.01f, 19);
    m.triangles[139000].y = static_cast<uint32_t>(m.positions.size());
    m.triangles[70000].z = static_cast<uint32_t>(m.positions.size()) + 5;
    for (const uint32_t threads : {1u, 2u, 3u}) {
        BvhBuildOptions o;
        o.buildThreads = threads;
        try {
            (void)buildBvh(m.positions, m.triangles, o);
            ADD_FAILURE() << "no error with " << threads << " threads";
        } catch (const std::invalid_argument& e) {
            EXPECT_NE(std::string(e.what()).find("triangle 70000 "), std::string::npos) << e.what();
        }
    }
    Mesh f = test::randomSoup(140000, 0.01f, 20);
    f.positions[f.triangles[100000].x].y = std::numeric_limits<float>::infinity();
    try {
        (void)buildBvh(f.positions, f.triangles);
        ADD_FAILURE() << "no error for an infinite vertex";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("triangle 100000 has a non-finite"), std::string::npos)
            << e.what();
    }
}

TEST(BvhBuilder, SameResultForAnyThreadCount) {
    const Mesh m = test::randomSoup(60000, 0.02f, 14);
    BvhBuildOptions serial;
    serial.buildThreads = 1;
    const Bvh a = buildBvh(m.positions, m.triangles, serial);
    checkStructure(m, a, serial.maxLeafSize);
    // 60000 triangles: a top phase of three levels, the root binned in three chunks with
    // three or more threads, then subtrees on every thread.
    for (const uint32_t threads : {2u, 3u, 4u, 7u}) {
        BvhBuildOptions parallel;
        parallel.buildThreads = threads;
        const Bvh b = buildBvh(m.positions, m.triangles, parallel);
        ASSERT_EQ(a.nodes.size(), b.nodes.size()) << threads << " threads";
        EXPECT_EQ(std::memcmp(a.nodes.data(), b.nodes.data(), a.nodes.size() * sizeof(gpu::BvhNode)), 0)
            << threads << " threads";
        EXPECT_EQ(a.triangleOrder, b.triangleOrder) << threads << " threads";
        EXPECT_EQ(a.stats.sahCost, b.stats.sahCost);
    }
    // The collapse too: subtrees under the top two wide levels collapsed in parallel.
    ASSERT_GE(a.nodes.size(), 16384u) << "too small for the parallel collapse";
    const WideBvh serialWide = collapseToWide(a.nodes, 1);
    for (const uint32_t threads : {2u, 3u}) {
        const WideBvh w = collapseToWide(a.nodes, threads);
        ASSERT_EQ(w.nodes.size(), serialWide.nodes.size());
        EXPECT_EQ(
            std::memcmp(w.nodes.data(), serialWide.nodes.data(), w.nodes.size() * sizeof(gpu::BvhWideNode)),
            0)
            << threads << " threads";
        EXPECT_EQ(w.maxStack, serialWide.maxStack);
        EXPECT_EQ(w.maxDepth, serialWide.maxDepth);
    }
}

// After pbrt-v3 shapes_test.cpp (Triangle.Watertight): rays from inside a closed mesh towards
// points exactly on shared edges and at vertices must hit something.
TEST(BvhTraversal, WatertightThroughSharedEdges) {
    const Mesh m = test::icosphere(4);
    const Bvh bvh = buildBvh(m.positions, m.triangles);
    const auto geoms = makeTriangleGeoms(m.positions, m.triangles, bvh.triangleOrder);
    std::mt19937 rng(15);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    uint32_t misses = 0;
    const uint32_t rayCount = 100000;
    for (uint32_t i = 0; i < rayCount; ++i) {
        const glm::uvec3 t = m.triangles[rng() % m.triangles.size()];
        const glm::vec3 a = m.positions[t[i % 3]];
        const glm::vec3 b = m.positions[t[(i + 1) % 3]];
        const float s = (i % 5 == 0) ? 0.0f : u01(rng);  // every fifth ray at a vertex
        const glm::vec3 target = a + s * (b - a);
        const glm::vec3 orig = 0.5f * test::uniformInBox(rng, glm::vec3(-1.0f), glm::vec3(1.0f));
        const glm::vec3 dir = target - orig;
        const Hit h = traceClosestCpu(bvh.nodes, geoms, orig, dir, 0.0f, 1e30f);
        const bool any = traceAnyCpu(bvh.nodes, geoms, orig, dir, 0.0f, 1e30f);
        if ((h.triangle == gpu::kInvalidIndex || !any) && ++misses <= 5) {
            ADD_FAILURE() << "ray through a shared edge escaped the closed mesh (ray " << i << ")";
        }
    }
    EXPECT_EQ(misses, 0u);
}

// growBvhBoxes: a tree built over one set of positions and grown to hold the same triangles at
// other positions (another frame) finds, for rays of either set, exactly the brute-force hits
// of that set; without growing, the moved set's rays miss hits (the test can fail).
TEST(BvhBuilder, GrownBoxesHoldBothFrames) {
    const Mesh a = test::randomSoup(600, 0.15f, 31);
    Mesh b = a;
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> shift(-0.3f, 0.3f);
    for (std::size_t t = 0; t < b.triangles.size(); ++t) {
        const glm::vec3 d(shift(rng), shift(rng), shift(rng));  // each triangle moves by its own amount
        for (int k = 0; k < 3; ++k) b.positions[b.triangles[t][k]] += d;
    }
    const Bvh built = buildBvh(a.positions, a.triangles);
    Bvh grown = built;
    growBvhBoxes(grown, b.positions, b.triangles);
    const auto missed = [](const Bvh& bvh, const Mesh& m) {
        const auto leafGeoms = makeTriangleGeoms(m.positions, m.triangles, bvh.triangleOrder);
        const auto origGeoms = makeTriangleGeoms(m.positions, m.triangles, identityOrder(m.triangles.size()));
        const WideBvh wide = collapseToWide(bvh.nodes);
        int wrong = 0;
        for (const Ray& r : makeRays(m, 2000, 5)) {
            const Hit f = traceClosestBruteForce(origGeoms, r.orig, r.dir, 0.0f, r.tMax);
            const Hit w = traceClosestWideCpu(wide.nodes, leafGeoms, r.orig, r.dir, 0.0f, r.tMax);
            const bool anyW = traceAnyWideCpu(wide.nodes, leafGeoms, r.orig, r.dir, 0.0f, r.tMax);
            const bool same = (w.triangle == gpu::kInvalidIndex) == (f.triangle == gpu::kInvalidIndex) &&
                              (f.triangle == gpu::kInvalidIndex || w.t == f.t) &&
                              anyW == (f.triangle != gpu::kInvalidIndex);
            wrong += same ? 0 : 1;
        }
        return wrong;
    };
    EXPECT_EQ(grown.triangleOrder, built.triangleOrder);
    EXPECT_EQ(missed(grown, a), 0);
    EXPECT_EQ(missed(grown, b), 0);
    EXPECT_GT(missed(built, b), 20) << "the moved triangles fit the first frame's boxes anyway";
    Mesh fewer = b;
    fewer.triangles.pop_back();
    EXPECT_THROW(growBvhBoxes(grown, fewer.positions, fewer.triangles), std::invalid_argument);
}

}  // namespace
}  // namespace gdpt
