// The GLSL BVH traversal (the code the renderer runs) against brute force over all
// triangles on the CPU, for 10^5 seeded random rays per scene, on scenes that stress it:
// a random soup, a grid of coplanar and duplicated triangles, and degenerate slivers.
// Occlusion beams (four rays with one end or one direction in one traversal) against the
// same rays traced one by one on the device, answer for answer; ray bundles (primary fans: five
// closest-hit rays from one origin; bundles of four from origins a little apart, to their own
// ends) likewise, hit for hit.
// Closest hit: the same triangle, or (for coplanar/duplicate ties) the same t; t within the
// rounding two devices may differ by (tTolerance). Any hit: identical answers. The same with the stack in
// registers (kSpecBvhRegisterStack, 8 and 16 entries) on trees that need exactly that many.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "bvh/builder.h"
#include "bvh/traverse_cpu.h"
#include "bvh/wide_bvh.h"
#include "gpu_fixture.h"
#include "render/device_scene/scene_spec.h"
#include "trace_beams.spv.h"
#include "trace_beams_units.spv.h"
#include "trace_bundles.spv.h"
#include "trace_rays.spv.h"
#include "trace_rays_units.spv.h"
#include "vk/buffer.h"
#include "vk/commands.h"
#include "vk/kernel.h"

