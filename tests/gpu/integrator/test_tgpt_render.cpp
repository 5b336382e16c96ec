// Temporal G-PT (tgpt_integrator.h) against answers it did not make:
//   - a still scene rendered as frames has temporal differences exactly 0 (the paired halves
//     replay the same paths), and its reconstruction is tied across window boundaries;
//   - E[dt] = I_f+1 − I_f: block means of dt over independent seeds against the difference of
//     two path-traced frames of the moving-box animation (many samples, independent), by a
//     Student t test per block (Šidák-corrected family level 1e-3); the test shows its power
//     by rejecting the difference of the frames the other way round;
//   - the same seed gives the same bits.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "gpu_fixture.h"
#include "integrator/integrator.h"
#include "integrator/pt_sampler.h"
#include "integrator/tgpt_integrator.h"
#include "same_bits.h"
#include "scene/gltf_loader.h"
#include "scene/procedural.h"
#include "stats_normal.h"
#include "util/frame_pattern.h"

namespace gdpt {
namespace {

// Many short renders of the same kernels: a context that keeps its pipelines.
class TgptRender : public test::KeptPipelinesTest {};

FrameWindow windowOf(std::function<Scene(int)> scene, int first, int count, unsigned seed,
                     bool starts = true) {
    FrameWindow w;
    w.first = first;
    w.count = count;
    w.scene = std::move(scene);
    w.seed = [seed](int f) { return sequenceFrameSeed(seed, f); };
    w.startsSequence = starts;
    return w;
}

TEST_F(TgptRender, AStillSceneHasZeroTemporalDifferencesAndJoinsWindows) {
    const Scene box = makeCornellBox();
    TgptOptions o;
    o.window = 2;
    TgptIntegrator tgpt(o);
    RenderOptions options = renderOptions(20, 16, 4, 0);
    const auto still = [&](int) { return box; };
    const std::vector<RenderOutput> first = tgpt.renderWindow(keeping(), windowOf(still, 0, 2, 3), options);
    const std::vector<RenderOutput> second =
        tgpt.renderWindow(keeping(), windowOf(still, 2, 2, 3, false), options);
    ASSERT_EQ(first.size(), 2u);
    ASSERT_EQ(second.size(), 2u);
    EXPECT_FALSE(first[0].stats.tgpt.temporalToPrevious);
    EXPECT_TRUE(first[1].stats.tgpt.temporalToPrevious);
    EXPECT_FALSE(first[0].stats.tgpt.joinedPreviousWindow);
    EXPECT_TRUE(second[0].stats.tgpt.joinedPreviousWindow);
    EXPECT_TRUE(second[0].stats.tgpt.temporalToPrevious);
    EXPECT_EQ(first[1].stats.tgpt.firstHalfSpp, 2u);
    EXPECT_EQ(first[1].stats.spp, 4u);
    for (const auto* frame : {&first[1], &second[0], &second[1]})
        for (int c = 0; c < 3; ++c)
            for (float v : frame->layer("dt").plane(c)) ASSERT_EQ(v, 0.0f);
    // The halves of frames 0 and 1 differ (other seeds), so their primals do, but not dt.
    EXPECT_NE(first[0].layer("primal").plane(0), first[1].layer("primal").plane(0));
    for (const RenderOutput& f : first) {
        ASSERT_EQ(f.stats.reconstructions.size(), 1u);
        EXPECT_TRUE(f.stats.reconstructions[0].converged);
        EXPECT_EQ(f.stats.reconstructions[0].method, "spacetime_l1");
    }
}

// Block means of dt (frame 1 − frame 0 of moving_box at 2 fps) over independent seeds against
// the difference of the two frames path-traced with many samples.
TEST_F(TgptRender, TemporalDifferencesAreUnbiased) {
    const GltfAsset asset(std::string(GDPT_SOURCE_DIR) + "/scenes/moving_box.gltf");
    const auto sceneAt = [&](int f) { return asset.instance(0, f * 0.5); };
    const int w = 32, h = 24, block = 8, bx = w / block, by = h / block;
    constexpr int kSeeds = 16;
    TgptOptions o;
    o.window = 2;
    o.l1 = false;
    TgptIntegrator tgpt(o);
    std::vector<std::vector<double>> blocks(bx * by * 3);  // per block and channel: one value per seed
    for (int seed = 0; seed < kSeeds; ++seed) {
        const auto frames = tgpt.renderWindow(keeping(), windowOf(sceneAt, 0, 2, unsigned(seed) * 7919u),
                                              renderOptions(w, h, 8, 0));
        const Image& dt = frames[1].layer("dt");
        for (int c = 0; c < 3; ++c)
            for (int b = 0; b < bx * by; ++b) {
                double sum = 0.0;
                for (int y = 0; y < block; ++y)
                    for (int x = 0; x < block; ++x)
                        sum += dt.at((b % bx) * block + x, (b / bx) * block + y, c);
                blocks[(b * 3) + c].push_back(sum / (block * block));
            }
    }
    // The reference: the two frames path-traced, independent of each other and of tgpt.
    const RenderResult pt0 = renderPt(keeping(), sceneAt(0), renderOptions(w, h, 2048, 101));
    const RenderResult pt1 = renderPt(keeping(), sceneAt(1), renderOptions(w, h, 2048, 202));
    const double threshold = test::twoSidedT(test::sidakAlpha(1e-3, bx * by * 3), kSeeds - 1);
    const auto rejected = [&](double sign) {
        int count = 0;
        double worst = 0.0;
        for (int c = 0; c < 3; ++c)
            for (int b = 0; b < bx * by; ++b) {
                double ref = 0.0, refVar = 0.0;
                for (int y = 0; y < block; ++y)
                    for (int x = 0; x < block; ++x) {
                        const int px = (b % bx) * block + x, py = (b / bx) * block + y;
                        ref += pt1.image.at(px, py, c) - pt0.image.at(px, py, c);
                        refVar += pt1.varianceOfMean.at(px, py, c) + pt0.varianceOfMean.at(px, py, c);
                    }
                ref = sign * ref / (block * block);
                refVar /= double(block * block) * double(block * block);
                const std::vector<double>& v = blocks[(b * 3) + c];
                double mean = 0.0, m2 = 0.0;
                for (double x : v) mean += x;
                mean /= kSeeds;
                for (double x : v) m2 += (x - mean) * (x - mean);
                const double se2 = m2 / (kSeeds - 1) / kSeeds + refVar;
                const double t = (mean - ref) / std::sqrt(std::max(se2, 1e-30));
                worst = std::max(worst, std::abs(t));
                count += std::abs(t) > threshold ? 1 : 0;
            }
        return std::make_pair(count, worst);
    };
    const auto [fails, worst] = rejected(1.0);
    EXPECT_EQ(fails, 0) << "worst |t| " << worst << " against the threshold " << threshold;
    // Power: the box moved, so the difference the other way round must be rejected.
    const auto [reversedFails, reversedWorst] = rejected(-1.0);
    EXPECT_GE(reversedFails, 3) << "the test cannot tell dt from -dt (worst |t| " << reversedWorst << ")";
}

TEST_F(TgptRender, SameSeedSameBits) {
    const GltfAsset asset(std::string(GDPT_SOURCE_DIR) + "/scenes/moving_box.gltf");
    const auto sceneAt = [&](int f) { return asset.instance(0, f * 0.25); };
    TgptOptions o;
    o.window = 3;
    const auto run = [&] {
        TgptIntegrator tgpt(o);
        return tgpt.renderWindow(keeping(), windowOf(sceneAt, 4, 3, 11), renderOptions(16, 12, 4, 0));
    };
    const auto a = run(), b = run();
    for (std::size_t f = 0; f < a.size(); ++f)
        for (std::size_t l = 0; l < a[f].layers.size(); ++l)
            test::expectSameBits(a[f].layers[l].image, b[f].layers[l].image,
                                 "frame " + std::to_string(f) + " layer " + a[f].layers[l].name);
}

}  // namespace
}  // namespace gdpt
