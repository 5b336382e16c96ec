// pixel_stats.glsl: Welford accumulation and the Chan et al. 1979 merge against a two-pass
// (mean, then squared deviations) computation in double precision, the merge of two partial
// statistics, the variance of the mean, and the non-finite policy (a sample with an Inf or
// NaN channel is counted and enters as zero). Runs the very functions every kernel runs
// (shaders/lib/pixel_stats.glsl compiled as C++).
#include <gtest/gtest.h>

#include <cmath>
#include <glm/glm.hpp>
#include <limits>
#include <random>
#include <vector>

#include "gdpt_shared.h"
#include "lib/pixel_stats.glsl"

namespace {

using namespace gdpt::gpu;
using glm::dvec3;

// Reference statistics of a sample list: count, mean and M2 = Σ (x − mean)², two passes.
struct TwoPass {
    std::uint32_t count = 0;
    dvec3 mean{0.0};
    dvec3 m2{0.0};
};

TwoPass twoPass(const std::vector<vec3>& xs) {
    TwoPass r;
    r.count = static_cast<std::uint32_t>(xs.size());
    for (const vec3& x : xs) r.mean += dvec3(x);
    if (r.count > 0) r.mean /= static_cast<double>(r.count);
    for (const vec3& x : xs) r.m2 += (dvec3(x) - r.mean) * (dvec3(x) - r.mean);
    return r;
}

// One invocation's batch as the kernels fold it: Welford over the samples, then the merge.
PixelStats foldBatch(PixelStats stored, const std::vector<vec3>& xs) {
    Welford a = welfordInit();
    std::uint32_t n = 0;
    for (const vec3& x : xs) {
        ++n;
        welfordAdd(a, statsSample(x, isFinite(x)), n);
    }
    return chanMerge(stored, a, n);
}

PixelStats emptyStats() {
    PixelStats s{};
    s.mean = vec3(0.0f);
    s.m2 = vec3(0.0f);
    s.count = 0;
    return s;
}

std::vector<vec3> samples(std::uint32_t seed, int n, float offset, float spread) {
    std::mt19937 gen(seed);
    std::normal_distribution<float> d(0.0f, spread);
    std::vector<vec3> xs;
    for (int i = 0; i < n; ++i) xs.push_back(vec3(offset + d(gen), 2.0f * offset + d(gen), d(gen)));
    return xs;
}

void expectMatches(const PixelStats& s, const TwoPass& r, double relTol) {
    ASSERT_EQ(s.count, r.count);
    for (int c = 0; c < 3; ++c) {
        const double scale = std::max(1.0, std::abs(r.mean[c]));
        EXPECT_NEAR(s.mean[c], r.mean[c], relTol * scale) << "channel " << c;
        EXPECT_NEAR(s.m2[c], r.m2[c], relTol * std::max(1.0, r.m2[c])) << "channel " << c;
    }
}

TEST(PixelStats, WelfordBatchMatchesTwoPass) {
    const std::vector<vec3> xs = samples(1, 1000, 3.0f, 0.7f);
    expectMatches(foldBatch(emptyStats(), xs), twoPass(xs), 1e-5);
}

// A mean far above the spread: the naive Σx² − n·mean² form would cancel in float32.
TEST(PixelStats, WelfordStaysAccurateForLargeMeanSmallSpread) {
    const std::vector<vec3> xs = samples(2, 4000, 1000.0f, 0.01f);
    const TwoPass r = twoPass(xs);
    const PixelStats s = foldBatch(emptyStats(), xs);
    for (int c = 0; c < 2; ++c) EXPECT_NEAR(s.m2[c] / r.m2[c], 1.0, 0.05) << "channel " << c;
}

// Chan et al. 1979: two partial statistics of different sizes merge into the statistics of
// the concatenation, in either order, and successive batches keep matching.
TEST(PixelStats, ChanMergeOfTwoPartialsMatchesTwoPassOfTheUnion) {
    const std::vector<vec3> a = samples(3, 37, 5.0f, 2.0f);
    const std::vector<vec3> b = samples(4, 211, 6.0f, 0.5f);
    std::vector<vec3> all = a;
    all.insert(all.end(), b.begin(), b.end());
    const TwoPass r = twoPass(all);
    expectMatches(foldBatch(foldBatch(emptyStats(), a), b), r, 2e-5);
    expectMatches(foldBatch(foldBatch(emptyStats(), b), a), r, 2e-5);
    PixelStats running = emptyStats();
    std::vector<vec3> seen;
    for (int batch = 0; batch < 20; ++batch) {
        const std::vector<vec3> xs =
            samples(100u + static_cast<std::uint32_t>(batch), 1 + batch % 7, 1.0f, 1.0f);
        running = foldBatch(running, xs);
        seen.insert(seen.end(), xs.begin(), xs.end());
        expectMatches(running, twoPass(seen), 2e-5);
    }
}

TEST(PixelStats, MergingAnEmptyBatchLeavesTheStatisticsUnchanged) {
    const PixelStats s = foldBatch(emptyStats(), samples(5, 10, 1.0f, 1.0f));
    const PixelStats t = chanMerge(s, welfordInit(), 0u);
    EXPECT_EQ(t.count, s.count);
    for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(t.mean[c], s.mean[c]);
        EXPECT_EQ(t.m2[c], s.m2[c]);
    }
    const PixelStats e = chanMerge(emptyStats(), welfordInit(), 0u);
    EXPECT_EQ(e.count, 0u);
    EXPECT_EQ(e.mean, vec3(0.0f));
}

