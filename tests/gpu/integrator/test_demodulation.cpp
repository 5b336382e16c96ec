// G-PT's first-hit texture demodulation (gpt.comp kDemodulate, render/passes/gpt_pass.h).
//
// - demodulationMask keeps exactly the pixels whose 3x3 neighbourhood shows one surface: hand-
//   placed misses, a change of material, a step in depth and an edge pixel of the probe each
//   exclude the pixels around them, and nothing else.
// - On a scene without textures every path's modulation is 1, so turning it on must leave
//   every statistic bit for bit the same (x / 1 is exact) and m̄ exactly 1.
// - A checkerboard-textured plane under a uniform sky is the case where demodulation is
//   exact: every sample's f / t is the same function of the sky, so m̄ · J estimates the pixel
//   without the within-pixel covariance that makes it approximate elsewhere. Its
//   modulation × primal must match an independent PT render within z standard errors, on the
//   step-3 lattice of independent pixels (the primal of p depends on p's 4 neighbours), with
//   the variance Var(m̄ J) ≈ J² Var(m̄) + m̄² Var(J) + Var(PT) (m̄ and J of one pixel are nearly
//   independent here: J does not depend on where in the pixel a sample lands). z is
//   Šidák-corrected over the pixel tests (family alpha 1e-3). Power: the same statistic
//   against the PT image shifted by one checker cell must be rejected somewhere.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "gpu_fixture.h"
#include "integrator/gpt_sampler.h"
#include "integrator/pt_sampler.h"
#include "integrator/render_options.h"
#include "render/passes/gpt_pass.h"
#include "scene/procedural.h"
#include "scene_builders.h"
#include "stats_normal.h"

