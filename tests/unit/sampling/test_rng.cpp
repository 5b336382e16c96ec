// rng.glsl: range, determinism, uniformity and decorrelation of neighbouring streams.
// Uniformity tests are chi-square fits with expected counts n / cells (all cells >= 5).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "gdpt_shared.h"
#include "lib/rng.glsl"
#include "sampling_test_util.h"
#include "stats.h"

namespace {

using namespace gdpt::gpu;

static_assert(sizeof(Rng) == 4, "Rng must stay a one-word value type (copied by offset paths)");

constexpr uint kSeed = 1234u;

gdpt::stats::Chi2Result uniformChi2(const std::vector<double>& counts, double n) {
    std::vector<double> expected(counts.size(), n / static_cast<double>(counts.size()));
    return gdpt::stats::chi2Test(counts, expected);
}

TEST(Rng, RangeIsHalfOpen) {
    Rng r = rngInit(0u, 0u, kSeed);
    for (int i = 0; i < 1000000; ++i) {
        float x = rngNext(r);
        ASSERT_GE(x, 0.0f);
        ASSERT_LT(x, 1.0f);
    }
    // Find a state whose next output has all top 24 bits set (1 in 2^24 states; the output
    // permutation is a bijection so such states exist) and check the float stays below 1.
    Rng probe;
    bool found = false;
    for (uint s = 0u; s < 0xFFFFFFFFu && !found; ++s) {
        probe.state = s;
        Rng copy = probe;
        found = (rngNextUint(copy) >> 8u) == 0xFFFFFFu;
    }
    ASSERT_TRUE(found);
    float top = rngNext(probe);
    EXPECT_LT(top, 1.0f);
    EXPECT_EQ(top, kOneMinusEpsilon);
}

TEST(Rng, DeterministicAndCopyable) {
    Rng a = rngInit(17u, 5u, kSeed);
    Rng b = rngInit(17u, 5u, kSeed);
    Rng c = rngInit(17u, 5u, kSeed + 1u);
    EXPECT_EQ(a.state, b.state);
    EXPECT_NE(a.state, c.state);
    rngNext(a);
    Rng offsetCopy = a;  // what a gradient-domain offset path does
    for (int i = 0; i < 10; ++i) {
        EXPECT_EQ(rngNext(a), rngNext(offsetCopy));
    }
}

TEST(Rng, UniformityChi2) {
    const int n = 1000000;
    std::vector<double> counts(1000, 0.0);
    Rng r = rngInit(3u, 9u, kSeed);
    for (int i = 0; i < n; ++i) {
        counts[static_cast<size_t>(rngNext(r) * 1000.0f)] += 1.0;
    }
    auto res = uniformChi2(counts, n);
    EXPECT_TRUE(res.error.empty()) << res.error;
    EXPECT_GT(res.pValue, gdpt::test::chi2Alpha()) << "chi2=" << res.statistic;
}

// Pairs (x, y) on a 32 x 32 grid: dependence between the two streams shows up as a
// non-uniform joint histogram. Also checks the Pearson correlation |rho| < 5 / sqrt(n)
// (5 standard errors of rho under independence).
void pairTest(const char* what, float (*first)(int), float (*second)(int)) {
    const int n = 400000;
    const int k = 32;
    std::vector<double> counts(k * k, 0.0);
    double sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
    for (int i = 0; i < n; ++i) {
        float x = first(i);
        float y = second(i);
        counts[static_cast<size_t>(static_cast<int>(x * k) * k + static_cast<int>(y * k))] += 1.0;
        sx += x;
        sy += y;
        sxx += double(x) * x;
        syy += double(y) * y;
        sxy += double(x) * y;
    }
    auto res = uniformChi2(counts, n);
    EXPECT_TRUE(res.error.empty()) << what << ": " << res.error;
    EXPECT_GT(res.pValue, gdpt::test::chi2Alpha()) << what << ": chi2=" << res.statistic;
    double cov = sxy / n - (sx / n) * (sy / n);
    double mx = sx / n;
    double my = sy / n;
    double rho = cov / std::sqrt((sxx / n - mx * mx) * (syy / n - my * my));
    EXPECT_LT(std::fabs(rho), 5.0 / std::sqrt(double(n))) << what << ": rho=" << rho;
}

TEST(Rng, AdjacentPixelsUncorrelated) {
    pairTest(
        "pixels",
        [](int i) {
            Rng r = rngInit(uint(i), 0u, kSeed);
            return rngNext(r);
        },
        [](int i) {
            Rng r = rngInit(uint(i) + 1u, 0u, kSeed);
            return rngNext(r);
        });
}

TEST(Rng, AdjacentSamplesUncorrelated) {
    pairTest(
        "samples",
        [](int i) {
            Rng r = rngInit(42u, uint(i), kSeed);
            return rngNext(r);
        },
        [](int i) {
            Rng r = rngInit(42u, uint(i) + 1u, kSeed);
            return rngNext(r);
        });
}

TEST(Rng, AdjacentSeedsUncorrelated) {
    pairTest(
        "seeds",
        [](int i) {
            Rng r = rngInit(uint(i), 7u, 0u);
            return rngNext(r);
        },
        [](int i) {
            Rng r = rngInit(uint(i), 7u, 1u);
            return rngNext(r);
        });
}

TEST(Rng, SuccessiveDrawsUncorrelated) {
    // Dimension d and d+1 of the same path (the pair a BSDF sample consumes).
    pairTest(
        "successive",
        [](int i) {
            Rng r = rngInit(uint(i), 3u, kSeed);
            return rngNext(r);
        },
        [](int i) {
            Rng r = rngInit(uint(i), 3u, kSeed);
            rngNext(r);
            return rngNext(r);
        });
}

// The pair test must be able to fail: a stream against itself is perfectly correlated.
TEST(Rng, PairTestDetectsCorrelation) {
    const int n = 100000;
    std::vector<double> counts(32 * 32, 0.0);
    for (int i = 0; i < n; ++i) {
        Rng r = rngInit(uint(i), 0u, kSeed);
        float x = rngNext(r);
        Rng s = rngInit(uint(i) + 1u, 0u, kSeed);
        float y = 0.5f * (x + rngNext(s));  // dependent on x
        counts[static_cast<size_t>(static_cast<int>(x * 32) * 32 + static_cast<int>(y * 32))] += 1;
    }
    EXPECT_LT(uniformChi2(counts, n).pValue, 1e-10);
}

}  // namespace