namespace gdpt {
namespace {

struct Soup {
    std::vector<glm::vec3> positions;
    std::vector<glm::uvec3> triangles;
    void add(glm::vec3 a, glm::vec3 b, glm::vec3 c) {
        const auto i = static_cast<std::uint32_t>(positions.size());
        positions.insert(positions.end(), {a, b, c});
        triangles.emplace_back(i, i + 1, i + 2);
    }
};

// `count` triangles with vertices within `extent` of centres uniform in [-1, 1]^3.
Soup randomSoup(std::uint32_t count, std::uint32_t seed, float extent = 0.1f) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> pos(-1.0f, 1.0f), size(-extent, extent);
    Soup s;
    for (std::uint32_t i = 0; i < count; ++i) {
        const glm::vec3 c(pos(rng), pos(rng), pos(rng));
        s.add(c + glm::vec3(size(rng), size(rng), size(rng)), c + glm::vec3(size(rng), size(rng), size(rng)),
              c + glm::vec3(size(rng), size(rng), size(rng)));
    }
    return s;
}

// A 20×20 grid of quads in the plane z = 0, each quad duplicated, plus coplanar overlaps.
Soup coplanarGrid() {
    Soup s;
    for (int y = 0; y < 20; ++y)
        for (int x = 0; x < 20; ++x) {
            const float x0 = -1.0f + float(x) * 0.1f, y0 = -1.0f + float(y) * 0.1f, x1 = x0 + 0.1f,
                        y1 = y0 + 0.1f;
            for (int copy = 0; copy < 2; ++copy) {
                s.add({x0, y0, 0}, {x1, y0, 0}, {x1, y1, 0});
                s.add({x0, y0, 0}, {x1, y1, 0}, {x0, y1, 0});
            }
        }
    return s;
}

// Slivers, zero-area triangles (collinear and repeated vertices) mixed with normal ones.
Soup degenerate(std::uint32_t seed) {
    Soup s = randomSoup(800, seed);
    std::mt19937 rng(seed + 1);
    std::uniform_real_distribution<float> pos(-1.0f, 1.0f);
    for (int i = 0; i < 800; ++i) {
        const glm::vec3 a(pos(rng), pos(rng), pos(rng)), b(pos(rng), pos(rng), pos(rng));
        switch (i % 3) {
            case 0:
                s.add(a, a, a);
                break;  // a point
            case 1:
                s.add(a, b, 0.5f * (a + b));
                break;  // collinear
            default:
                s.add(a, b, b + glm::vec3(1e-6f, 0, 0));
                break;  // sliver
        }
    }
    return s;
}

std::vector<gpu::TestRay> randomRays(std::uint32_t count, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> pos(-1.5f, 1.5f), dir(-1.0f, 1.0f);
    std::vector<gpu::TestRay> rays(count);
    for (auto& r : rays) {
        r.origin = glm::vec3(pos(rng), pos(rng), pos(rng));
        // Half the rays aim at the scene centre region so that most of them hit.
        glm::vec3 d(dir(rng), dir(rng), dir(rng));
        if (rng() % 2) d = glm::vec3(pos(rng), pos(rng), pos(rng)) * 0.5f - r.origin;
        if (glm::length(d) < 1e-3f) d = glm::vec3(0, 0, 1);
        r.dir = d;
        r.tMin = 0.0f;
        r.tMax = (rng() % 4 == 0) ? 1.0f : INFINITY;  // some bounded queries (shadow-ray style)
    }
    return rays;
}

// `count` ray bundles of trace_bundles.comp (five TestRays each). The centre ray from an origin
// uniform in [-1.5, 1.5]^3, aimed at a random point of the soup's region (or, for a quarter of
// the bundles, in a random direction); the other four along its direction plus a random
// offset of up to `dirSpread` per component (about a pixel's angle for 0.003), each wanted with
// probability 0.85. Primary fans (`four` false): every ray from the centre's origin to
// infinity, the centre ray traced. Bundles of four: the centre ray not traced, the four from
// its origin plus up to `originSpread` per component, half of the bundles to infinity and half
// to their own tMax in [0.2, 3] (as G-PT's glossy offsets' next rays and reconnections).
std::vector<gpu::TestRay> randomBundles(std::uint32_t count, std::uint32_t seed, float originSpread,
                                        float dirSpread, bool four) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> pos(-1.5f, 1.5f), nearO(-originSpread, originSpread),
        nearD(-dirSpread, dirSpread), unit(0.0f, 1.0f), length(0.2f, 3.0f);
    std::vector<gpu::TestRay> rays(5 * std::size_t(count));
    for (std::uint32_t f = 0; f < count; ++f) {
        const glm::vec3 origin(pos(rng), pos(rng), pos(rng));
        glm::vec3 centre = rng() % 4 == 0 ? glm::vec3(pos(rng), pos(rng), pos(rng))
                                          : glm::vec3(pos(rng), pos(rng), pos(rng)) * 0.6f - origin;
        if (glm::length(centre) < 1e-3f) centre = glm::vec3(0, 0, 1);
        centre = glm::normalize(centre);
        const bool bounded = four && f % 2 == 1;
        for (std::uint32_t j = 0; j < 5; ++j) {
            gpu::TestRay& r = rays[5 * f + j];
            r.origin = j == 0 || !four ? origin : origin + glm::vec3(nearO(rng), nearO(rng), nearO(rng));
            r.dir = j == 0 ? centre : centre + glm::vec3(nearD(rng), nearD(rng), nearD(rng));
            r.tMin = j == 0 ? (four ? 1.0f : 0.0f) : (unit(rng) < 0.85f ? 0.0f : 1.0f);
            r.tMax = bounded && j != 0 ? length(rng) : INFINITY;
        }
    }
    return rays;
}

