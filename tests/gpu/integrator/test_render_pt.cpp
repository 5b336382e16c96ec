// Path tracer against things we did not make up: the white furnace (closed emitting sphere,
// L = Le / (1 - a)), an emitter seen directly (exactly its radiance), and determinism.
// Every tolerance is a number of standard errors estimated from the per-pixel sample
// variance the renderer accumulates, with fixed seeds.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "gpu_fixture.h"
#include "integrator/pt_sampler.h"
#include "integrator/sampling_loop.h"
#include "render/passes/pt_pass.h"
#include "scene/procedural.h"
#include "scene_builders.h"
#include "stats_normal.h"
#include "vk/commands.h"

namespace gdpt {
namespace {

class RenderPt : public test::GpuTest {
protected:
    RenderResult render(const Scene& scene, int w, int h, std::uint32_t spp, std::uint32_t seed = 1) {
        return renderPt(ctx(), scene, renderOptions(w, h, spp, seed));
    }
};

// Closed sphere, Lambertian albedo a, uniform emission Le, camera inside: every path sees
// L = Le (1 + a + a^2 + ...) = Le / (1 - a) (Neumann series). Tests: the image mean and
// 16 block means (16 px each) against that value. Each mean's standard error is
// sqrt(sum of per-pixel variances of the mean) / pixels; the block tests are Šidák-corrected
// (family alpha = 1e-3 over 16 blocks x 3 channels), the image mean uses 4 sigma.
void checkFurnace(const RenderResult& r, double expected) {
    const Image& img = r.image;
    const Image& var = r.varianceOfMean;
    const double zBlock = test::twoSidedZ(test::sidakAlpha(1e-3, 16 * 3));
    for (int c = 0; c < 3; ++c) {
        double sum = 0.0, varSum = 0.0;
        for (std::size_t i = 0; i < img.pixelCount(); ++i) {
            sum += img.plane(c)[i];
            varSum += var.plane(c)[i];
        }
        const double n = static_cast<double>(img.pixelCount());
        const double mean = sum / n, se = std::sqrt(varSum) / n;
        EXPECT_GT(se, 0.0);
        EXPECT_LT(std::abs(mean - expected), 4.0 * se) << "channel " << c << " mean " << mean << " se " << se;
        for (int by = 0; by < 4; ++by)
            for (int bx = 0; bx < 4; ++bx) {
                double bs = 0.0, bv = 0.0;
                for (int y = by * 4; y < by * 4 + 4; ++y)
                    for (int x = bx * 4; x < bx * 4 + 4; ++x) {
                        bs += img.at(x, y, c);
                        bv += var.at(x, y, c);
                    }
                const double bm = bs / 16.0, bse = std::sqrt(bv) / 16.0;
                EXPECT_LT(std::abs(bm - expected), zBlock * bse) << "block " << bx << "," << by;
            }
    }
    EXPECT_EQ(r.stats.nanSamples, 0u);
}

TEST_F(RenderPt, WhiteFurnaceAlbedoHalf) {
    const RenderResult r = render(makeFurnaceSphere(0.5f, glm::vec3(1.0f), 3), 16, 16, 256);
    checkFurnace(r, 1.0 / (1.0 - 0.5));
}

TEST_F(RenderPt, WhiteFurnaceAlbedoPointEight) {
    const RenderResult r = render(makeFurnaceSphere(0.8f, glm::vec3(0.25f), 3), 16, 16, 256, 7);
    checkFurnace(r, 0.25 / (1.0 - 0.8));
}

// Two emitters of unequal power (the sphere's cap is a copy of its material): whichever rule
// next-event estimation picks them by, the image is the furnace's. A rule whose
// probabilities the light sampling and the MIS weight of a BSDF-sampled hit disagree on
// biases it (a test build whose MIS weights used pmf x 1.25 failed every rule).
TEST_F(RenderPt, WhiteFurnaceWithTwoEmittersUnderEveryLightSelection) {
    const Scene scene = makeTwoEmitterFurnace(0.5f, glm::vec3(1.0f), 3);
    for (LightSelection sel :
         {LightSelection::Power, LightSelection::Uniform, LightSelection::Mixed, LightSelection::Probe}) {
        SCOPED_TRACE(toString(sel));
        RenderOptions o = renderOptions(16, 16, 256, 11);
        o.scene.lightSelection = sel;
        checkFurnace(renderPt(ctx(), scene, o), 1.0 / (1.0 - 0.5));
    }
}

// The probe rule where `mixed` wastes samples: 96 % of the power is behind the back wall,
// lighting nothing inside (scene_builders.h). `mixed` sends 73 % of the NEE samples there,
// the probe rule 37 % (half its `mixed` share), so the ceiling light's direct and indirect
// NEE estimates, most of the image's variance, get 0.63 of the samples instead of 0.27. Both
// rules are unbiased: their image means agree within 4 standard errors of the difference.
// The summed per-pixel variance of the mean falls to 0.50 of `mixed`'s (fixed seed,
// measured 2026-12-05); the bound 0.75 fails if the probe gave the hidden emitter its `mixed`
// share (ratio 1) or more.
TEST_F(RenderPt, ProbeRuleLowersTheVarianceWhereMixedSamplesAHiddenEmitter) {
    std::uint32_t hidden = 0;
    const Scene scene = test::cornellBoxWithHiddenEmitter(hidden);
    double mean[2] = {0.0, 0.0}, var[2] = {0.0, 0.0};
    const LightSelection rules[2] = {LightSelection::Mixed, LightSelection::Probe};
    for (int k = 0; k < 2; ++k) {
        RenderOptions o = renderOptions(32, 32, 64, 5);
        o.scene.lightSelection = rules[k];
        const RenderResult r = renderPt(ctx(), scene, o);
        for (int c = 0; c < 3; ++c)
            for (std::size_t i = 0; i < r.image.pixelCount(); ++i) {
                mean[k] += r.image.plane(c)[i];
                var[k] += r.varianceOfMean.plane(c)[i];
            }
    }
    EXPECT_LT(std::abs(mean[0] - mean[1]), 4.0 * std::sqrt(var[0] + var[1]))
        << "image sums " << mean[0] << " (mixed) and " << mean[1] << " (probe)";
    EXPECT_LT(var[1], 0.75 * var[0]) << "summed variance of the mean: mixed " << var[0] << ", probe "
                                     << var[1];
}

// A black emitter filling the view returns its radiance in every pixel, with no noise.
TEST_F(RenderPt, EmitterSeenDirectlyIsExact) {
    const glm::vec3 le(3.0f, 2.0f, 0.5f);
    const RenderResult r = render(makeEmissiveQuad(le), 24, 16, 4);
    for (int c = 0; c < 3; ++c)
        for (std::size_t i = 0; i < r.image.pixelCount(); ++i) {
            ASSERT_FLOAT_EQ(r.image.plane(c)[i], le[c]) << "pixel " << i;
            ASSERT_EQ(r.varianceOfMean.plane(c)[i], 0.0f);
        }
}

// Same scene, seed and spp give bit-identical images; another seed gives another image.
TEST_F(RenderPt, DeterministicPerSeed) {
    const Scene scene = makeCornellBox();
    const RenderResult a = render(scene, 32, 32, 6, 3);
    const RenderResult b = render(scene, 32, 32, 6, 3);
    const RenderResult c = render(scene, 32, 32, 6, 4);
    int differentSeedDiffers = 0;
    for (int ch = 0; ch < 3; ++ch) {
        ASSERT_EQ(a.image.plane(ch), b.image.plane(ch));
        ASSERT_EQ(a.varianceOfMean.plane(ch), b.varianceOfMean.plane(ch));
        differentSeedDiffers += a.image.plane(ch) != c.image.plane(ch);
    }
    EXPECT_GT(differentSeedDiffers, 0);
}

// The partial last pass of a timed render: rows that one more sample covers in the time
// left, with the 10 % margin, never more than the image, none without time or a rate.
TEST(PartialPass, RowsFitTheTimeLeft) {
    EXPECT_EQ(partialPassRows(0.5, 1.0, 100), 45u);
    EXPECT_EQ(partialPassRows(0.05, 1.0, 100), 4u);
    EXPECT_EQ(partialPassRows(5.0, 1.0, 100), 100u);
    EXPECT_EQ(partialPassRows(0.0, 1.0, 100), 0u);
    EXPECT_EQ(partialPassRows(-1.0, 1.0, 100), 0u);
    EXPECT_EQ(partialPassRows(0.5, 0.0, 100), 0u);
}

// A row-limited batch samples exactly those rows: after two whole samples and one more for
// the first 3 rows, those rows hold the statistics of three whole samples bit for bit and the
// others those of two.
TEST_F(RenderPt, RowLimitedBatchSamplesOnlyThoseRows) {
    const Scene scene = makeCornellBox();
    SceneGpuOptions so;
    so.width = 16;
    so.height = 12;
    SceneGpu sceneGpu(ctx(), scene, so);
    auto statsAfter = [&](std::uint32_t lastRows) {
        PtPass pass(ctx(), sceneGpu, WorkgroupSize{}, 0);
        vk::CommandStream stream(ctx(), "row-limited");
        pass.record(stream.begin(), 0, 2, 5, nullptr);
        stream.submitAndWait();
        pass.record(stream.begin(), 2, 1, 5, nullptr, lastRows);
        stream.submitAndWait();
        return pass.downloadStats()[0];
    };
    const auto partial = statsAfter(3), full = statsAfter(12);
    const auto two = [&] {
        PtPass pass(ctx(), sceneGpu, WorkgroupSize{}, 0);
        vk::CommandStream stream(ctx(), "two");
        pass.record(stream.begin(), 0, 2, 5, nullptr);
        stream.submitAndWait();
        return pass.downloadStats()[0];
    }();
    for (std::size_t i = 0; i < partial.size(); ++i) {
        const auto& expected = i < 3u * 16u ? full[i] : two[i];
        ASSERT_EQ(partial[i].count, i < 3u * 16u ? 3u : 2u) << "pixel " << i;
        ASSERT_EQ(0, std::memcmp(&partial[i], &expected, sizeof expected)) << "pixel " << i;
    }
}

// A timed render's counters agree with its sample counts: every pixel got `spp` samples and
// the rows of the partial pass one more.
TEST_F(RenderPt, TimedRenderCountsWholeAndPartialPasses) {
    RenderOptions o = renderOptions(32, 24, 1, 2);
    o.timeBudget = 0.6;
    const RenderResult r = renderPt(ctx(), makeCornellBox(), o);
    EXPECT_GE(r.stats.spp, 1u);
    EXPECT_LT(r.stats.partialPassRows, 24u);
    EXPECT_EQ(r.stats.pathsCompleted,
              std::uint64_t{r.stats.spp} * 32u * 24u + std::uint64_t{r.stats.partialPassRows} * 32u);
}

}  // namespace
}  // namespace gdpt