namespace gdpt {
namespace {

gpu::EdgeProbe hit(float x, float y, float z, std::uint32_t material) {
    gpu::EdgeProbe p{};
    p.position = glm::vec3(x, y, z);
    p.material = material;
    p.normal = glm::vec3(0.0f, 0.0f, 1.0f);
    p.hit = 1;
    return p;
}

TEST(DemodulationMask, KeepsOnlyPixelsWhoseNeighbourhoodShowsOneSurface) {
    const std::uint32_t w = 12, h = 10;
    std::vector<std::uint32_t> edges(w * h, 0u);
    std::vector<gpu::EdgeProbe> probes(w * h);
    for (std::uint32_t y = 0; y < h; ++y)
        for (std::uint32_t x = 0; x < w; ++x) {
            // Material 1 from column 8 on; the plane one unit lower from row 6 on (a step in
            // depth between parallel faces, 0.1 apart in the plane).
            probes[y * w + x] =
                hit(0.1f * float(x), 0.1f * float(y), y >= 6 ? -1.0f : 0.0f, x >= 8 ? 1u : 0u);
        }
    for (std::uint32_t y = 0; y < 2; ++y)
        for (std::uint32_t x = 0; x < 2; ++x) probes[y * w + x] = gpu::EdgeProbe{};  // misses
    edges[3 * w + 4] = 1;  // an edge the probe found inside pixel (4, 3)
    const std::vector<std::uint32_t> mask = demodulationMask(edges, probes, w, h);
    ASSERT_EQ(mask.size(), std::size_t{w} * h);
    for (std::uint32_t y = 0; y < h; ++y)
        for (std::uint32_t x = 0; x < w; ++x) {
            const bool excluded = x == 7 || x == 8 ||                        // material change
                                  y == 5 || y == 6 ||                        // depth step
                                  (x >= 3 && x <= 5 && y >= 2 && y <= 4) ||  // around the edge pixel
                                  (x <= 2 && y <= 2 && x + y > 0);           // misses next to hits
            EXPECT_EQ(mask[y * w + x], excluded ? 0u : 1u) << "pixel " << x << "," << y;
        }
    // Misses among misses are one "surface": (0, 0) above sees only the 2x2 block of misses,
    // and a 3x3 block of misses keeps its centre.
    std::vector<gpu::EdgeProbe> empty(9);
    EXPECT_EQ(demodulationMask(std::vector<std::uint32_t>(9, 0u), empty, 3, 3)[4], 1u);
}

class Demodulation : public test::GpuTest {};

TEST_F(Demodulation, LeavesAnUntexturedSceneBitForBitAlone) {
    const Scene scene = makeCornellBox();
    ASSERT_FALSE(demodulationApplies(scene));
    RenderOptions o = renderOptions(24, 24, 2, 3);
    GptSamplingOptions g;
    g.demodulate = gdpt::Demodulation::Off;
    const RenderResultGpt off = renderGpt(ctx(), scene, o, g);
    g.demodulate = gdpt::Demodulation::On;
    const RenderResultGpt on = renderGpt(ctx(), scene, o, g);
    EXPECT_FALSE(off.stats.demodulated);
    EXPECT_TRUE(off.modulation.empty());
    ASSERT_TRUE(on.stats.demodulated);
    EXPECT_GT(on.stats.demodulatedPixels, 0u);
    for (const auto& [a, b] : {std::pair{&off.primal, &on.primal},
                               {&off.dx, &on.dx},
                               {&off.dy, &on.dy},
                               {&off.varPrimal, &on.varPrimal},
                               {&off.direct, &on.direct}})
        for (int c = 0; c < 3; ++c)
            for (std::size_t i = 0; i < a->pixelCount(); ++i) ASSERT_EQ(a->plane(c)[i], b->plane(c)[i]);
    for (int c = 0; c < 3; ++c)
        for (std::size_t i = 0; i < on.modulation.pixelCount(); ++i)
            ASSERT_EQ(on.modulation.plane(c)[i], 1.0f);
}

// A plane z = 0 filling the view of a camera 2 above it (90°), albedo 0.9 times a checkerboard
// texture (0.15 / 0.85, cells of 3 pixels), under a sky of radiance 1: L = albedo there.
Scene checkerUnderSky() {
    Scene s;
    gpu::Material m = test::lambert(glm::vec3(0.9f));
    m.baseColorTex = 0;
    s.materials.push_back(m);
    Texture t;
    t.width = t.height = 8;
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) {
            const float v = (x + y) % 2 ? 0.85f : 0.15f;
            t.texels.emplace_back(v, v * 0.8f, v * 0.6f, 1.0f);
        }
    s.textures.push_back(t);
    // 48 px span 4 world units at z = 0 and uv = world / 2 with 8 texels per uv unit, so a texel
    // (a cell) is 3 pixels; linear filtering blends only near the cell borders.
    const float e = 20.0f;
    s.positions = {{-e, -e, 0}, {e, -e, 0}, {e, e, 0}, {-e, e, 0}};
    s.uvs = {{-e / 2.0f, -e / 2.0f}, {e / 2.0f, -e / 2.0f}, {e / 2.0f, e / 2.0f}, {-e / 2.0f, e / 2.0f}};
    s.triangles = {{0, 1, 2}, {0, 2, 3}};
    s.triangleMaterial = {0, 0};
    s.cameras.push_back(test::lookDown(2.0f, 90.0f));
    return s;
}

TEST_F(Demodulation, ModulatedPrimalOfATexturedPlaneUnderASkyMatchesThePathTracer) {
    const Scene scene = checkerUnderSky();
    ASSERT_TRUE(demodulationApplies(scene));
    RenderOptions o = renderOptions(48, 48, 32, 11);
    o.scene.envRadiance = glm::vec3(1.0f);
    const RenderResultGpt g = renderGpt(ctx(), scene, o);  // Auto: on
    ASSERT_TRUE(g.stats.demodulated);
    EXPECT_GT(g.stats.demodulatedPixels, 48u * 48u * 9 / 10);
    o.spp = 256;
    o.seed = 12;
    const RenderResult pt = renderPt(ctx(), scene, o);
    const int w = 48, h = 48;
    int tests = 0;
    for (int y = 0; y < h; y += 3)
        for (int x = 0; x < w; x += 3) tests += 3;
    const double z = std::max(4.0, test::twoSidedZ(test::sidakAlpha(1e-3, tests)));
    int failures = 0;
    double maxWrong = 0.0;
    bool modulationVaries = false;
    for (int y = 0; y < h; y += 3)
        for (int x = 0; x < w; x += 3)
            for (int c = 0; c < 3; ++c) {
                const double m = g.modulation.at(x, y, c), j = g.primal.at(x, y, c);
                modulationVaries = modulationVaries || m < 0.5;
                const double estimate = m * j + g.direct.at(x, y, c);
                const double var = j * j * g.varModulation.at(x, y, c) + m * m * g.varPrimal.at(x, y, c) +
                                   g.varDirect.at(x, y, c);
                const double right = std::abs(estimate - pt.image.at(x, y, c)) /
                                     std::sqrt(var + pt.varianceOfMean.at(x, y, c));
                if (right > z && failures++ < 10)
                    ADD_FAILURE() << "pixel " << x << "," << y << " channel " << c << ": G-PT " << estimate
                                  << " PT " << pt.image.at(x, y, c) << " z " << right;
                const int xs = std::min(x + 3, w - 1);  // the next cell: the other colour
                maxWrong = std::max(maxWrong, std::abs(estimate - pt.image.at(xs, y, c)) /
                                                  std::sqrt(var + pt.varianceOfMean.at(xs, y, c)));
            }
    EXPECT_EQ(failures, 0) << "pixels outside " << z << " standard errors";
    EXPECT_TRUE(modulationVaries) << "the texture never reached the modulation";
    EXPECT_GT(maxWrong, z) << "power check: the shifted image was not rejected";
}

}  // namespace
}  // namespace gdpt
