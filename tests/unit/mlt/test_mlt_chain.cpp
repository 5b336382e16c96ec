// The Metropolis steps of mlt.glsl and the host's estimate (integrator/mlt_estimate.h).
//
// Detailed balance: a chain that starts in its target's distribution stays in it. Many
// independent chains start from exact samples of an analytic target on the unit square
// (rejection sampling), each takes kSteps mutations with mlt.glsl's small and large steps and
// acceptance; their final states are independent samples, whose histogram is chi-square
// tested against the target's cell integrals. The same test with a wrong acceptance ratio
// (min(1, sqrt(T'/T)): its chain targets sqrt(T)) must fail, and does by a wide margin: the
// test has the power to catch a broken Metropolis-Hastings ratio.
//
// The splat: chains on the same target splat a carried quantity with mlt.glsl's weights (the
// Metropolis shares and the large steps' multiple importance sampling) into four quadrants;
// over independent runs the estimates' means must match the quadrants' integrals, with the
// weights' b' 50 % off the true b (any b' is unbiased), and must not without the large
// steps' share, or with the Metropolis sum scaled by b' instead of b.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include "integrator/mlt_estimate.h"
#include "lib/mlt.glsl"
#include "stats.h"
#include "stats_normal.h"

namespace gdpt {
namespace {

// A smooth bump on a floor, with a hole of zero target (the chain must never enter it).
double target(double u, double v) {
    if (u > 0.8 && v < 0.2) return 0.0;
    return 0.1 + std::exp(-((u - 0.3) * (u - 0.3) + (v - 0.6) * (v - 0.6)) / 0.02);
}

// The target a chain walks: `target` to the power `exponent` (mlt.glsl mltTemperedTarget),
// divided, with `blocks`, by the divisor of the cell of a 3 x 3 grid that (u, v) lies in (as
// mlt.comp divides by its image block's, mlt_estimate.h MltBlockNormaliser).
struct Walk {
    float exponent = 1.0f;
    bool blocks = false;
};
constexpr std::array<double, 9> kBlockDivisors = {1.0, 2.5, 0.5, 1.5, 0.8, 3.0, 0.6, 1.2, 2.0};
constexpr double kWalkedBound = 1.1 / 0.5;  // the largest walked target: the rejection sampler's bound

double walked(double u, double v, Walk walk) {
    const double t = gpu::mltTemperedTarget(static_cast<float>(target(u, v)), walk.exponent);
    if (!walk.blocks) return t;
    return t / kBlockDivisors[std::size_t(std::min(int(v * 3), 2) * 3 + std::min(int(u * 3), 2))];
}

constexpr int kCells = 10;      // 10 x 10 histogram
constexpr int kSteps = 64;      // mutations per chain
constexpr int kChains = 40000;  // independent chains (final states)
constexpr float kLargeStep = 0.3f;

using Acceptance = std::function<float(float, float)>;

// Chains on the analytic target, as mlt.comp walks: uniform numbers, a start drawn from the
// target exactly (rejection sampling), and the proposal (a large step with probability
// kLargeStep, else a small step of both coordinates).
class AnalyticChains {
public:
    explicit AnalyticChains(std::uint32_t seed, Walk walk) : gen_(seed), walk_(walk) {}
    float uniform() { return uni_(gen_); }
    void start(float& u, float& v) {
        do {
            u = uniform();
            v = uniform();
        } while (uniform() * kWalkedBound >= walked(u, v, walk_));
    }
    // The proposal from (u, v) into (pu, pv); true for a large step.
    bool propose(float u, float v, float& pu, float& pv) {
        if (uniform() < kLargeStep) {
            pu = uniform();
            pv = uniform();
            return true;
        }
        pu = gpu::mltSmallStep(u, uniform(), uniform());
        pv = gpu::mltSmallStep(v, uniform(), uniform());
        return false;
    }

private:
    std::mt19937 gen_;
    Walk walk_;
    std::uniform_real_distribution<float> uni_{0.0f, 1.0f};
};

// What a mutation of the chains below sees: the current state (u, v) of target t, the
// proposal (pu, pv) of target tp, and whether it is a large step.
struct Mutation {
    float u, v, t, pu, pv, tp;
    bool large;
};

// Walks `count` chains of `steps` mutations from exact starts on the target `walk`:
// `step(m)` returns the acceptance probability of mutation m (and may splat it); `end(u, v)`
// sees each final state.
template <class Step, class End>
void walkChains(std::uint32_t seed, int count, int steps, Walk walk, Step step, End end) {
    AnalyticChains chains(seed, walk);
    for (int c = 0; c < count; ++c) {
        Mutation m{};
        chains.start(m.u, m.v);
        m.t = static_cast<float>(walked(m.u, m.v, walk));
        for (int s = 0; s < steps; ++s) {
            m.large = chains.propose(m.u, m.v, m.pu, m.pv);
            m.tp = static_cast<float>(walked(m.pu, m.pv, walk));
            if (chains.uniform() < step(m)) m.u = m.pu, m.v = m.pv, m.t = m.tp;
        }
        end(m.u, m.v);
    }
}

std::vector<double> finalStateHistogram(const Acceptance& accept, std::uint32_t seed) {
    std::vector<double> counts(kCells * kCells, 0.0);
    walkChains(
        seed, kChains, kSteps, Walk{}, [&](const Mutation& m) { return accept(m.t, m.tp); },
        [&](float u, float v) {
            counts[std::size_t(std::min(int(v * kCells), kCells - 1) * kCells +
                               std::min(int(u * kCells), kCells - 1))] += 1.0;
        });
    return counts;
}

std::vector<double> expectedCounts() {
    // Cell integrals by a 40 x 40 midpoint rule per cell, normalised to kChains.
    std::vector<double> e(kCells * kCells, 0.0);
    double total = 0.0;
    constexpr int kSub = 40;
    for (int cy = 0; cy < kCells; ++cy)
        for (int cx = 0; cx < kCells; ++cx) {
            double s = 0.0;
            for (int j = 0; j < kSub; ++j)
                for (int i = 0; i < kSub; ++i)
                    s += target((cx + (i + 0.5) / kSub) / kCells, (cy + (j + 0.5) / kSub) / kCells);
            e[std::size_t(cy * kCells + cx)] = s;
            total += s;
        }
    for (double& x : e) x *= kChains / total;
    return e;
}

TEST(MltChain, SmallStepStaysInTheUnitIntervalAndWraps) {
    EXPECT_FLOAT_EQ(gpu::mltSmallStep(0.5f, 0.0f, 0.0f), 0.5f + gpu::kMltSmallStepMax);
    EXPECT_NEAR(gpu::mltSmallStep(0.5f, 0.9f, 1.0f), 0.5f - gpu::kMltSmallStepMin, 1e-7f);
    EXPECT_NEAR(gpu::mltSmallStep(0.999f, 0.0f, 0.0f), 0.999f + gpu::kMltSmallStepMax - 1.0f, 1e-6f);
    EXPECT_NEAR(gpu::mltSmallStep(0.001f, 0.9f, 0.0f), 0.001f - gpu::kMltSmallStepMax + 1.0f, 1e-6f);
    std::mt19937 gen(7);
    std::uniform_real_distribution<float> uni(0.0f, 1.0f);
    for (int i = 0; i < 100000; ++i) {
        const float v = gpu::mltSmallStep(uni(gen), uni(gen), uni(gen));
        ASSERT_GE(v, 0.0f);
        ASSERT_LT(v, 1.0f);
    }
}

TEST(MltChain, AcceptanceIsTheMetropolisRatio) {
    EXPECT_FLOAT_EQ(gpu::mltAcceptance(2.0f, 1.0f), 0.5f);
    EXPECT_FLOAT_EQ(gpu::mltAcceptance(1.0f, 3.0f), 1.0f);
    EXPECT_FLOAT_EQ(gpu::mltAcceptance(1.0f, 0.0f), 0.0f);
    EXPECT_FLOAT_EQ(gpu::mltAcceptance(0.0f, 0.0f), 1.0f);
    EXPECT_FLOAT_EQ(gpu::mltSplatWeight(0.25f, 2.0f, 0.0f), 0.125f);
    EXPECT_FLOAT_EQ(gpu::mltSplatWeight(1.0f, 0.0f, 0.0f), 0.0f);
    EXPECT_FLOAT_EQ(gpu::mltSplatWeight(0.25f, 2.0f, 0.5f), 0.1f);
    // b' = 2, p = 0.25: the large step's share b'/(T + b'p).
    EXPECT_FLOAT_EQ(gpu::mltLargeStepWeight(1.5f, 2.0f, 0.25f), 1.0f);
    EXPECT_FLOAT_EQ(gpu::mltLargeStepWeight(0.0f, 0.0f, 0.25f), 0.0f);
}

TEST(MltChain, DetailedBalanceKeepsTheTargetDistribution) {
    const std::vector<double> expected = expectedCounts();
    const std::vector<double> right = finalStateHistogram(gpu::mltAcceptance, 11);
    const stats::Chi2Result ok = stats::chi2Test(right, expected);
    ASSERT_TRUE(ok.error.empty()) << ok.error;
    EXPECT_GT(ok.pValue, 1e-3) << "chi2 " << ok.statistic << " dof " << ok.dof;
    // The hole: no chain may be found where the target is zero (cells of u > 0.8, v < 0.2).
    for (int cy = 0; cy < 2; ++cy)
        for (int cx = 8; cx < kCells; ++cx) EXPECT_EQ(right[std::size_t(cy * kCells + cx)], 0.0);

    // Power: a chain whose ratio is sqrt(T'/T) targets sqrt(T); 64 steps from the right
    // distribution move it far enough to be rejected.
    const Acceptance wrong = [](float t, float tp) {
        return t > 0.0f ? std::min(1.0f, std::sqrt(tp / t)) : 1.0f;
    };
    const stats::Chi2Result bad = stats::chi2Test(finalStateHistogram(wrong, 11), expected);
    EXPECT_LT(bad.pValue, 1e-9) << "chi2 " << bad.statistic << " dof " << bad.dof;
}

// What a state carries: non-zero only where the target is, and not proportional to it.
double carried(double u, double v) {
    return target(u, v) * (0.5 + u) + (target(u, v) > 0.0 && v > 0.9 ? 2.0 : 0.0);
}

int quadrant(double u, double v) {
    return (v < 0.5 ? 0 : 2) + (u < 0.5 ? 0 : 1);
}

// ∫ of the walked target and the quadrants' ∫ carried, by a 600 x 600 midpoint rule (the hole's,
// the band's and the 3 x 3 grid's edges lie on its cell boundaries).
void exactIntegrals(double& b, std::array<double, 4>& q, Walk walk = {}) {
    constexpr int kN = 600;
    b = 0.0;
    q = {};
    for (int j = 0; j < kN; ++j)
        for (int i = 0; i < kN; ++i) {
            const double u = (i + 0.5) / kN, v = (j + 0.5) / kN;
            b += walked(u, v, walk) / (kN * kN);
            q[std::size_t(quadrant(u, v))] += carried(u, v) / (kN * kN);
        }
}

// How a render's chains walk and weigh: the target they walk, and the target their splat
// weights divide by (the same, unless a test breaks it on purpose).
struct Tempering {
    Walk walk, weigh;
};

// One render of the quadrants: chains started from exact samples of the target, each
// mutating as mlt.comp does and splatting both records with mlt.glsl's weights (b' = bWeights),
// the Metropolis sum scaled by the true b (mlt_estimate.h), the large steps' share kept or not.
std::array<double, 4> misRender(std::uint32_t seed, double b, float bWeights, bool largeShare,
                                Tempering tempering) {
    constexpr int kMisChains = 400, kMisSteps = 100;
    std::array<double, 4> metropolis{}, large{};
    const float bLarge = bWeights * kLargeStep;
    walkChains(
        seed, kMisChains, kMisSteps, tempering.walk,
        [&](const Mutation& m) {
            const float a = gpu::mltAcceptance(m.t, m.tp);
            const float t = static_cast<float>(walked(m.u, m.v, tempering.weigh));
            const float tp = static_cast<float>(walked(m.pu, m.pv, tempering.weigh));
            metropolis[std::size_t(quadrant(m.u, m.v))] +=
                gpu::mltSplatWeight(1.0f - a, t, bLarge) * carried(m.u, m.v);
            metropolis[std::size_t(quadrant(m.pu, m.pv))] +=
                gpu::mltSplatWeight(a, tp, bLarge) * carried(m.pu, m.pv);
            if (m.large)
                large[std::size_t(quadrant(m.pu, m.pv))] +=
                    gpu::mltLargeStepWeight(tp, bWeights, kLargeStep) * carried(m.pu, m.pv);
            return a;
        },
        [](float, float) {});
    std::array<double, 4> q{};
    for (std::size_t k = 0; k < 4; ++k)
        q[k] = (b * metropolis[k] + (largeShare ? large[k] : 0.0)) / double(kMisChains * kMisSteps);
    return q;
}

// The largest |t| over the quadrants of kRuns renders' means against the exact integrals;
// b scales the Metropolis sum.
double worstQuadrantT(double b, float bWeights, bool largeShare, const std::array<double, 4>& exact,
                      Tempering tempering = {}) {
    constexpr int kRuns = 30;
    std::array<double, 4> sum{}, sumSquares{};
    for (int r = 0; r < kRuns; ++r) {
        const std::array<double, 4> q =
            misRender(1000u + std::uint32_t(r), b, bWeights, largeShare, tempering);
        for (std::size_t k = 0; k < 4; ++k) sum[k] += q[k], sumSquares[k] += q[k] * q[k];
    }
    double worst = 0.0;
    for (std::size_t k = 0; k < 4; ++k) {
        const double mean = sum[k] / kRuns;
        const double var = (sumSquares[k] - kRuns * mean * mean) / (kRuns - 1);
        worst = std::max(worst, std::abs(mean - exact[k]) / std::sqrt(var / kRuns));
    }
    return worst;
}

TEST(MltEstimate, LargeStepMultipleImportanceSamplingIsUnbiased) {
    double b = 0.0;
    std::array<double, 4> exact{};
    exactIntegrals(b, exact);
    // 30 independent renders: Student t with 29 degrees of freedom, Šidák over 4 quadrants
    // and the 2 settings at a family level of 1e-3.
    const double threshold = test::twoSidedT(test::sidakAlpha(1e-3, 8), 29);
    EXPECT_LT(worstQuadrantT(b, static_cast<float>(b), true, exact), threshold) << "b' = b";
    EXPECT_LT(worstQuadrantT(b, static_cast<float>(1.5 * b), true, exact), threshold) << "b' = 1.5 b";
    // Power: without the large steps' share the estimate misses about p/(T/b + p) of it.
    EXPECT_GT(worstQuadrantT(b, static_cast<float>(b), false, exact), threshold) << "the test has no power";
    // Nor with the Metropolis sum scaled by the weights' b' = 1.5 b instead of b.
    EXPECT_GT(worstQuadrantT(1.5 * b, static_cast<float>(1.5 * b), true, exact), threshold)
        << "the test has no power";
}

// gmlt's chains walk a tempered target (T^γ, mltTemperedTarget): the same estimate, unbiased,
// as long as the splat weights and b divide by the target walked. Power: weights that divide by
// T while the chains walk T^0.5 miss the quadrants by many standard errors.
TEST(MltEstimate, TemperedTargetIsUnbiased) {
    constexpr float kExponent = 0.5f;
    double b = 0.0, bUntempered = 0.0;
    std::array<double, 4> exact{}, unused{};
    exactIntegrals(b, exact, Walk{kExponent});
    exactIntegrals(bUntempered, unused, Walk{1.0f});
    const double threshold = test::twoSidedT(test::sidakAlpha(1e-3, 8), 29);
    const Tempering tempered{{kExponent}, {kExponent}};
    EXPECT_LT(worstQuadrantT(b, static_cast<float>(b), true, exact, tempered), threshold) << "b' = b";
    EXPECT_LT(worstQuadrantT(b, static_cast<float>(1.5 * b), true, exact, tempered), threshold)
        << "b' = 1.5 b";
    EXPECT_GT(
        worstQuadrantT(bUntempered, static_cast<float>(bUntempered), true, exact, {{kExponent}, {1.0f}}),
        threshold)
        << "the test has no power";
}

// gmlt's chains walk their tempered target divided by its image block's divisor
// (MltBlockNormaliser): unbiased as long as the weights and b divide by the same. Power:
// weights that leave the divisors out while the chains walk with them miss the quadrants.
TEST(MltEstimate, BlockDividedTargetIsUnbiased) {
    const Walk divided{0.25f, true}, undivided{0.25f, false};
    double b = 0.0, bUndivided = 0.0;
    std::array<double, 4> exact{}, unused{};
    exactIntegrals(b, exact, divided);
    exactIntegrals(bUndivided, unused, undivided);
    const double threshold = test::twoSidedT(test::sidakAlpha(1e-3, 8), 29);
    EXPECT_LT(worstQuadrantT(b, static_cast<float>(b), true, exact, {divided, divided}), threshold)
        << "b' = b";
    EXPECT_LT(worstQuadrantT(b, static_cast<float>(1.5 * b), true, exact, {divided, divided}), threshold)
        << "b' = 1.5 b";
    EXPECT_GT(worstQuadrantT(bUndivided, static_cast<float>(bUndivided), true, exact, {divided, undivided}),
              threshold)
        << "the test has no power";
}

// The divisors: per block the mean untempered target of the even-indexed samples in it plus
// kMltBlockFloor times their mean over the image, to the power γ; odd samples left out.
TEST(MltEstimate, BlockNormaliserIsTheBlocksMeanWithAFloor) {
    // A 5 x 2 image in blocks of 2: 3 x 1 blocks (the last one column wide). Targets are T^0.5.
    auto sample = [](float t, std::uint32_t x, std::uint32_t y) {
        return gpu::MltBootstrapSample{std::sqrt(t), y * 5 + x};
    };
    const std::vector<gpu::MltBootstrapSample> samples = {
        sample(4.0f, 0, 0), sample(1e6f, 0, 0),  // block 0; the odd one is not used
        sample(2.0f, 1, 1), sample(1e6f, 4, 1),  // block 0
        sample(0.0f, 2, 0), sample(1e6f, 4, 0),  // block 1: nothing found
        sample(9.0f, 4, 1),                      // block 2
    };
    const MltBlockNormaliser n = mltBlockNormaliser(samples, 5, 2, 2, 0.5f);
    ASSERT_EQ(n.block, 2u);
    EXPECT_EQ(n.columns, 3u);
    EXPECT_EQ(n.rows, 1u);
    ASSERT_EQ(n.divisors.size(), 3u);
    const double floor = kMltBlockFloor * (4.0 + 2.0 + 0.0 + 9.0) / 4.0;
    EXPECT_NEAR(n.divisors[0], std::sqrt(3.0 + floor), 1e-5);
    EXPECT_NEAR(n.divisors[1], std::sqrt(0.0 + floor), 1e-5);
    EXPECT_NEAR(n.divisors[2], std::sqrt(9.0 + floor), 1e-5);
    EXPECT_EQ(n.divisor(1 * 5 + 4, 5), n.divisors[2]);
    EXPECT_EQ(n.divisor(0 * 5 + 3, 5), n.divisors[1]);
    // Exponent 1: the means themselves (targets read as T).
    const MltBlockNormaliser one = mltBlockNormaliser({{3.0f, 0}, {5.0f, 0}, {1.0f, 2}}, 4, 1, 2, 1.0f);
    EXPECT_NEAR(one.divisors[0], 3.0 + kMltBlockFloor * 2.0, 1e-6);
    EXPECT_NEAR(one.divisors[1], 1.0 + kMltBlockFloor * 2.0, 1e-6);
    // Nothing found: every divisor 1. No blocks: no division.
    const MltBlockNormaliser dark = mltBlockNormaliser({{0.0f, 0}, {7.0f, 1}}, 4, 1, 2, 0.25f);
    EXPECT_EQ(dark.divisors, (std::vector<float>{1.0f, 1.0f}));
    const MltBlockNormaliser none = mltBlockNormaliser(samples, 5, 2, 0, 0.5f);
    EXPECT_EQ(none.block, 0u);
    EXPECT_EQ(none.divisor(3, 5), 1.0f);
}

TEST(MltChain, TemperedTargetIsTheIdentityAtOneAndKeepsZero) {
    for (const float t : {0.0f, 1e-30f, 0.37f, 1.0f, 3.5e6f}) EXPECT_EQ(gpu::mltTemperedTarget(t, 1.0f), t);
    EXPECT_EQ(gpu::mltTemperedTarget(0.0f, 0.25f), 0.0f);
    EXPECT_EQ(gpu::mltTemperedTarget(-1.0f, 0.5f), 0.0f);
    EXPECT_FLOAT_EQ(gpu::mltTemperedTarget(16.0f, 0.25f), 2.0f);
    EXPECT_FLOAT_EQ(gpu::mltTemperedTarget(0.25f, 0.5f), 0.5f);
}

TEST(MltEstimate, NormalisationIsTheMeanTargetWithItsStandardError) {
    const std::vector<float> t = {1.0f, 2.0f, 3.0f, 6.0f, 0.0f, -1.0f, NAN};
    const MltNormalisation n = mltNormalisation(t);
    // Negative and non-finite targets count as 0: values 1, 2, 3, 6, 0, 0, 0.
    EXPECT_EQ(n.samples, 7u);
    EXPECT_DOUBLE_EQ(n.b, 12.0 / 7.0);
    double ss = 0.0;
    for (double v : {1.0, 2.0, 3.0, 6.0, 0.0, 0.0, 0.0}) ss += (v - 12.0 / 7.0) * (v - 12.0 / 7.0);
    EXPECT_NEAR(n.standardError, std::sqrt(ss / 6.0 / 7.0), 1e-12);
    EXPECT_EQ(mltNormalisation({}).b, 0.0);
    // Kish's effective sample size: (1 + 2 + 3 + 6)² / (1 + 4 + 9 + 36) = 144 / 50.
    TargetSums sums;
    for (float v : t) sums.add(v);
    EXPECT_DOUBLE_EQ(sums.effectiveSampleSize(), 144.0 / 50.0);
    EXPECT_EQ(TargetSums{}.effectiveSampleSize(), 0.0);
}

TEST(MltEstimate, PooledTargetsAreTheMeanOfAllSamples) {
    // The bootstrap's and the large steps' sums pooled give the mean of all their targets.
    TargetSums boot, large;
    for (float t : {1.0f, 3.0f}) boot.add(t);
    for (float t : {2.0f, 6.0f, 0.0f}) large.add(t);
    boot.add(large);
    const MltNormalisation n = boot.normalisation();
    EXPECT_EQ(n.samples, 5u);
    EXPECT_DOUBLE_EQ(n.b, 12.0 / 5.0);
    EXPECT_NEAR(n.standardError, mltNormalisation({1.0f, 3.0f, 2.0f, 6.0f, 0.0f}).standardError, 1e-12);
}

TEST(MltEstimate, ChainsStartInProportionToTheTarget) {
    const std::vector<float> t = {0.0f, 1.0f, 3.0f, 0.0f, 4.0f, 0.5f};
    const std::uint32_t chains = 8500;
    const std::vector<std::uint32_t> starts = mltChainStarts(t, chains, 5);
    ASSERT_EQ(starts.size(), chains);
    std::vector<double> count(t.size(), 0.0);
    for (std::uint32_t s : starts) count.at(s) += 1.0;
    // Systematic resampling: each sample is chosen floor or ceil of chains · T_i / Σ T times.
    for (std::size_t i = 0; i < t.size(); ++i)
        EXPECT_LE(std::abs(count[i] - chains * t[i] / 8.5), 1.0) << "sample " << i;
    EXPECT_TRUE(std::is_sorted(starts.begin(), starts.end()));
    EXPECT_TRUE(mltChainStarts({0.0f, 0.0f}, 10, 1).empty());
    EXPECT_EQ(mltChainStarts({0.0f, 2.0f, 0.0f}, 3, 9), (std::vector<std::uint32_t>{1, 1, 1}));
}

TEST(MltEstimate, RecordsResolveLikeGptResolve) {
    // A 3 x 2 image; one record at pixel (1, 0) with central c and an offset to the right n
    // and a gradient to the right g, one at (2, 0) with a gradient to the left g2.
    MltAccumulator acc(3, 2, 1.0f, 0.0f);
    gpu::MltRecord r[2]{};
    r[0].pixel = 1;
    r[0].weight = 0.5f;
    r[0].value[gpu::kMltCentral] = {2.0f, 4.0f, 6.0f};
    r[0].value[gpu::kMltNeighbor + gpu::kGptRight] = {1.0f, 1.0f, 1.0f};
    r[0].value[gpu::kMltGradient + gpu::kGptRight] = {0.5f, 0.5f, 0.5f};
    r[1].pixel = 2;
    r[1].weight = 2.0f;
    r[1].value[gpu::kMltGradient + gpu::kGptLeft] = {0.25f, 0.0f, 0.0f};
    r[0].largeTarget = -1.0f;  // not a large step
    r[1].largeTarget = 4.0f;   // a large step's proposal: one more sample of b
    acc.add(r, 2);
    EXPECT_EQ(acc.largeSteps().count, 1u);
    EXPECT_DOUBLE_EQ(acc.largeSteps().sum, 4.0);
    // p = 0: the large step's share b'/(T + 0) = 1/4 goes to the second sum.
    const MltScale scale{3.0, 0.0};
    const MltImages m = resolveGradientSamples(acc, scale);
    // (1, 0) has neighbours left, right, down: k = 3. (2, 0) has left and down: k = 2.
    EXPECT_FLOAT_EQ(m.primal.at(1, 0, 0), float(3.0 * 0.5 * 2.0 / 3.0));
    EXPECT_FLOAT_EQ(m.primal.at(1, 0, 2), float(3.0 * 0.5 * 6.0 / 3.0));
    EXPECT_FLOAT_EQ(m.primal.at(2, 0, 0), float(3.0 * 0.5 * 1.0 / 2.0));
    EXPECT_FLOAT_EQ(m.primal.at(0, 0, 0), 0.0f);
    // dx(1, 0) = gradient_right(1, 0) − gradient_left(2, 0).
    EXPECT_FLOAT_EQ(m.dx.at(1, 0, 0), float(3.0 * (0.5 * 0.5 - 2.0 * 0.25)));
    EXPECT_FLOAT_EQ(m.dx.at(1, 0, 1), float(3.0 * 0.5 * 0.5));
    EXPECT_FLOAT_EQ(m.dx.at(2, 0, 0), 0.0f);  // last column
    EXPECT_FLOAT_EQ(m.dy.at(1, 0, 0), 0.0f);
    // The large step's share (b' = 1, p = 0: 1/4 of its values) scaled by `large`.
    const MltImages l = resolveGradientSamples(acc, MltScale{0.0, 8.0});
    EXPECT_FLOAT_EQ(l.dx.at(1, 0, 0), float(-8.0 * 0.25 * 0.25));
    EXPECT_FLOAT_EQ(l.primal.at(1, 0, 0), 0.0f);
}

}  // namespace
}  // namespace gdpt