// `count` occlusion beams of trace_beams.comp (four TestRays each): origins within `spread` of a
// centre uniform in [-1.5, 1.5]^3, each wanted with probability 0.85; a third of the beams
// leave along a random direction, a third end at a random point, a third at a point inside a
// random triangle of `soup` (as G-PT's reconnections end on the base's next vertex).
std::vector<gpu::TestRay> randomBeams(std::uint32_t count, std::uint32_t seed, float spread,
                                      const Soup& soup) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> pos(-1.5f, 1.5f), near(-spread, spread), unit(0.0f, 1.0f);
    std::vector<gpu::TestRay> rays(4 * std::size_t(count));
    for (std::uint32_t b = 0; b < count; ++b) {
        const glm::vec3 centre(pos(rng), pos(rng), pos(rng));
        for (std::uint32_t j = 0; j < 4; ++j) {
            gpu::TestRay& r = rays[4 * b + j];
            r.origin = centre + glm::vec3(near(rng), near(rng), near(rng));
            r.tMin = unit(rng) < 0.85f ? 0.0f : 1.0f;
            r.dir = glm::vec3(0.0f);
            r.tMax = 0.0f;
        }
        gpu::TestRay& first = rays[4 * b];
        switch (b % 3) {
            case 0:  // along a direction, to infinity
                first.dir = glm::normalize(glm::vec3(pos(rng), pos(rng), pos(rng)) + glm::vec3(1e-3f));
                first.tMax = INFINITY;
                break;
            case 1:  // towards a point
                first.dir = glm::vec3(pos(rng), pos(rng), pos(rng)) * (2.0f / 3.0f);
                first.tMax = 1.0f;
                break;
            default: {  // towards a point on a triangle
                const glm::uvec3 t = soup.triangles[rng() % soup.triangles.size()];
                float u = unit(rng), v = unit(rng);
                if (u + v > 1.0f) u = 1.0f - u, v = 1.0f - v;
                first.dir = soup.positions[t.x] + u * (soup.positions[t.y] - soup.positions[t.x]) +
                            v * (soup.positions[t.z] - soup.positions[t.x]);
                first.tMax = 1.0f;
            }
        }
    }
    return rays;
}

// How far two evaluations of intersectTriangleGeom's t = dot(e2, cross(orig - v0, e1)) / det,
// det = dot(e1, cross(dir, e2)), may lie apart when each device rounds its own way: `precise`
// forbids reassociation but not the fused multiply-adds a driver may use inside dot() and
// cross(), and Vulkan allows 1/x an error of 2.5 ulp (Vulkan 1.3 spec, "Precision and Operation
// of SPIR-V Instructions"). By the usual first-order bounds (Higham 2002, sections 3.1 and 3.5), a
// dot product of cross products of rounded differences is within 6u of its absolute-value sum
// (u = 2^-24), det within 5u of its own, the reciprocal and the product add 6u: each result lies
// within that of the exact t, so two results lie within twice that of each other (lavapipe agreed
// with the CPU to 4 ulps; an NVIDIA driver, 2026-12-04, did not).
double tTolerance(const gpu::TriangleGeom& g, const glm::vec3& orig, const glm::vec3& dir, double t) {
    const glm::dvec3 v0(g.v0), e1(g.e1), e2(g.e2), o(orig), d(dir);
    const glm::dvec3 tv = o - v0;
    const auto absCrossSum = [](glm::dvec3 a, glm::dvec3 b) {
        a = glm::abs(a);
        b = glm::abs(b);
        return glm::dvec3(a.y * b.z + a.z * b.y, a.z * b.x + a.x * b.z, a.x * b.y + a.y * b.x);
    };
    const double num = glm::dot(e2, glm::cross(tv, e1));
    const double det = glm::dot(e1, glm::cross(d, e2));
    const double numScale = glm::dot(glm::abs(e2), absCrossSum(tv, e1));
    const double detScale = glm::dot(glm::abs(e1), absCrossSum(d, e2));
    const double u = std::ldexp(1.0, -24);
    const double relative = 6 * u * numScale / std::abs(num) + 5 * u * detScale / std::abs(det) + 6 * u;
    return 2 * relative * std::abs(t);
}

// The traversal loop's two builds (shaders/lib/bvh_traverse.glsl).
enum class Steps { Nodes, Units };

// A test kernel's description: the scene's geometry bindings, `outputs` more, 64 invocations per
// workgroup, `pushBytes` of push constants.
vk::KernelDesc testKernelDesc(vk::KernelDesc desc, std::vector<std::uint32_t> outputs,
                              std::uint32_t pushBytes) {
    desc.bindings = {gpu::kBindTriGeom, gpu::kBindBvh, gpu::kBindTestInput};
    desc.bindings.insert(desc.bindings.end(), outputs.begin(), outputs.end());
    desc.texelBindings = SceneSpec::geometryTexelBindings();
    desc.pushConstantBytes = pushBytes;
    desc.localSizeX = 64;
    return desc;
}

