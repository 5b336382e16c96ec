// G-PT's extra samples in the pixels that a geometric edge crosses (edge.comp,
// render/passes/edge_pass.h), against closed forms: with the camera looking straight down at planes
// parallel to the image, a rectangle's edges project to straight image lines, placed here on
// pixel centres, so the pixels whose quarter probes (at x + 0.25 and x + 0.75) straddle an
// edge are known exactly, with a quarter pixel to spare on either side. The probe must find
// exactly those for a step in depth between faces of one material and for a change of
// material within one plane, and nothing on a plane split into triangles of one material or
// inside a smooth sphere. Then every edge pixel gets edgeSamples × spp more samples in its
// statistics and every other pixel none. That the estimates stay unbiased with the extra
// samples is checked by test_gpt_render.cpp's comparisons with the path tracer, which run
// with them on (the default).
#include <gtest/gtest.h>

#include <cstdint>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "gpu_fixture.h"
#include "render/device_scene/scene_gpu.h"
#include "render/passes/gpt_pass.h"
#include "scene/procedural.h"
#include "scene_builders.h"
#include "vk/commands.h"

namespace gdpt {
namespace {

class EdgeSamples : public test::GpuTest {};

// 64², camera at height 2 looking down with a 90° field of view: the plane z maps world x to
// pixel (x / (2 − z) + 1) · 32 (y mirrored, symmetric here).
constexpr int kSize = 64;
constexpr float kCameraHeight = 2.0f;

// Rectangle [x0, x1] x [y0, y1] in the plane z, facing +z (the camera).
void addRect(Scene& s, float x0, float x1, float y0, float y1, float z, std::uint32_t mat) {
    const auto base = static_cast<std::uint32_t>(s.positions.size());
    s.positions.insert(s.positions.end(), {{x0, y0, z}, {x1, y0, z}, {x1, y1, z}, {x0, y1, z}});
    s.triangles.emplace_back(base, base + 1, base + 2);
    s.triangles.emplace_back(base, base + 2, base + 3);
    s.triangleMaterial.insert(s.triangleMaterial.end(), {mat, mat});
}

Scene lookingDown() {
    Scene s;
    s.materials.push_back(test::lambert(glm::vec3(0.5f)));
    s.materials.push_back(test::lambert(glm::vec3(0.2f, 0.6f, 0.3f)));
    s.materials.push_back(test::lambert(glm::vec3(0.0f), glm::vec3(2.0f)));  // a light
    s.cameras.push_back(test::lookDown(kCameraHeight, 90.0f));
    // A light far above the camera's view (outside the image), facing down, so that the
    // scenes have something to render.
    const auto base = static_cast<std::uint32_t>(s.positions.size());
    s.positions.insert(s.positions.end(), {{-1, -1, 4}, {1, -1, 4}, {1, 1, 4}, {-1, 1, 4}});
    s.triangles.emplace_back(base, base + 2, base + 1);
    s.triangles.emplace_back(base, base + 3, base + 2);
    s.triangleMaterial.insert(s.triangleMaterial.end(), {2u, 2u});
    return s;
}

SceneGpuOptions sizeOptions() {
    SceneGpuOptions o;
    o.width = kSize;
    o.height = kSize;
    return o;
}

// The mask of EdgePass on `scene` at kSize², as a set of (x, y).
std::set<std::pair<int, int>> probe(const vk::Context& ctx, const Scene& scene) {
    SceneGpu gpu(ctx, scene, sizeOptions());
    EdgePass pass(ctx, gpu.spec(), WorkgroupSize{}, 1, vk::PipelineCreation::Now);
    pass.attach(gpu);
    vk::CommandStream stream(ctx, "edge test");
    pass.find(stream);
    std::set<std::pair<int, int>> out;
    const std::vector<std::uint32_t>& mask = pass.mask();
    EXPECT_EQ(mask.size(), std::size_t{kSize} * kSize);
    for (std::size_t i = 0; i < mask.size(); ++i)
        if (mask[i] != 0) out.insert({int(i % kSize), int(i / kSize)});
    EXPECT_EQ(out.size(), pass.edgeCount());
    return out;
}

// A square of half-size 0.515625 at z = 1 projects to [15.5, 48.5]² (pixel centres), in front
// of a wall at z = 0: its outline is the pixels of columns 15 and 48 and rows 15 and 48
// between them.
std::set<std::pair<int, int>> squareOutline() {
    std::set<std::pair<int, int>> out;
    for (int i = 15; i <= 48; ++i) {
        out.insert({15, i});
        out.insert({48, i});
        out.insert({i, 15});
        out.insert({i, 48});
    }
    return out;
}

// The pixels that get the edge samples (edgeSampleList): those of `pixels` and their four
// neighbours inside the kSize² image.
std::set<std::pair<int, int>> withNeighbours(const std::set<std::pair<int, int>>& pixels) {
    std::set<std::pair<int, int>> out;
    for (const auto& [x, y] : pixels)
        for (const auto& [dx, dy] : {std::pair{0, 0}, {1, 0}, {-1, 0}, {0, 1}, {0, -1}})
            if (x + dx >= 0 && y + dy >= 0 && x + dx < kSize && y + dy < kSize) out.insert({x + dx, y + dy});
    return out;
}

// The square of squareOutline() in front of a wall, both of material 0.
Scene stepScene() {
    Scene s = lookingDown();
    addRect(s, -10, 10, -10, 10, 0.0f, 0);
    addRect(s, -0.515625f, 0.515625f, -0.515625f, 0.515625f, 1.0f, 0);
    return s;
}

TEST_F(EdgeSamples, ProbeFindsExactlyTheSilhouetteOfAStepInDepthWithinOneMaterial) {
    const auto found = probe(ctx(), stepScene());
    EXPECT_EQ(found, squareOutline());
    EXPECT_EQ(found.size(), 132u);
}

TEST_F(EdgeSamples, ProbeFindsAChangeOfMaterialWithinAPlaneAndNotATriangleBoundary) {
    // Split at world x = 0.53125, which z = 0 maps to pixel x 40.5: column 40 changes
    // material; the split at x = -0.53125 (pixel 23.5) has the same material on both sides.
    Scene s = lookingDown();
    addRect(s, -10, -0.53125f, -10, 10, 0.0f, 0);
    addRect(s, -0.53125f, 0.53125f, -10, 10, 0.0f, 0);
    addRect(s, 0.53125f, 10, -10, 10, 0.0f, 1);
    std::set<std::pair<int, int>> expected;
    for (int y = 0; y < kSize; ++y) expected.insert({40, y});
    EXPECT_EQ(probe(ctx(), s), expected);
}

TEST_F(EdgeSamples, SmoothSphereSeenFromInsideHasNoEdges) {
    // The furnace's icosphere (1280 facets, neighbours about 10° apart, one material).
    EXPECT_TRUE(probe(ctx(), makeFurnaceSphere(0.5f, glm::vec3(0.5f), 3)).empty());
}

// A G-PT pass over stepScene() at kSize² with `edgeSamples`, its edges found.
struct StepPass {
    StepPass(const vk::Context& ctx, std::uint32_t edgeSamples, bool countWeights = true)
        : gpu(ctx, stepScene(), sizeOptions()),
          pass(ctx, gpu, WorkgroupSize{}, passOptions(edgeSamples, countWeights)),
          stream(ctx, "edge test") {
        pass.findEdges(stream);
    }
    static GptPassOptions passOptions(std::uint32_t edgeSamples, bool countWeights) {
        GptPassOptions o;
        o.edgeSamples = edgeSamples;
        o.countWeights = countWeights;
        return o;
    }
    SceneGpu gpu;
    GptPass pass;
    vk::CommandStream stream;
};

// Each edge pixel's and each of its four neighbours' statistics count (1 + edgeSamples) × spp
// samples, every other pixel spp; a partial pass (rows < height) adds no edge samples.
TEST_F(EdgeSamples, EdgePixelsAndTheirNeighboursGetTheExtraSamplesAndOnlyThey) {
    StepPass step(ctx(), 3);
    GptPass& pass = step.pass;
    vk::CommandStream& stream = step.stream;
    const auto listed = withNeighbours(squareOutline());
    ASSERT_EQ(pass.edges().edgeCount(), 132u);
    ASSERT_EQ(pass.edges().count(), listed.size());
    // The outline (a 34-pixel square ring, 132) and the rings just outside (36-pixel square,
    // less its 4 corners, which only touch the outline diagonally: 136) and inside (124).
    ASSERT_EQ(listed.size(), 132u + 136u + 124u);
    const std::uint32_t seed = 7;
    auto batch = [&](std::uint32_t first, std::uint32_t n, std::uint32_t rows) {
        pass.record(stream.begin(), first, n, seed, nullptr, rows);
        stream.submitAndWait();
    };
    batch(0, 2, kSize);
    batch(2, 3, kSize);
    batch(5, 1, 10);  // partial pass: rows 0..9 only
    const auto stats = pass.downloadStats();
    const std::vector<gpu::PixelStats>& central = stats[0];
    int wrong = 0;
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
            const std::uint32_t expected = (listed.count({x, y}) ? 5u * 4u : 5u) + (y < 10 ? 1u : 0u);
            const std::uint32_t got = central[std::size_t(y) * kSize + x].count;
            if (got != expected && wrong++ < 5)
                ADD_FAILURE() << "pixel " << x << "," << y << ": " << got << " samples, expected "
                              << expected;
        }
    EXPECT_EQ(wrong, 0);
}

// With kEdgeSamplesAuto the count of the listed pixels sets the factor by the rule
// (edge_options.h), and they get that many extra samples (the square's outline and its
// neighbours, 392 of kSize²: 9.6 %, factor 2; gdpt render's JSON test has a share that lowers it).
TEST_F(EdgeSamples, TheAutomaticFactorFollowsTheListedPixelsShare) {
    StepPass step(ctx(), kEdgeSamplesAuto);
    GptPass& pass = step.pass;
    const auto listed = withNeighbours(squareOutline());
    ASSERT_EQ(pass.edges().count(), listed.size());
    const std::uint32_t k = autoEdgeSamples(listed.size(), std::uint64_t{kSize} * kSize);
    EXPECT_EQ(k, 2u);
    EXPECT_EQ(pass.edges().samplesPerSpp(), k);
    ASSERT_GT(k, 0u) << "the test needs a factor that adds samples";
    pass.record(step.stream.begin(), 0, 2, 7, nullptr);
    step.stream.submitAndWait();
    const auto stats = pass.downloadStats();
    int wrong = 0;
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
            const std::uint32_t expected = listed.count({x, y}) ? 2u * (1u + k) : 2u;
            if (stats[0][std::size_t(y) * kSize + x].count != expected) ++wrong;
        }
    EXPECT_EQ(wrong, 0);
}

