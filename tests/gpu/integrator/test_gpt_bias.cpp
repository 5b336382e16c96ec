// Bias of G-PT's final image against path tracing, over independent seeds:
//   - the block test: 16×16-pixel block means of the final image (R + G + B) over N seeds
//     against the block means of one long PT render (independent seeds), by a Student t test
//     per block (t = (mean − PT) / sqrt(s²/N + var_PT), N − 1 degrees of freedom, which is
//     conservative: the PT term only adds degrees of freedom), Šidák-corrected to a family
//     level of 1e-3 over the blocks of a scene; and the whole image's mean the same way;
//   - power: the same test on the default reconstruction without its debiasing
//     (--debias-cells 0) of the same samples must reject, on the scenes where it is biased --
//     so the test can fail;
//   - the white furnace (every pixel exactly 1): the image mean of every --recon within its
//     noise of 1;
//   - the integrator's final image is the debiased reconstruction + direct, bit for bit.
// The renders are small (64×64, few samples), as the renders where L1's bias is largest.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "gpu_fixture.h"
#include "integrator/gpt_integrator.h"
#include "integrator/pt_sampler.h"
#include "poisson/debias.h"
#include "same_bits.h"
#include "scene/gltf_loader.h"
#include "stats_normal.h"

namespace gdpt {
namespace {

Scene sceneFile(const char* name) {
    return loadGltf(std::string(GDPT_SOURCE_DIR) + "/scenes/" + name);
}

// Sums of R + G + B over the blocks of an image (block b = by * (w / B) + bx), divided by the
// block's pixels: block means.
std::vector<double> blockMeans(const Image& im, int block) {
    const int bw = im.width() / block, bh = im.height() / block;
    std::vector<double> m(std::size_t(bw) * bh, 0.0);
    for (int y = 0; y < bh * block; ++y)
        for (int x = 0; x < bw * block; ++x)
            for (int c = 0; c < 3; ++c) m[std::size_t(y / block) * bw + x / block] += im.at(x, y, c);
    for (double& v : m) v /= double(block) * block;
    return m;
}

// Per-seed statistics of a set of block means (the last entry: the whole image's mean).
struct SeedStats {
    std::vector<double> sum, sumSq;
    int n = 0;
    void add(const std::vector<double>& v) {
        if (sum.empty()) sum.assign(v.size(), 0.0), sumSq.assign(v.size(), 0.0);
        for (std::size_t i = 0; i < v.size(); ++i) sum[i] += v[i], sumSq[i] += v[i] * v[i];
        ++n;
    }
    [[nodiscard]] double mean(std::size_t i) const { return sum[i] / n; }
    [[nodiscard]] double varOfMean(std::size_t i) const {
        return std::max(0.0, (sumSq[i] - sum[i] * sum[i] / n) / (n - 1)) / n;
    }
};

std::vector<double> withImageMean(std::vector<double> blocks) {
    double s = 0.0;
    for (double v : blocks) s += v;
    blocks.push_back(s / double(blocks.size()));
    return blocks;
}

// The largest |t| over blocks and the image mean against expected values (with their own
// variances of the mean), and where it was.
struct TResult {
    double maxT = 0.0;
    std::size_t where = 0;
    double relativeBias = 0.0;  // of the worst block: (mean − expected) / expected
};

TResult tTest(const SeedStats& s, const std::vector<double>& expected,
              const std::vector<double>& expectedVar) {
    TResult r;
    for (std::size_t i = 0; i < expected.size(); ++i) {
        const double t = std::abs(s.mean(i) - expected[i]) / std::sqrt(s.varOfMean(i) + expectedVar[i]);
        if (t > r.maxT) {
            r.maxT = t;
            r.where = i;
            r.relativeBias = (s.mean(i) - expected[i]) / expected[i];
        }
    }
    return r;
}

class GptBias : public test::KeptPipelinesTest {
protected:
    static void checkScene(const char* file, int size, std::uint32_t spp, int seeds, std::uint32_t ptSpp,
                           bool publishedBiased);
};

// N seeds of the default G-PT (its default reconstruction, debiased) and of the same
// reconstruction undebiased (the same samples), against a PT render of `ptSpp`: the default
// passes the block test, the undebiased one must fail it where `publishedBiased`.
void GptBias::checkScene(const char* file, int size, std::uint32_t spp, int seeds, std::uint32_t ptSpp,
                         bool publishedBiased) {
    const vk::Context& ctx = keeping();
    const Scene scene = sceneFile(file);
    const int block = 16;
    const RenderResult pt = renderPt(ctx, scene, renderOptions(size, size, ptSpp, 777));
    std::vector<double> expected = withImageMean(blockMeans(pt.image, block));
    // PT pixels are independent: a block mean's variance is the sum of its pixels' variances
    // (summed over the three channels) / pixels².
    const std::vector<double> varBlocks = blockMeans(pt.varianceOfMean, block);
    std::vector<double> expectedVar;
    for (double v : varBlocks) expectedVar.push_back(v / (double(block) * block));
    double imageVar = 0.0;
    for (double v : varBlocks) imageVar += v / (double(block) * block);
    expectedVar.push_back(imageVar / (double(varBlocks.size()) * double(varBlocks.size())));

    GptOptions published;
    published.debiasCells = 0;
    GptIntegrator integrator("gpt", published);
    SeedStats debiased, raw;
    std::string reconLayer;  // the scene's reconstruction (gpt_reconstruction.h)
    for (int s = 0; s < seeds; ++s) {
        const RenderOutput out =
            integrator.render(ctx, scene, renderOptions(size, size, spp, 1000u + unsigned(s)));
        ASSERT_EQ(out.stats.nanSamples, 0u);
        ASSERT_FALSE(out.stats.reconstructions.empty());
        reconLayer = "recon_" + out.stats.reconstructions.front().method;
        Image recon = out.layer(reconLayer);
        raw.add(withImageMean(blockMeans(out.layer(""), block)));
        debiasImage(recon, out.layer("primal"), kDefaultDebiasCells);
        debiased.add(withImageMean(blockMeans(addImages(recon, out.layer("direct")), block)));
    }
    const double limit = test::twoSidedT(test::sidakAlpha(1e-3, int(expected.size())), seeds - 1);
    const TResult d = tTest(debiased, expected, expectedVar), p = tTest(raw, expected, expectedVar);
    EXPECT_LE(d.maxT, limit) << file << ": the debiased " << reconLayer << "'s block " << d.where
                             << " is off by " << 100.0 * d.relativeBias << " % (t " << d.maxT << ")";
    if (publishedBiased) {
        EXPECT_GT(p.maxT, limit) << file << ": the test has no power: the undebiased " << reconLayer
                                 << "'s worst block " << p.where << " is off by " << 100.0 * p.relativeBias
                                 << " %, t " << p.maxT;
    }
    std::printf(
        "%s (%s): limit %.2f; debiased worst t %.2f (%+.2f %%); undebiased worst t %.2f (%+.2f %%), image "
        "mean %+.2f %%\n",
        file, reconLayer.c_str(), limit, d.maxT, 100.0 * d.relativeBias, p.maxT, 100.0 * p.relativeBias,
        100.0 * (raw.mean(expected.size() - 1) / expected.back() - 1.0));
}

TEST_F(GptBias, DoorAjarBlocksAreUnbiasedWhereThePublishedL1IsDark) {
    checkScene("indirect_gap.gltf", 64, 8, 24, 2048, true);
}

TEST_F(GptBias, CornellBoxBlocksAreUnbiased) {
    checkScene("cornell_box.gltf", 64, 4, 24, 1024, true);
}

// The glossy box's reconstruction is WL2 (its mirror sphere: gpt_reconstruction.h), whose
// weights leave the pixels that met a firefly dark before the debiasing (worst block −29 %,
// t ≈ 60). At 48² the debiased blocks pass with t below 2. At 64² and 4 or 8 spp one block sits
// at the limit for every reconstruction and for the unbiased primal itself (WL2 t 5.3-6.0, WL1
// 5.2-5.9, L1 5.2, the primal 4.8; 2.2-2.7 % below PT): light reflected by the mirror reaches it
// as rare fireflies, whose block means over 24 seeds are too skewed for a t test; at 16 spp it
// passes (t 1.7-3.2), at three times this test's cost.
TEST_F(GptBias, GlossyBoxBlocksAreUnbiased) {
    checkScene("glossy_cornell.gltf", 48, 8, 24, 2048, true);
}

TEST_F(GptBias, FurnaceMeanIsOneForEveryReconstruction) {
    const Scene scene = sceneFile("furnace.gltf");
    GptOptions o;
    o.reconstructionByScene = false;  // these four, L1 giving the final image
    o.reconstructions = {Reconstruction::L1, Reconstruction::L2, Reconstruction::WeightedL2,
                         Reconstruction::WeightedL1};
    GptIntegrator integrator("gpt", o);
    o.debiasCells = 0;
    GptIntegrator published("gpt", o);
    const int seeds = 16;
    std::vector<SeedStats> debiased(4), raw(4);
    for (int s = 0; s < seeds; ++s) {
        const RenderOptions ro = renderOptions(64, 64, 4, 500u + unsigned(s));
        const RenderOutput out = integrator.render(keeping(), scene, ro);
        const RenderOutput pub = published.render(keeping(), scene, ro);
        for (std::size_t r = 0; r < o.reconstructions.size(); ++r) {
            const std::string name = std::string("recon_") + toString(o.reconstructions[r]);
            const auto mean = [&](const RenderOutput& x) {
                const std::array<double, 3> m = addImages(x.layer(name), x.layer("direct")).meanRgb();
                return std::vector<double>{(m[0] + m[1] + m[2]) / 3.0};
            };
            debiased[r].add(mean(out));
            raw[r].add(mean(pub));
        }
    }
    const double limit = test::twoSidedT(test::sidakAlpha(1e-3, 4), seeds - 1);
    for (std::size_t r = 0; r < o.reconstructions.size(); ++r) {
        const char* name = toString(o.reconstructions[r]);
        const TResult d = tTest(debiased[r], {1.0}, {0.0}), p = tTest(raw[r], {1.0}, {0.0});
        EXPECT_LE(d.maxT, limit) << name << ": furnace mean off by " << 100.0 * d.relativeBias << " %";
        std::printf("furnace %s: debiased %+.3f %% (t %.2f), published %+.3f %% (t %.2f), limit %.2f\n", name,
                    100.0 * d.relativeBias, d.maxT, 100.0 * p.relativeBias, p.maxT, limit);
        // Power: the published L1 is dark here (Kettunen et al.'s L1 follows the median).
        if (o.reconstructions[r] == Reconstruction::L1) {
            EXPECT_GT(p.maxT, limit) << "no power on the furnace";
        }
    }
}

TEST_F(GptBias, TheFinalImageIsTheDebiasedReconstructionPlusDirect) {
    const Scene scene = sceneFile("cornell_box.gltf");
    GptIntegrator integrator("gpt", GptOptions{});
    const RenderOutput out = integrator.render(keeping(), scene, renderOptions(48, 40, 2, 9));
    GptOptions o;
    o.debiasCells = 0;
    GptIntegrator published("gpt", o);
    const RenderOutput raw = published.render(keeping(), scene, renderOptions(48, 40, 2, 9));
    const std::string layer = std::string("recon_") + toString(o.reconstructions.front());
    Image recon = raw.layer(layer);
    const DebiasReport r = debiasImage(recon, raw.layer("primal"), kDefaultDebiasCells);
    test::expectSameBits(out.layer(layer), recon, layer);
    test::expectSameBits(out.layer(""), addImages(recon, out.layer("direct")), "final");
    EXPECT_NE(r.meanCorrection, 0.0);
    ASSERT_EQ(out.stats.reconstructions.size(), 1u);
    EXPECT_EQ(out.stats.reconstructions[0].debiasScale, 5);  // 40 px / 8 cells
    EXPECT_DOUBLE_EQ(out.stats.reconstructions[0].debiasMeanChange, r.meanCorrection / r.meanBefore);
}

}  // namespace
}  // namespace gdpt
