// Metropolis light transport (pssmlt, gmlt) against answers it did not make: the white
// furnace, whose every pixel is exactly 1, and the path tracer's image of the Cornell box.
//
// Statistics. A render's pixels are correlated (its chains splat across the image), so the
// tests compare region means over independent renders (seeds): with n seeds, the mean of the
// region means and its standard error (sample sd / sqrt(n)) give a Student t statistic with
// n − 1 degrees of freedom, against the expected value (plus, for the path tracer, its own
// standard error from its per-pixel variances). The threshold is the t quantile of a Šidák-
// corrected family level of 1e-3. Each test checks its power: the same statistic against an
// expectation 5 % off must be rejected, so a test that could not fail would fail.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "gpu_fixture.h"
#include "integrator/integrator.h"
#include "integrator/mlt_integrator.h"
#include "scene/gltf_loader.h"
#include "scene_builders.h"
#include "stats_normal.h"

namespace gdpt {
namespace {

class MltRender : public test::GpuTest {};

constexpr int kSeeds = 10;

// Mean of channel c over the pixels [x0, x1) x [y0, y1).
double regionMean(const Image& im, int c, int x0, int y0, int x1, int y1) {
    double s = 0.0;
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) s += im.at(x, y, c);
    return s / double((x1 - x0) * (y1 - y0));
}

// The mean of `samples` (one per seed), their sample variance and the mean's standard error.
struct SampleMean {
    double mean = 0.0, variance = 0.0, standardError = 0.0;
};
SampleMean sampleMean(const std::vector<double>& samples) {
    SampleMean m;
    for (double s : samples) m.mean += s;
    m.mean /= double(samples.size());
    for (double s : samples) m.variance += (s - m.mean) * (s - m.mean);
    m.variance /= double(samples.size() - 1);
    m.standardError = std::sqrt(m.variance / double(samples.size()));
    return m;
}

// The t statistic of `samples` (one per seed) against `expected` ± expectedSe.
double tStatistic(const std::vector<double>& samples, double expected, double expectedSe) {
    const SampleMean m = sampleMean(samples);
    return (m.mean - expected) / std::sqrt(m.standardError * m.standardError + expectedSe * expectedSe);
}

// The layer that holds the method's splatted estimate: pssmlt's final image, gmlt's primal
// plus direct (the reconstruction has its own tests; its L1 bias at low counts is G-PT's).
const char* estimateLayer(const std::string& method) {
    return method == "gmlt" ? "primal_plus_direct" : "";
}

TEST_F(MltRender, FurnaceMeanIsOneForBothTargets) {
    const Scene scene = loadGltf(std::string(GDPT_SOURCE_DIR) + "/scenes/furnace.gltf");
    const double threshold = test::twoSidedT(test::sidakAlpha(1e-3, 2), kSeeds - 1);
    for (const std::string method : {"pssmlt", "gmlt"}) {
        std::unique_ptr<Integrator> integrator = makeIntegrator(method);
        std::vector<double> means;
        for (int s = 0; s < kSeeds; ++s) {
            const RenderOutput out = integrator->render(ctx(), scene, renderOptions(16, 16, 16, 100 + s));
            const Image& im = out.layer(estimateLayer(method));
            means.push_back(regionMean(im, 1, 0, 0, 16, 16));
            // The very-direct light of the furnace is its emission, 0.5, exactly.
            EXPECT_FLOAT_EQ(out.layer("direct").at(5, 7, 0), 0.5f);
            EXPECT_GT(out.stats.mlt.acceptedSmall, 0u);
            EXPECT_GT(out.stats.mlt.acceptedLarge, 0u);
        }
        const double t = tStatistic(means, 1.0, 0.0);
        EXPECT_LT(std::abs(t), threshold) << method << ": mean of " << kSeeds << " image means is off 1";
        EXPECT_GT(std::abs(tStatistic(means, 1.05, 0.0)), threshold) << method << ": the test has no power";
    }
}

TEST_F(MltRender, CornellBoxQuadrantsMatchThePathTracer) {
    const Scene scene = loadGltf(std::string(GDPT_SOURCE_DIR) + "/scenes/cornell_box.gltf");
    constexpr int kSize = 32, kHalf = kSize / 2;
    const RenderOutput pt = makeIntegrator("pt")->render(ctx(), scene, renderOptions(kSize, kSize, 1024, 7));
    const Image& ptImage = pt.image();
    const Image& ptVar = pt.layer("variance");
    const double threshold = test::twoSidedT(test::sidakAlpha(1e-3, 2 * 4 * 3), kSeeds - 1);
    for (const std::string method : {"pssmlt", "gmlt"}) {
        std::unique_ptr<Integrator> integrator = makeIntegrator(method);
        std::vector<std::vector<double>> quadrant(12);
        for (int s = 0; s < kSeeds; ++s) {
            const RenderOutput out =
                integrator->render(ctx(), scene, renderOptions(kSize, kSize, 32, 200 + s));
            const Image& im = out.layer(estimateLayer(method));
            for (int q = 0; q < 4; ++q)
                for (int c = 0; c < 3; ++c)
                    quadrant[std::size_t(q * 3 + c)].push_back(regionMean(
                        im, c, (q % 2) * kHalf, (q / 2) * kHalf, (q % 2 + 1) * kHalf, (q / 2 + 1) * kHalf));
        }
        double worstWrong = 0.0;
        for (int q = 0; q < 4; ++q)
            for (int c = 0; c < 3; ++c) {
                const int x0 = (q % 2) * kHalf, y0 = (q / 2) * kHalf;
                const double expected = regionMean(ptImage, c, x0, y0, x0 + kHalf, y0 + kHalf);
                // Pixels of a PT render are independent: the variance of the region mean is
                // the sum of the per-pixel variances of the mean over the pixel count squared.
                const double se =
                    std::sqrt(regionMean(ptVar, c, x0, y0, x0 + kHalf, y0 + kHalf) / (kHalf * kHalf));
                const std::vector<double>& v = quadrant[std::size_t(q * 3 + c)];
                EXPECT_LT(std::abs(tStatistic(v, expected, se)), threshold)
                    << method << " quadrant " << q << " channel " << c << ": PT " << expected;
                worstWrong = std::max(worstWrong, std::abs(tStatistic(v, 1.05 * expected, 1.05 * se)));
            }
        EXPECT_GT(worstWrong, threshold) << method << ": the test has no power";
    }
}

// The very-direct image (the emission the camera sees, which the chains leave out) takes PT's
// and G-PT's emitter supersampling at the light's rim: there the pixels get their direct
// phase's 16 camera samples of k rays each from the supersampling pass instead of 16 rays
// (k = 16 at 64², fewer on smaller images, where the pass's ray budget cuts it). Over 10 seeds each (pssmlt:
// the same direct phase as gmlt's, cheaper chains), in the rim pixels (those whose direct value
// varies between the renders without it): the mean with the supersampling matches the mean
// without (Welch's t, both unbiased), its seed-to-seed variance is far below (k times the rays:
// about 1/k of it; the test asks for less than 1/4, which with 9 degrees of freedom per rim
// pixel and a few dozen pixels an F statistic misses by chance with a probability far below
// 1e-3), and the power check: a mean 5 % off is rejected.
TEST_F(MltRender, VeryDirectLightIsSupersampledAtTheLightsRim) {
    const Scene scene = loadGltf(std::string(GDPT_SOURCE_DIR) + "/scenes/cornell_box.gltf");
    constexpr int kSize = 64;
    std::unique_ptr<Integrator> pssmlt = makeIntegrator("pssmlt");
    std::vector<Image> on, off;
    for (int s = 0; s < kSeeds; ++s) {
        RenderOptions o = renderOptions(kSize, kSize, 1, 300 + s);
        const RenderOutput a = pssmlt->render(ctx(), scene, o);
        EXPECT_GT(a.stats.emitterSupersampledPixels, 0u);
        // The pass's ray budget (a quarter ray per pixel and camera sample) may cut the 16.
        EXPECT_GE(a.stats.emitterRaysPerSample, 8u);
        on.push_back(a.layer("direct"));
        o.emitterSupersampling = 0;
        const RenderOutput b = pssmlt->render(ctx(), scene, o);
        EXPECT_EQ(b.stats.emitterSupersampledPixels, 0u);
        off.push_back(b.layer("direct"));
    }
    std::vector<std::size_t> rim;
    for (std::size_t p = 0; p < std::size_t(kSize * kSize); ++p)
        for (int s = 1; s < kSeeds; ++s)
            if (off[std::size_t(s)].plane(1)[p] != off[0].plane(1)[p]) {
                rim.push_back(p);
                break;
            }
    ASSERT_GE(rim.size(), 12u) << "the light's rim";
    // Per seed the rim's mean; per pixel the variance over seeds, summed.
    std::vector<double> meanOn, meanOff;
    double varOn = 0.0, varOff = 0.0;
    for (int s = 0; s < kSeeds; ++s) {
        double a = 0.0, b = 0.0;
        for (std::size_t p : rim) a += on[std::size_t(s)].plane(1)[p], b += off[std::size_t(s)].plane(1)[p];
        meanOn.push_back(a / double(rim.size()));
        meanOff.push_back(b / double(rim.size()));
    }
    for (std::size_t p : rim) {
        std::vector<double> a, b;
        for (int s = 0; s < kSeeds; ++s) {
            a.push_back(on[std::size_t(s)].plane(1)[p]);
            b.push_back(off[std::size_t(s)].plane(1)[p]);
        }
        varOn += sampleMean(a).variance;
        varOff += sampleMean(b).variance;
    }
    EXPECT_LT(4.0 * varOn, varOff) << rim.size() << " rim pixels";
    const SampleMean without = sampleMean(meanOff);
    const double threshold = test::twoSidedT(test::sidakAlpha(1e-3, 1), kSeeds - 1);
    EXPECT_LT(std::abs(tStatistic(meanOn, without.mean, without.standardError)), threshold)
        << "rim mean " << without.mean;
    EXPECT_GT(std::abs(tStatistic(meanOn, 1.05 * without.mean, without.standardError)), threshold)
        << "the test has no power";
}

// gmlt's kernel in the split bounce loop build (mlt_split: G-PT's sample with its bounces after
// every offset reconnected run without the code for offsets with vertices of their own, and the
// fan, beams and bundles of gpt_split) is a schedule of the same sample: the same bits as the
// single loop, in every layer, with the same acceptances; on the glossy box with the half-vector
// threshold raised (offsets keep their own vertices through the rough metal too), an environment
// and a point light.
TEST_F(MltRender, SplitBounceLoopGivesTheSameBitsAsTheSingleLoop) {
    Scene scene = test::glossyCornellWithPointLight();
    RenderOptions o = renderOptions(20, 16, 6, 11);
    o.scene.shiftThreshold = 0.5f;
    o.scene.envRadiance = glm::vec3(0.4f, 0.5f, 0.6f);
    MethodOptions split, single;
    split.mlt.splitBounce = GptPassOptions::SplitBounce::On;
    single.mlt.splitBounce = GptPassOptions::SplitBounce::Off;
    const RenderOutput a = makeIntegrator("gmlt", split)->render(ctx(), scene, o);
    const RenderOutput b = makeIntegrator("gmlt", single)->render(ctx(), scene, o);
    EXPECT_TRUE(a.stats.gptSplitBounce);
    EXPECT_FALSE(b.stats.gptSplitBounce);
    EXPECT_EQ(a.stats.raysTraced, b.stats.raysTraced);
    EXPECT_EQ(a.stats.mlt.acceptedSmall, b.stats.mlt.acceptedSmall);
    EXPECT_EQ(a.stats.mlt.acceptedLarge, b.stats.mlt.acceptedLarge);
    ASSERT_EQ(a.layers.size(), b.layers.size());
    for (std::size_t i = 0; i < a.layers.size(); ++i)
        for (int ch = 0; ch < 3; ++ch)
            ASSERT_EQ(a.layers[i].image.plane(ch), b.layers[i].image.plane(ch)) << a.layers[i].name;
}

TEST_F(MltRender, DeterministicPerSeed) {
    const Scene scene = loadGltf(std::string(GDPT_SOURCE_DIR) + "/scenes/glossy_cornell.gltf");
    std::unique_ptr<Integrator> gmlt = makeIntegrator("gmlt");
    const RenderOutput a = gmlt->render(ctx(), scene, renderOptions(24, 24, 8, 3));
    const RenderOutput b = gmlt->render(ctx(), scene, renderOptions(24, 24, 8, 3));
    const RenderOutput c = gmlt->render(ctx(), scene, renderOptions(24, 24, 8, 4));
    ASSERT_EQ(a.layers.size(), b.layers.size());
    for (std::size_t i = 0; i < a.layers.size(); ++i)
        for (int ch = 0; ch < 3; ++ch)
            ASSERT_EQ(a.layers[i].image.plane(ch), b.layers[i].image.plane(ch)) << i;
    EXPECT_NE(a.image().plane(0), c.image().plane(0));
    EXPECT_EQ(a.stats.mlt.acceptedSmall, b.stats.mlt.acceptedSmall);
}

}  // namespace
}  // namespace gdpt
