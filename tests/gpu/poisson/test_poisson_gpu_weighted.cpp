// test_poisson_gpu_weighted.cpp — the variance-weighted reconstructions: WL2 against the CPU
// solve with inverse-variance row weights, WL1 against L1 given its weights, and the box-filtered
// variances and the weights' contrast bound they use.
#include "poisson_gpu_support.h"

namespace gdpt {
namespace {

using namespace poisson_test;

// Inverse-variance weights equal the CPU solve with the same row weights.
TEST_F(PoissonGpu, WeightedL2MatchesCpuWithInverseVarianceWeights) {
    const VarianceProblem p0 = varianceProblem(26, 19, 51, {0.01, 1.0}, {0.01, 1.0});
    const Image &primal = p0.primal, &dx = p0.dx, &dy = p0.dy, &vp = p0.vp, &vx = p0.vx, &vy = p0.vy;
    SolveOptions o;
    o.method = Reconstruction::WeightedL2;
    o.tolerance = 1e-6;
    const PoissonInput in = p0.variances();
    Image out;
    const SolveReport r = solve(primal, dx, dy, o, out, &in);
    EXPECT_TRUE(r.converged);
    auto inv = [&](const Image& v) {
        Field f(v.pixelCount());
        for (std::size_t i = 0; i < f.size(); ++i)
            f[i] = 1.0 / ((double(v.plane(0)[i]) + v.plane(1)[i] + v.plane(2)[i]) / 3.0 + o.varianceEpsilon);
        return f;
    };
    for (int c = 0; c < 3; ++c) {
        PoissonProblem p = channelProblem(primal, dx, dy, o.alpha, c);
        p.weightPrimal = inv(vp);
        p.weightDx = inv(vx);
        p.weightDy = inv(vy);
        EXPECT_LT(relError(channel(out, c), solvePoissonL2(p, L2Method::Exact)), 1e-4) << c;
    }
}

// The WL1 variance filter against a direct sum over each clipped box: RGB means, invalid
// values (non-finite, negative) left out of the averages and counted, -1 where a box has
// no valid value.
TEST(BoxFilteredVariance, AveragesTheClippedBoxOfValidValues) {
    const int w = 7, h = 5;
    Image var(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c) var.at(x, y, c) = float(x + 10 * y + c);
    var.at(2, 1, 1) = std::nanf("");
    var.at(5, 3, 0) = -400.0f;  // a negative channel: no variance
    const auto valid = [&](int x, int y) { return !((x == 2 && y == 1) || (x == 5 && y == 3)); };
    for (int radius : {0, 1, 2, 9}) {
        std::size_t nonFinite = 0, negative = 0;
        const std::vector<float> f = boxFilteredVariance(var, radius, nonFinite, negative);
        EXPECT_EQ(nonFinite, 1u);
        EXPECT_EQ(negative, 1u);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                double sum = 0.0;
                int count = 0;
                for (int yy = std::max(0, y - radius); yy <= std::min(h - 1, y + radius); ++yy)
                    for (int xx = std::max(0, x - radius); xx <= std::min(w - 1, x + radius); ++xx)
                        if (valid(xx, yy)) {
                            sum += xx + 10.0 * yy + 1.0;  // mean of the channels x+10y+c
                            ++count;
                        }
                const float expected = count > 0 ? float(sum / count) : -1.0f;
                EXPECT_NEAR(f[static_cast<std::size_t>(y * w + x)], expected, 1e-4f)
                    << "radius " << radius << " at " << x << "," << y;
            }
    }
}

// A firefly's variance beside zeros: the running sums take it in and out again, and the boxes
// after it, all zeros, must average to about 0 (a rounding residue far below WL1's ε = 1e-4),
// never to a negative residue (which WL1 read as a missing variance and gave its rows weight 0).
// Before the clamp: -2.6e-13 at every one of these pixels.
TEST(BoxFilteredVariance, ZerosAfterAFireflyAverageToZero) {
    const int w = 40, h = 3;
    Image var(w, h);
    for (int y = 0; y < h; ++y)
        for (int c = 0; c < 3; ++c) {
            var.at(3, y, c) = 5703.4f;
            var.at(4, y, c) = 0.1f + 0.01f * float(c);
            var.at(5, y, c) = 13928.7f;
        }
    std::size_t nonFinite = 0, negative = 0;
    const std::vector<float> f = boxFilteredVariance(var, 3, nonFinite, negative);
    for (int y = 0; y < h; ++y)
        for (int x = 9; x < w; ++x) {
            EXPECT_GE(f[std::size_t(y * w + x)], 0.0f) << x << "," << y;
            EXPECT_LT(f[std::size_t(y * w + x)], 1e-9f) << x << "," << y;
        }
    for (float v : f) EXPECT_GE(v, 0.0f);
}

// boundWeightContrast: the positive weights clamped into [m/K, m·K] around their median m
// (the upper middle one of an even count), zeros kept, K < 1 (or 0) changing nothing.
TEST(BoundWeightContrast, ClampsAroundTheMedianOfThePositiveWeights) {
    // Positive: 0.01, 0.5, 1, 2, 3, 400 (six: the upper middle is 2).
    const std::vector<float> w = {0.5f, 0.0f, 400.0f, 2.0f, 0.01f, 0.0f, 1.0f, 3.0f};
    std::vector<float> b = w;
    boundWeightContrast(b, 4.0);
    EXPECT_EQ(b, (std::vector<float>{0.5f, 0.0f, 8.0f, 2.0f, 0.5f, 0.0f, 1.0f, 3.0f}));
    b = w;
    boundWeightContrast(b, 1.0);  // every positive weight becomes the median
    EXPECT_EQ(b, (std::vector<float>{2.0f, 0.0f, 2.0f, 2.0f, 2.0f, 0.0f, 2.0f, 2.0f}));
    for (double none : {0.0, 0.5}) {
        b = w;
        boundWeightContrast(b, none);
        EXPECT_EQ(b, w) << none;
    }
    std::vector<float> zeros(5, 0.0f);
    boundWeightContrast(zeros, 4.0);
    EXPECT_EQ(zeros, std::vector<float>(5, 0.0f));
}

// The inverse box-filtered variances of a problem's three row families as WL1 weights them
// (the rows past the last column / row do not exist: 0), their contrast bounded by K.
std::vector<float> wl1Weights(const VarianceProblem& p, const SolveOptions& o, double contrast) {
    const int w = p.primal.width(), h = p.primal.height();
    const std::size_t n = p.primal.pixelCount();
    std::vector<float> all(3 * n, 0.0f);
    const Image* vars[3] = {&p.vp, &p.vx, &p.vy};
    for (std::size_t k = 0; k < 3; ++k) {
        std::size_t nonFinite = 0, negative = 0;
        const std::vector<float> f =
            boxFilteredVariance(*vars[k], o.varianceFilterRadius, nonFinite, negative);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                if (!((k == 1 && x + 1 == w) || (k == 2 && y + 1 == h))) {
                    const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
                    all[k * n + i] = static_cast<float>(1.0 / (double(f[i]) + o.varianceEpsilon));
                }
    }
    boundWeightContrast(all, contrast);
    return all;
}

// WL1 is L1 (IRLS) whose rows are weighted by the inverse of the box-filtered variances,
// bounded to SolveOptions::varianceWeightContrast around their median: the same solve as L1
// given those weights explicitly (bounded by default, raw with the bound off), and not the
// unweighted L1. The variances here span 200x, so the default bound of 4 changes the weights.
TEST_F(PoissonGpu, WeightedL1IsL1WithFilteredInverseVarianceWeights) {
    const VarianceProblem p0 = varianceProblem(26, 19, 71, {0.001, 0.1}, {0.01, 2.0});
    const Image &primal = p0.primal, &dx = p0.dx, &dy = p0.dy;
    const std::size_t n = primal.pixelCount();
    const PoissonInput vars = p0.variances();
    Image l1;
    SolveOptions plain;
    plain.method = Reconstruction::L1;
    plain.tolerance = 1e-6;
    solve(primal, dx, dy, plain, l1);
    Image bounded;
    for (double contrast : {kDefaultVarianceWeightContrast, 0.0}) {
        SolveOptions o = plain;
        o.method = Reconstruction::WeightedL1;
        o.varianceWeightContrast = contrast;
        Image wl1, explicitWeights;
        const SolveReport r = solve(primal, dx, dy, o, wl1, &vars);
        EXPECT_EQ(r.irlsIterations, o.irlsIterations);
        const std::vector<float> all = wl1Weights(p0, o, contrast);
        const std::vector<float> wp(all.begin(), all.begin() + std::ptrdiff_t(n)),
            wx(all.begin() + std::ptrdiff_t(n), all.begin() + std::ptrdiff_t(2 * n)),
            wy(all.begin() + std::ptrdiff_t(2 * n), all.end());
        PoissonInput weighted;
        weighted.weightPrimal = &wp;
        weighted.weightDx = &wx;
        weighted.weightDy = &wy;
        solve(primal, dx, dy, plain, explicitWeights, &weighted);
        for (int c = 0; c < 3; ++c) {
            Field a = channel(wl1, c), b = channel(explicitWeights, c), u = channel(l1, c);
            EXPECT_LT(relError(a, b), 1e-4) << "contrast " << contrast << ", channel " << c;
            EXPECT_GT(relError(a, u), 1e-3) << c << ": the weights should change the solution";
            if (contrast == 0.0) {
                EXPECT_GT(relError(a, channel(bounded, c)), 1e-3)
                    << c << ": the bound should change the solution";
            }
        }
        if (contrast != 0.0) bounded = wl1;
    }
}

}  // namespace
}  // namespace gdpt
