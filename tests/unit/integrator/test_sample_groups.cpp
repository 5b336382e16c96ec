// Groups of samples and the variance of paired differences (integrator/sample_groups.h):
//   - equal group ends, the merging of a render's batch ends in pairs, the recorder's refusals;
//   - the between-group estimator against the variance it estimates, on synthetic renders whose
//     samples are known: 20,000 pixels of independent normal samples, paired through a shared
//     term, in groups of unequal sizes; the mean estimate over the pixels must be within 4
//     standard errors of σ²/n (each pixel's estimate is σ²/n · χ²_(G−1)/(G−1), so the mean's
//     relative standard error is √(2/(G−1)/pixels)); and the power: the same estimate without
//     the group sizes' weights, and the unpaired one (the halves' own variances added), are
//     rejected;
//   - the partner map: a pixel's difference is taken to its partner, and none gives 0.
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <random>

#include "integrator/sample_groups.h"
#include "poisson/poisson_spacetime.h"
#include "util/error.h"

namespace gdpt {
namespace {

TEST(SampleGroups, EqualEndsCoverTheSamples) {
    EXPECT_EQ(equalGroupEnds(4, 16), (std::vector<std::uint32_t>{1, 2, 3, 4}));
    EXPECT_EQ(equalGroupEnds(33, 16).size(), 16u);
    EXPECT_EQ(equalGroupEnds(33, 16).back(), 33u);
    const std::vector<std::uint32_t> ends = equalGroupEnds(33, 16);
    for (std::size_t j = 0; j < ends.size(); ++j) {
        const std::uint32_t size = ends[j] - (j > 0 ? ends[j - 1] : 0);
        EXPECT_TRUE(size == 2 || size == 3) << "group " << j;
    }
    EXPECT_TRUE(equalGroupEnds(0, 16).empty());
}

TEST(SampleGroups, EveryBatchMergesNeighboursPastTheLimit) {
    SampleGroupRecorder r = SampleGroupRecorder::everyBatch(16);
    for (std::uint32_t done = 1; done <= 100; ++done) {
        r.record(done, {Image(1, 1, float(done))});
        const SampleGroups& g = r.groups();
        ASSERT_LE(g.ends.size(), 16u);
        ASSERT_EQ(g.ends.back(), done);
        if (done >= 16) {
            ASSERT_GE(g.ends.size(), 8u);
        }
        // Each kept end keeps its own cumulative mean.
        for (std::size_t j = 0; j < g.ends.size(); ++j)
            ASSERT_EQ(g.means[j][0].at(0, 0, 0), float(g.ends[j]));
    }
    EXPECT_THROW(r.record(100, {Image(1, 1)}), Error);
    EXPECT_THROW((void)SampleGroupRecorder::everyBatch(1), Error);
    EXPECT_THROW((void)SampleGroupRecorder::atEnds({2, 2}), Error);
    EXPECT_THROW((void)SampleGroupRecorder::atEnds({0, 2}), Error);
    SampleGroupRecorder fixed = SampleGroupRecorder::atEnds({2, 5});
    EXPECT_FALSE(fixed.wants(1));
    EXPECT_TRUE(fixed.wants(2));
    fixed.record(1, {Image(1, 1)});
    fixed.record(2, {Image(1, 1)});
    EXPECT_EQ(fixed.groups().ends, (std::vector<std::uint32_t>{2}));
}

// Two renders of `pixels` pixels (one row) whose sample i of pixel p is e_i = s_i + u_i (earlier)
// and l_i = s_i + v_i + 1 (later): the shared term s has variance 4 and u, v variance 0.25, so a
// paired difference has variance 0.5 and each render alone 4.25.
struct Synthetic {
    SampleGroups earlier, later;
    double ownVariance = 4.25, differenceVariance = 0.5;
};

Synthetic synthetic(const std::vector<std::uint32_t>& ends, int pixels, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> shared(0.0, 2.0), own(0.0, 0.5);
    Synthetic s;
    s.earlier.ends = s.later.ends = ends;
    std::vector<double> sumE(std::size_t(pixels), 0.0), sumL(std::size_t(pixels), 0.0);
    std::uint32_t done = 0;
    for (std::uint32_t end : ends) {
        for (; done < end; ++done)
            for (int p = 0; p < pixels; ++p) {
                const double x = shared(rng);
                sumE[std::size_t(p)] += x + own(rng);
                sumL[std::size_t(p)] += x + own(rng) + 1.0;
            }
        Image e(pixels, 1), l(pixels, 1);
        for (int p = 0; p < pixels; ++p)
            for (int c = 0; c < 3; ++c) {
                e.plane(c)[std::size_t(p)] = float(sumE[std::size_t(p)] / end);
                l.plane(c)[std::size_t(p)] = float(sumL[std::size_t(p)] / end);
            }
        s.earlier.means.push_back({e});
        s.later.means.push_back({l});
    }
    return s;
}

TEST(SampleGroups, PairedVarianceMatchesTheTruthAndHasPower) {
    // Unequal groups (1, 3, 2, 6, 4, 8 samples: n = 24, G = 6).
    const std::vector<std::uint32_t> ends = {1, 4, 6, 12, 16, 24};
    const int pixels = 20000;
    const Synthetic s = synthetic(ends, pixels, 7);
    const Image v = pairedDifferenceVariance(s.later, s.earlier, 0, {});
    ASSERT_EQ(v.pixelCount(), std::size_t(pixels));
    const double n = 24.0, groups = 6.0, truth = s.differenceVariance / n;
    const double se = truth * std::sqrt(2.0 / (groups - 1.0) / pixels);
    double mean = 0.0;
    for (float x : v.plane(0)) mean += x / pixels;
    EXPECT_NEAR(mean, truth, 4.0 * se);
    // Power: the group means' plain sample variance (sizes ignored) over n/G, and the variance
    // the halves would give if they were independent.
    double plain = 0.0;
    for (int p = 0; p < pixels; ++p) {
        std::vector<double> d;
        for (std::size_t j = 0; j < ends.size(); ++j) {
            const double prev = j > 0 ? ends[j - 1] : 0.0, m = ends[j] - prev;
            const auto groupMean = [&](const SampleGroups& g) {
                return (ends[j] * double(g.means[j][0].plane(0)[std::size_t(p)]) -
                        (j > 0 ? prev * double(g.means[j - 1][0].plane(0)[std::size_t(p)]) : 0.0)) /
                       m;
            };
            d.push_back(groupMean(s.later) - groupMean(s.earlier));
        }
        const double dm = std::accumulate(d.begin(), d.end(), 0.0) / groups;
        double ss = 0.0;
        for (double x : d) ss += (x - dm) * (x - dm);
        plain += ss / (groups - 1.0) * (n / groups) / n / pixels;
    }
    EXPECT_GT(std::abs(plain - truth), 8.0 * se) << "the test cannot tell unweighted groups";
    EXPECT_GT(2.0 * s.ownVariance / n - truth, 100.0 * se);
}

TEST(SampleGroups, DifferencesFollowThePartners) {
    const std::vector<std::uint32_t> ends = {2, 4, 6};
    const Synthetic s = synthetic(ends, 3, 11);
    // Pixel 0 → 2, pixel 1 → none, pixel 2 → 0.
    const Image v = pairedDifferenceVariance(s.later, s.earlier, 0, {2, kNoTemporalPartner, 0});
    const Image same = pairedDifferenceVariance(s.later, s.earlier, 0, {});
    EXPECT_EQ(v.at(1, 0, 1), 0.0f);
    EXPECT_GT(same.at(1, 0, 1), 0.0f);
    // Pixel 0's difference is to the later render's pixel 2: the same as with pixel 2's values
    // moved to pixel 0 and no partners.
    SampleGroups moved = s.later;
    for (std::vector<Image>& m : moved.means)
        for (int c = 0; c < 3; ++c) m[0].plane(c)[0] = m[0].plane(c)[2];
    const Image byHand = pairedDifferenceVariance(moved, s.earlier, 0, {});
    for (int c = 0; c < 3; ++c) EXPECT_EQ(v.at(0, 0, c), byHand.at(0, 0, c));
    EXPECT_NE(v.at(0, 0, 0), same.at(0, 0, 0));
    SampleGroups shorter = s.earlier;
    shorter.ends.pop_back();
    shorter.means.pop_back();
    EXPECT_THROW((void)pairedDifferenceVariance(s.later, shorter, 0, {}), Error);
    EXPECT_THROW((void)pairedDifferenceVariance(s.later, s.earlier, 1, {}), Error);
    SampleGroups one = s.earlier, oneLater = s.later;
    for (SampleGroups* g : {&one, &oneLater}) {
        g->ends.resize(1);
        g->means.resize(1);
    }
    EXPECT_TRUE(pairedDifferenceVariance(oneLater, one, 0, {}).empty()) << "one group has no spread";
}

}  // namespace
}  // namespace gdpt