// A soup's triangles and wide tree and the test rays, on the device and bound to `kernel`.
struct DeviceScene {
    vk::Buffer geoms, nodes, rays;
    DeviceScene(const vk::Context& ctx, vk::Kernel& kernel, const std::vector<gpu::TriangleGeom>& g,
                const WideBvh& wide, const std::vector<gpu::TestRay>& r)
        : geoms(ctx, g.size() * sizeof(gpu::TriangleGeom), "geoms"),
          nodes(ctx, wide.nodes.size() * sizeof(gpu::BvhWideNode), "nodes"),
          rays(ctx, r.size() * sizeof(gpu::TestRay), "rays") {
        geoms.uploadVector(g);
        nodes.uploadVector(wide.nodes);
        rays.uploadVector(r);
        kernel.bind(gpu::kBindTriGeom, geoms);
        kernel.bind(gpu::kBindBvh, nodes);
        kernel.bind(gpu::kBindTestInput, rays);
    }
};

class BvhGpu : public test::GpuTest {
protected:
    // registerStack: kSpecBvhRegisterStack (0 = the stack in memory); the tree must fit it.
    // Steps::Units: the unit-step build, whose stack is always in memory.
    void check(const Soup& soup, std::uint32_t seed,
               vk::PipelineCreation creation = vk::PipelineCreation::Now, std::uint32_t registerStack = 0,
               std::uint32_t rayCount = 100000, Steps steps = Steps::Nodes) {
        const Bvh bvh = buildBvh(soup.positions, soup.triangles);
        const auto geoms = makeTriangleGeoms(soup.positions, soup.triangles, bvh.triangleOrder);
        const auto rays = randomRays(rayCount, seed);

        ASSERT_TRUE(steps == Steps::Nodes || registerStack == 0) << "unit steps keep the stack in memory";
        vk::KernelDesc desc = testKernelDesc(
            steps == Steps::Units ? vk::kernelDesc("trace_rays", GDPT_KERNEL_SPIRV(trace_rays_units))
                                  : vk::kernelDesc("trace_rays", GDPT_KERNEL_SPIRV(trace_rays)),
            {gpu::kBindTestOutput, gpu::kBindTestOutput2}, sizeof(std::uint32_t));
        const WideBvh wide = collapseToWide(bvh.nodes);
        if (registerStack != 0) {
            ASSERT_LE(wide.maxStack, registerStack) << "the tree does not fit the register stack";
            desc.specConstants = {{gpu::kSpecBvhRegisterStack, registerStack}};
        }
        vk::Kernel kernel(ctx(), desc, creation);
        const DeviceScene scene(ctx(), kernel, geoms, wide, rays);
        vk::Buffer hitBuf(ctx(), rays.size() * sizeof(glm::vec4), "hits");
        vk::Buffer anyBuf(ctx(), rays.size() * sizeof(std::uint32_t), "any");
        kernel.bind(gpu::kBindTestOutput, hitBuf);
        kernel.bind(gpu::kBindTestOutput2, anyBuf);
        vk::CommandStream cmd(ctx(), "trace_rays");
        kernel.dispatchItems(cmd.begin(), rayCount, 1, &rayCount);
        vk::computeBarrier(cmd.cmd());
        cmd.submitAndWait();
        const auto hits = hitBuf.downloadVector<glm::vec4>(rayCount);
        const auto any = anyBuf.downloadVector<std::uint32_t>(rayCount);

        int hitCount = 0, idMismatch = 0, tMismatch = 0, anyMismatch = 0;
        for (std::uint32_t i = 0; i < rayCount; ++i) {
            const auto& r = rays[i];
            const gpu::Hit ref = traceClosestBruteForce(geoms, r.origin, r.dir, r.tMin, r.tMax);
            std::uint32_t gpuTri = 0;
            std::memcpy(&gpuTri, &hits[i].w, sizeof gpuTri);
            const bool refHit = ref.triangle != gpu::kInvalidIndex;
            hitCount += refHit;
            if (refHit != (gpuTri != gpu::kInvalidIndex)) {
                ++idMismatch;
            } else if (refHit) {
                // Ties (coplanar or duplicated triangles, or two within rounding of each other)
                // may pick either triangle; t must agree within rounding.
                const double tol = tTolerance(geoms[ref.triangle], r.origin, r.dir, ref.t);
                const double tDiff = std::abs(double(hits[i].x) - double(ref.t));
                if (gpuTri != ref.triangle && tDiff > tol) ++idMismatch;
                if (!(tDiff <= tol)) ++tMismatch;
            }
            const bool refAny = traceAnyBruteForce(geoms, r.origin, r.dir, r.tMin, r.tMax);
            if (refAny != (any[i] != 0)) ++anyMismatch;
        }
        EXPECT_GT(hitCount, static_cast<int>(rayCount / 10)) << "test rays should hit often";
        EXPECT_EQ(idMismatch, 0);
        EXPECT_EQ(tMismatch, 0);
        EXPECT_EQ(anyMismatch, 0);
    }

