// stats_merge.h: merging the per-pixel statistics of disjoint sample sets gives the statistics
// of their union (against a two-pass double-precision computation), is deterministic in part
// order, and refuses statistics of another shape.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "integrator/stats_merge.h"
#include "lib/pixel_stats.glsl"
#include "util/error.h"

namespace gdpt {
namespace {

using gpu::PixelStats;

// Per-pixel statistics of `samples` (Welford), as the kernels fold a batch.
PixelStats fold(const std::vector<glm::vec3>& samples) {
    gpu::Welford w = gpu::welfordInit();
    std::uint32_t n = 0;
    for (const glm::vec3& x : samples) gpu::welfordAdd(w, x, ++n);
    PixelStats s{};
    return gpu::chanMerge(s, w, n);
}

TEST(StatsMerge, PartsMergeIntoTheStatisticsOfAllTheirSamples) {
    std::mt19937 rng(11);
    std::lognormal_distribution<float> radiance(0.0f, 1.5f);  // skewed, as path samples are
    for (int parts : {2, 3, 7}) {
        std::vector<glm::vec3> all;
        std::vector<PixelStats> acc;
        for (int p = 0; p < parts; ++p) {
            std::vector<glm::vec3> part;
            for (int i = 0; i < 5 + 3 * p; ++i) part.push_back({radiance(rng), radiance(rng), 0.0f});
            all.insert(all.end(), part.begin(), part.end());
            const PixelStats s = fold(part);
            if (acc.empty())
                acc = {s};
            else
                mergeStatsInto(acc, &s, 1);
        }
        // Two passes in double: mean, then squared deviations.
        for (int c = 0; c < 3; ++c) {
            double mean = 0.0, m2 = 0.0;
            for (const auto& x : all) mean += x[c];
            mean /= double(all.size());
            for (const auto& x : all) m2 += (x[c] - mean) * (x[c] - mean);
            // float32 rounding over n merges: a few ulps per sample of the magnitudes involved.
            const double scale = 1e-6 * double(all.size());
            EXPECT_NEAR(acc[0].mean[c], mean, scale * (std::abs(mean) + std::sqrt(m2))) << parts << " parts";
            EXPECT_NEAR(acc[0].m2[c], m2, scale * (m2 + 1e-30)) << parts << " parts";
        }
        EXPECT_EQ(acc[0].count, all.size());
    }
}

TEST(StatsMerge, StatesMergeBufferByBufferAndCountTheirSamples) {
    SamplerState a, b;
    a.spp = 3;
    b.spp = 2;
    a.nextBatch = 4;
    a.buffers = {std::vector<PixelStats>(4, fold({{1, 1, 1}, {2, 2, 2}, {3, 3, 3}})),
                 std::vector<PixelStats>(4, PixelStats{})};  // e.g. a pass that took nothing
    b.buffers = {std::vector<PixelStats>(4, fold({{4, 4, 4}, {5, 5, 5}})),
                 std::vector<PixelStats>(4, PixelStats{})};
    mergeStateInto(a, b);
    EXPECT_EQ(a.spp, 5u);
    EXPECT_EQ(a.nextBatch, 4u);
    for (const PixelStats& s : a.buffers[0]) {
        EXPECT_EQ(s.count, 5u);
        EXPECT_FLOAT_EQ(s.mean.x, 3.0f);
        EXPECT_FLOAT_EQ(s.m2.x, 10.0f);  // (4 + 1 + 0 + 1 + 4)
    }
    for (const PixelStats& s : a.buffers[1]) EXPECT_EQ(s.count, 0u);
}

TEST(StatsMerge, TheOrderIsPartOfTheResultSoPartsAreMergedInPartOrder) {
    // Merging is exact in real arithmetic but not in float32: the same parts merged in another
    // order may differ in the last bits, which is why every merge goes in part order.
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<PixelStats> parts;
    for (int p = 0; p < 5; ++p) {
        std::vector<glm::vec3> xs;
        for (int i = 0; i < 7; ++i) xs.push_back({u(rng), u(rng) * 1e3f, u(rng) * 1e-3f});
        parts.push_back(fold(xs));
    }
    const auto mergeAll = [&](const std::vector<int>& order) {
        std::vector<PixelStats> acc = {parts[order[0]]};
        for (std::size_t i = 1; i < order.size(); ++i) mergeStatsInto(acc, &parts[order[i]], 1);
        return acc[0];
    };
    const PixelStats once = mergeAll({0, 1, 2, 3, 4});
    const PixelStats again = mergeAll({0, 1, 2, 3, 4});
    EXPECT_EQ(std::memcmp(&once, &again, sizeof once), 0);
    const PixelStats other = mergeAll({4, 3, 2, 1, 0});
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(other.mean[c], once.mean[c], 1e-6f * std::abs(once.mean[c]));
}

TEST(StatsMerge, RefusesStatisticsOfAnotherShape) {
    std::vector<PixelStats> acc(4);
    const std::vector<PixelStats> other(5);
    EXPECT_THROW(mergeStatsInto(acc, other.data(), other.size()), Error);
    SamplerState a, b;
    a.buffers = {acc};
    b.buffers = {acc, acc};
    EXPECT_THROW(mergeStateInto(a, b), Error);
}

}  // namespace
}  // namespace gdpt