TEST(PixelStats, VarianceOfMeanIsSampleVarianceOverCount) {
    const std::vector<vec3> xs = samples(6, 500, 2.0f, 1.5f);
    const TwoPass r = twoPass(xs);
    const vec3 v = varianceOfMean(foldBatch(emptyStats(), xs));
    const double n = static_cast<double>(r.count);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(v[c], r.m2[c] / (n - 1.0) / n, 1e-5 * r.m2[c] / (n - 1.0) / n);
    // Below two samples there is no variance estimate: zero.
    EXPECT_EQ(varianceOfMean(emptyStats()), vec3(0.0f));
    EXPECT_EQ(varianceOfMean(foldBatch(emptyStats(), {vec3(3.0f)})), vec3(0.0f));
}

// The policy: any non-finite channel makes the whole sample zero (all three channels), and
// the sample still counts, so the statistics are those of the list with it set to zero.
TEST(PixelStats, NonFiniteSampleIsCountedAsZero) {
    const float inf = std::numeric_limits<float>::infinity();
    const float nan = std::numeric_limits<float>::quiet_NaN();
    EXPECT_EQ(statsSample(vec3(1.0f, nan, 2.0f), false), vec3(0.0f));
    EXPECT_EQ(statsSample(vec3(1.0f, 3.0f, 2.0f), true), vec3(1.0f, 3.0f, 2.0f));
    EXPECT_FALSE(isFinite(vec3(1.0f, 2.0f, inf)));
    EXPECT_FALSE(isFinite(vec3(-inf, 2.0f, 1.0f)));
    EXPECT_FALSE(isFinite(vec3(1.0f, nan, 1.0f)));
    EXPECT_TRUE(isFinite(vec3(std::numeric_limits<float>::max())));

    std::vector<vec3> xs = samples(7, 50, 4.0f, 1.0f);
    std::vector<vec3> zeroed = xs;
    xs[3] = vec3(1.0f, nan, 2.0f);
    xs[17] = vec3(inf, 1.0f, 1.0f);
    xs[49] = vec3(-inf, nan, 0.5f);
    zeroed[3] = zeroed[17] = zeroed[49] = vec3(0.0f);
    const PixelStats s = foldBatch(emptyStats(), xs);
    expectMatches(s, twoPass(zeroed), 1e-5);
    EXPECT_TRUE(isFinite(s.mean));
    EXPECT_TRUE(isFinite(s.m2));
}

}  // namespace