    // Beams of trace_beams.comp over `soup`: every wanted ray's beam answer must be its own
    // traversal's; with noGrowth (the power check) the beam's boxes are not grown, and the
    // number of rays on which the two differ is returned for the caller to expect above 0.
    // Also checks that the beams meet occluders often and miss them often.
    // Runs a ray-group test kernel (trace_beams, trace_bundles: push constants {groups, flags},
    // flag 1 = boxes not grown)
    // over `soup` and `rays`, one invocation per group, and returns its `outputs` vec4 answers.
    std::vector<glm::vec4> runGroups(vk::KernelDesc desc, const Soup& soup,
                                     const std::vector<gpu::TestRay>& rays, std::uint32_t groups,
                                     std::uint32_t flags, std::uint32_t registerStack, std::size_t outputs) {
        const Bvh bvh = buildBvh(soup.positions, soup.triangles);
        const auto geoms = makeTriangleGeoms(soup.positions, soup.triangles, bvh.triangleOrder);
        desc = testKernelDesc(std::move(desc), {gpu::kBindTestOutput}, 2 * sizeof(std::uint32_t));
        const WideBvh wide = collapseToWide(bvh.nodes);
        if (registerStack != 0) {
            EXPECT_LE(wide.maxStack, registerStack) << "the tree does not fit the register stack";
            desc.specConstants = {{gpu::kSpecBvhRegisterStack, registerStack}};
        }
        vk::Kernel kernel(ctx(), desc);
        const DeviceScene scene(ctx(), kernel, geoms, wide, rays);
        vk::Buffer outBuf(ctx(), outputs * sizeof(glm::vec4), "answers");
        kernel.bind(gpu::kBindTestOutput, outBuf);
        const std::uint32_t push[2] = {groups, flags};
        vk::CommandStream cmd(ctx(), "ray groups");
        kernel.dispatchItems(cmd.begin(), groups, 1, push);
        vk::computeBarrier(cmd.cmd());
        cmd.submitAndWait();
        return outBuf.downloadVector<glm::vec4>(outputs);
    }

    int checkBeams(const Soup& soup, std::uint32_t seed, float spread, std::uint32_t registerStack = 0,
                   Steps steps = Steps::Nodes, std::uint32_t noGrowth = 0, std::uint32_t beamCount = 20000) {
        const auto rays = randomBeams(beamCount, seed, spread, soup);
        const auto answers = runGroups(
            steps == Steps::Units ? vk::kernelDesc("trace_beams", GDPT_KERNEL_SPIRV(trace_beams_units))
                                  : vk::kernelDesc("trace_beams", GDPT_KERNEL_SPIRV(trace_beams)),
            soup, rays, beamCount, noGrowth, registerStack, rays.size());
        int wanted = 0, occluded = 0, differ = 0, unwantedOccluded = 0;
        for (std::size_t i = 0; i < rays.size(); ++i) {
            if (rays[i].tMin != 0.0f) {
                unwantedOccluded += answers[i].x != 0.0f;
                continue;
            }
            ++wanted;
            occluded += answers[i].y != 0.0f;
            differ += answers[i].x != answers[i].y;
        }
        EXPECT_EQ(unwantedOccluded, 0) << "a ray not wanted is never occluded";
        EXPECT_GT(occluded, wanted / 10) << "the beams should meet occluders often";
        EXPECT_LT(occluded, wanted * 9 / 10) << "and miss them often";
        if (noGrowth == 0) {
            EXPECT_EQ(differ, 0) << "beam answers that are not the single rays' answers";
        }
        return differ;
    }