// The pair weights count the two ends' samples (shift.glsl): the same samples weighted with and
// without the counts give bit-identical statistics wherever a pixel and all its neighbours have
// one rate, and where an unlisted pixel q borders the list, its primal (the average of its pair
// estimators) takes the listed neighbour p's (1 + K) × spp paths at weight 16/17 instead of 1/2
// (K = 3, equal densities): var_primal(q) falls to about 0.71 of the equal weights' (the pair
// (q, p): 0.3125 σ²/n → 0.225 σ²/n; with the three other pairs and the shared central term,
// 0.30 → 0.21 σ²/n; measured 0.70). Summed over the 256 such pixels, each variance estimated
// from 16 samples (relative noise sqrt(2/15) per pixel, about 2.3 % on the sum), the test asks
// for below 0.85 (and above 0.5): weights reversed (c for 1/c) or not counted fail it.
TEST_F(EdgeSamples, PairWeightsCountTheSamplesOfBothEnds) {
    constexpr std::uint32_t kFactor = 3, kSpp = 16, kSeed = 11;
    auto render = [&](bool countWeights) {
        StepPass step(ctx(), kFactor, countWeights);
        step.pass.record(step.stream.begin(), 0, kSpp, kSeed, nullptr);
        step.stream.submitAndWait();
        VkCommandBuffer cmd = step.stream.begin();
        step.pass.resolve(cmd, nullptr);
        step.stream.submitAndWait();
        return std::pair{step.pass.downloadStats(), step.pass.readback()};
    };
    const auto [countedStats, counted] = render(true);
    const auto [equalStats, equal] = render(false);
    const auto listed = withNeighbours(squareOutline());
    const auto rate = [&](int x, int y) { return listed.count({x, y}) ? 1 + kFactor : 1u; };
    const auto uniform = [&](int x, int y) {  // the pixel and its neighbours share one rate
        for (const auto& [dx, dy] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
            const int u = x + dx, v = y + dy;
            if (u >= 0 && v >= 0 && u < kSize && v < kSize && rate(u, v) != rate(x, y)) return false;
        }
        return true;
    };
    int differingUniform = 0, differingBorder = 0, border = 0;
    double varCounted = 0.0, varEqual = 0.0;
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
            const std::size_t i = std::size_t(y) * kSize + x;
            bool same = true;
            for (std::size_t b = 0; b < 9; ++b)  // central, neighbours, gradients
                for (int c = 0; c < 3; ++c)
                    same = same && countedStats[b][i].mean[c] == equalStats[b][i].mean[c] &&
                           countedStats[b][i].m2[c] == equalStats[b][i].m2[c];
            if (uniform(x, y)) {
                differingUniform += same ? 0 : 1;
                continue;
            }
            differingBorder += same ? 0 : 1;
            if (rate(x, y) != 1) continue;  // an unlisted pixel next to the list
            ++border;
            for (int c = 0; c < 3; ++c) {
                varCounted += counted.varPrimal.at(x, y, c);
                varEqual += equal.varPrimal.at(x, y, c);
            }
        }
    EXPECT_EQ(differingUniform, 0);
    EXPECT_GT(differingBorder, border);  // both sides of the list's border changed
    EXPECT_GT(border, 100);
    ASSERT_GT(varEqual, 0.0);
    EXPECT_LT(varCounted / varEqual, 0.85) << varCounted << " / " << varEqual;
    EXPECT_GT(varCounted / varEqual, 0.5) << varCounted << " / " << varEqual;
}

TEST_F(EdgeSamples, OffMeansNoProbeAndNoExtraSamples) {
    StepPass step(ctx(), 0);
    GptPass& pass = step.pass;
    vk::CommandStream& stream = step.stream;
    EXPECT_FALSE(pass.edges().enabled());
    EXPECT_EQ(pass.edges().count(), 0u);
    pass.record(stream.begin(), 0, 2, 1, nullptr);
    stream.submitAndWait();
    const auto stats = pass.downloadStats();
    for (const gpu::PixelStats& p : stats[0]) ASSERT_EQ(p.count, 2u);
}

TEST(EdgeSampleSeed, DiffersFromTheSeedAndKeepsSeedsApart) {
    std::set<std::uint32_t> seen;
    for (std::uint32_t seed = 0; seed < 1000; ++seed) {
        EXPECT_NE(edgeSampleSeed(seed), seed);
        seen.insert(edgeSampleSeed(seed));
    }
    EXPECT_EQ(seen.size(), 1000u);
}

}  // namespace
}  // namespace gdpt