    // Bundles of trace_bundles.comp (`rays`, five per bundle; `four`: bundles of four, else
    // primary fans) over `soup`: every wanted ray's bundle hit must be its own traversal's, the
    // same t, triangle and barycentrics bit for bit; where `ties` the triangle may differ at the
    // same t (duplicated triangles, which each traversal meets in its own order). Rays not
    // wanted are misses. Returns the number of wanted rays whose bundle hit differs from the
    // single ray's (the power check, noGrowth, expects many).
    int checkBundles(const Soup& soup, const std::vector<gpu::TestRay>& rays, bool four, bool ties,
                     std::uint32_t registerStack, std::uint32_t noGrowth) {
        const auto count = static_cast<std::uint32_t>(rays.size() / 5);
        const auto answers =
            runGroups(vk::kernelDesc("trace_bundles", GDPT_KERNEL_SPIRV(trace_bundles)), soup, rays, count,
                      noGrowth | (four ? 2u : 0u), registerStack, 2 * rays.size());
        const auto bits = [](float x) {
            std::uint32_t b;
            std::memcpy(&b, &x, sizeof b);
            return b;
        };
        int wanted = 0, hits = 0, differ = 0, tied = 0, unwantedHit = 0;
        for (std::size_t i = 0; i < rays.size(); ++i) {
            const glm::vec4 got = answers[2 * i], single = answers[2 * i + 1];
            if (rays[i].tMin != 0.0f || (four && i % 5 == 0)) {
                unwantedHit += bits(got.y) != gpu::kInvalidIndex;
                continue;
            }
            ++wanted;
            hits += bits(single.y) != gpu::kInvalidIndex;
            const bool sameT = bits(got.x) == bits(single.x);
            const bool same = sameT && bits(got.y) == bits(single.y) && bits(got.z) == bits(single.z) &&
                              bits(got.w) == bits(single.w);
            if (same) continue;
            if (ties && sameT) {
                ++tied;
                continue;
            }
            ++differ;
        }
        EXPECT_EQ(unwantedHit, 0) << "a ray not wanted is a miss";
        EXPECT_GT(hits, wanted / 10) << "the bundles' rays should hit often";
        EXPECT_LT(hits, wanted * 9 / 10) << "and miss often";
        if (noGrowth == 0) {
            EXPECT_EQ(differ, 0) << "bundle hits that are not the single rays' hits";
        }
        if (!ties) {
            EXPECT_EQ(tied, 0);
        }
        return differ;
    }
    int checkFans(const Soup& soup, std::uint32_t seed, float spread, bool ties = false,
                  std::uint32_t registerStack = 0, std::uint32_t noGrowth = 0) {
        return checkBundles(soup, randomBundles(20000, seed, 0.0f, spread, false), false, ties, registerStack,
                            noGrowth);
    }
    int checkBundlesOfFour(const Soup& soup, std::uint32_t seed, float originSpread, float dirSpread,
                           bool ties = false, std::uint32_t registerStack = 0, std::uint32_t noGrowth = 0) {
        return checkBundles(soup, randomBundles(20000, seed, originSpread, dirSpread, true), true, ties,
                            registerStack, noGrowth);
    }
};

TEST_F(BvhGpu, RandomSoupMatchesBruteForce) {
    check(randomSoup(1000, 7), 11);
}
TEST_F(BvhGpu, CoplanarDuplicatedGridMatchesBruteForce) {
    check(coplanarGrid(), 12);
}
// The same kernel with its pipeline created on a worker thread while the buffers are made,
// uploaded and bound (how the renderers create theirs): the first dispatch waits for it.
TEST_F(BvhGpu, BackgroundPipelineMatchesBruteForce) {
    check(randomSoup(300, 9), 13, vk::PipelineCreation::Background);
}
// A kernel whose background creation is never waited for is destroyed cleanly (the
// destructor joins the worker and destroys the pipeline; validation reports any leak).
TEST_F(BvhGpu, UnusedBackgroundPipelineIsDestroyed) {
    const vk::KernelDesc desc =
        testKernelDesc(vk::kernelDesc("trace_rays", GDPT_KERNEL_SPIRV(trace_rays)),
                       {gpu::kBindTestOutput, gpu::kBindTestOutput2}, sizeof(std::uint32_t));
    { vk::Kernel unused(ctx(), desc, vk::PipelineCreation::Background); }
    vk::Kernel waited(ctx(), desc, vk::PipelineCreation::Background);
    EXPECT_GE(waited.wait(), 0.0);
    EXPECT_EQ(waited.wait(), 0.0);  // already there: no second wait
}
TEST_F(BvhGpu, DegenerateTrianglesMatchBruteForce) {
    check(degenerate(9), 13);
}

// The unit-step build on the same soups, and on one whose tree is deep (a stack of more than
// 16 entries, as the scenes that take this build have).
TEST_F(BvhGpu, UnitStepsMatchBruteForce) {
    check(randomSoup(1000, 7), 11, vk::PipelineCreation::Now, 0, 30000, Steps::Units);
    check(coplanarGrid(), 12, vk::PipelineCreation::Now, 0, 30000, Steps::Units);
    check(degenerate(9), 13, vk::PipelineCreation::Now, 0, 30000, Steps::Units);
}
TEST_F(BvhGpu, UnitStepsOnADeepTreeMatchBruteForce) {
    const Soup soup = randomSoup(6000, 5, 0.05f);
    ASSERT_GT(collapseToWide(buildBvh(soup.positions, soup.triangles).nodes).maxStack, 16u);
    check(soup, 14, vk::PipelineCreation::Now, 0, 10000, Steps::Units);
}

// The register stacks at their capacity: a soup whose tree needs exactly 8 (16) entries,
// the most each holds, so the deepest entries are pushed and popped too (larger triangles
// than randomSoup's default, so that a tenth of the rays hit so few). 20,000 rays each.
Soup soupNeedingStack(std::uint32_t entries) {
    for (std::uint32_t n = 16; n <= 4096; n += 8) {
        Soup s = randomSoup(n, 7, 0.4f);
        const Bvh bvh = buildBvh(s.positions, s.triangles);
        if (collapseToWide(bvh.nodes).maxStack == entries) return s;
    }
    ADD_FAILURE() << "no random soup of up to 4096 triangles needs exactly " << entries << " stack entries";
    return {};
}
TEST_F(BvhGpu, RegisterStackOfEightMatchesBruteForce) {
    check(soupNeedingStack(8), 21, vk::PipelineCreation::Now, 8, 20000);
}
TEST_F(BvhGpu, RegisterStackOfSixteenMatchesBruteForce) {
    check(soupNeedingStack(16), 22, vk::PipelineCreation::Now, 16, 20000);
}

// Occlusion beams: rays a pixel apart (spread 0.002, as G-PT's offsets) and farther apart
// (0.05), on the soups above, with the stack in memory, in registers and in unit steps.
TEST_F(BvhGpu, BeamsMatchSingleRays) {
    checkBeams(randomSoup(1000, 7), 31, 0.002f);
    checkBeams(randomSoup(1000, 7), 32, 0.05f);
    checkBeams(coplanarGrid(), 33, 0.05f);
    checkBeams(degenerate(9), 34, 0.05f);
}
TEST_F(BvhGpu, BeamsMatchSingleRaysWithTheRegisterStack) {
    checkBeams(soupNeedingStack(8), 35, 0.05f, 8);
    checkBeams(soupNeedingStack(16), 36, 0.05f, 16);
}
TEST_F(BvhGpu, BeamsMatchSingleRaysInUnitSteps) {
    checkBeams(randomSoup(1000, 7), 37, 0.05f, 0, Steps::Units);
    const Soup deep = randomSoup(6000, 5, 0.05f);
    checkBeams(deep, 38, 0.05f, 0, Steps::Units, 0, 5000);
}
// The power check: without the grown boxes the beam walks only the nodes its centre ray
// enters, and misses occluders that the rays off the centre meet (measured: 5.5 % of the
// 68,000 rays, 3,700 answers of 27,000 occluded rays, in either build).
TEST_F(BvhGpu, BeamsWithoutGrownBoxesMissOccluders) {
    EXPECT_GT(checkBeams(randomSoup(6000, 5, 0.05f), 39, 0.05f, 0, Steps::Nodes, 1), 680);
    EXPECT_GT(checkBeams(randomSoup(6000, 5, 0.05f), 40, 0.05f, 0, Steps::Units, 1), 680);
}

// Primary fans: rays about a pixel's angle apart (spread 0.003, as G-PT's primary rays at
// 256²) and farther (0.03), on the soups above and with the stack in registers (about 88,000
// wanted rays per case, 35-90 % of them hitting): no hit differs. The coplanar grid's
// duplicated triangles are hit at the same t twice, where either may be reported (none was
// here: a duplicate shares its twin's leaf, tested in the same slot order by both walks).
TEST_F(BvhGpu, FansMatchSingleRays) {
    checkFans(randomSoup(1000, 7), 51, 0.003f);
    checkFans(randomSoup(1000, 7), 52, 0.03f);
    checkFans(coplanarGrid(), 53, 0.03f, true);
    checkFans(degenerate(9), 54, 0.03f);
}
TEST_F(BvhGpu, FansMatchSingleRaysWithTheRegisterStack) {
    checkFans(soupNeedingStack(8), 55, 0.03f, false, 8);
    checkFans(soupNeedingStack(16), 56, 0.03f, false, 16);
}
// Bundles of four (G-PT's glossy offsets' next rays: origins a pixel or so apart, directions
// near the base's, half of them ending at their own tMax): no hit differs, from near rays to
// rays 0.1 apart in origin and direction, with the stack in memory and in registers.
TEST_F(BvhGpu, BundlesOfFourMatchSingleRays) {
    checkBundlesOfFour(randomSoup(1000, 7), 61, 0.01f, 0.003f);
    checkBundlesOfFour(randomSoup(1000, 7), 62, 0.03f, 0.03f);
    checkBundlesOfFour(randomSoup(1000, 7), 63, 0.1f, 0.1f);
    checkBundlesOfFour(coplanarGrid(), 64, 0.03f, 0.03f, true);
    checkBundlesOfFour(degenerate(9), 65, 0.03f, 0.03f);
}
TEST_F(BvhGpu, BundlesOfFourMatchSingleRaysWithTheRegisterStack) {
    checkBundlesOfFour(soupNeedingStack(8), 66, 0.03f, 0.03f, false, 8);
    checkBundlesOfFour(soupNeedingStack(16), 67, 0.03f, 0.03f, false, 16);
}
// The power check of bundles of four: with their boxes not grown the bundle misses (or
// mistakes) the closest hits of rays off the centre ray (measured: 13,666 of 68,109 wanted
// rays).
TEST_F(BvhGpu, BundlesOfFourWithoutGrownBoxesMissHits) {
    EXPECT_GT(checkBundlesOfFour(randomSoup(6000, 5, 0.05f), 68, 0.03f, 0.03f, false, 0, 1), 1000);
}
// The power check: without the grown boxes the fan walks only the nodes its centre ray
// enters, and misses (or mistakes) the closest hits of the rays off the centre (measured:
// 11,363 of 87,881 wanted rays).
TEST_F(BvhGpu, FansWithoutGrownBoxesMissHits) {
    EXPECT_GT(checkFans(randomSoup(6000, 5, 0.05f), 57, 0.03f, false, 0, 1), 1000);
}

}  // namespace
}  // namespace gdpt
