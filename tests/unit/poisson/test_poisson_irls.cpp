// test_poisson_irls.cpp — IRLS L1 reconstruction: weights follow their formula, and with a
// few corrupted gradients (outliers) L1 recovers the image far better than L2, at any scale.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "poisson/poisson_irls.h"
#include "poisson_test_util.h"
#include "util/error.h"

namespace gdpt {
namespace {

using test::relativeError;
using test::structuredField;

RgbPoissonProblem exactRgbProblem(int w, int h, double scale) {
    RgbPoissonProblem p;
    p.width = w;
    p.height = h;
    p.alpha = 0.2;
    for (int c = 0; c < 3; ++c) {
        Field image = structuredField(w, h);
        for (double& v : image) v *= scale * (1.0 + 0.3 * c);
        const PoissonProblem q = test::exactProblem(image, w, h, p.alpha);
        p.primal[c] = q.primal;
        p.dx[c] = q.dx;
        p.dy[c] = q.dy;
    }
    return p;
}

TEST(Irls, WeightsFollowTheFormulaAndHaveMeanOne) {
    RgbPoissonProblem p = exactRgbProblem(4, 3, 1.0);
    std::array<Field, 3> x = p.primal;
    x[0][5] += 0.3;  // residuals in the rows touching pixel 5 = (1, 1)
    x[2][5] -= 0.4;
    const double reg = 0.05;
    const IrlsWeights w = computeIrlsWeights(p, x, reg);
    // Raw weights: 1/reg on rows with zero residual; the primal row of pixel 5 has residual
    // α·(0.3, 0, −0.4), length 0.2·0.5 = 0.1. Kept rows: 12 primal + 9 dx + 8 dy = 29.
    // Of them 5 touch pixel 5 (primal, dx of 4 and 5, dy of 1 and 5).
    const double raw0 = 1.0 / reg, rawPrimal5 = 1.0 / (0.1 + reg), rawGrad = 1.0 / (0.5 + reg);
    const double mean = (24.0 * raw0 + rawPrimal5 + 4.0 * rawGrad) / 29.0;
    EXPECT_NEAR(w.primal[0], raw0 / mean, 1e-12);
    EXPECT_NEAR(w.primal[5], rawPrimal5 / mean, 1e-12);
    EXPECT_NEAR(w.dx[4], rawGrad / mean, 1e-12);
    EXPECT_NEAR(w.dy[1], rawGrad / mean, 1e-12);
    EXPECT_EQ(w.dx[3], 0.0);  // last column: dropped row
    EXPECT_EQ(w.dy[8], 0.0);  // last row: dropped row
}

// A structured 24x20 RGB image, exact primal and gradients except 12 corrupted gradients of
// 10x the image scale. L2 spreads each outlier into a dipole; L1 (IRLS, L1D preset with a
// PCG inner solver so that the inner solves converge) downweights the outlier rows.
TEST(Irls, OutlierGradientsL1BeatsL2AtEveryScale) {
    const int w = 24, h = 20;
    for (double scale : {1e-6, 1.0, 1e6}) {
        SCOPED_TRACE("scale=" + std::to_string(scale));
        RgbPoissonProblem p = exactRgbProblem(w, h, scale);
        const std::array<Field, 3> truth = p.primal;
        std::mt19937 rng(17);
        std::uniform_int_distribution<int> pixel(0, w * h - 1);
        for (int k = 0; k < 12; ++k) {
            const int i = pixel(rng);
            Field* target = (k % 2 == 0) ? p.dx.data() : p.dy.data();
            for (int c = 0; c < 3; ++c) target[c][i] += 10.0 * scale * (k % 3 == 0 ? -1.0 : 1.0);
        }
        // Some primal noise as well (1 % of the scale), as in a real render.
        std::normal_distribution<double> noise(0.0, 0.01 * scale);
        for (auto& channel : p.primal)
            for (double& v : channel) v += noise(rng);

        IrlsOptions l2 = irlsPresetL2D();
        l2.innerIterations = 500;
        l2.innerTolerance = 1e-12;
        IrlsOptions l1 = irlsPresetL1D();
        l1.regScale = scale;
        l1.inner = InnerSolver::PcgMultigrid;
        IrlsStats stats;
        const auto x2 = solveL1Irls(p, l2);
        const auto x1 = solveL1Irls(p, l1, &stats);
        EXPECT_EQ(stats.irlsIterations, 20);
        double e1 = 0.0, e2 = 0.0;
        for (int c = 0; c < 3; ++c) {
            e1 += relativeError(x1[c], truth[c]);
            e2 += relativeError(x2[c], truth[c]);
        }
        RecordProperty("l1_over_l2", std::to_string(e1 / e2));
        EXPECT_LT(e1, 0.2 * e2) << "L1 error " << e1 << ", L2 error " << e2;
    }
}

TEST(Irls, InvalidOptionsThrow) {
    RgbPoissonProblem p = exactRgbProblem(3, 3, 1.0);
    IrlsOptions o;
    o.iterations = 0;
    EXPECT_THROW(solveL1Irls(p, o), Error);
    p.alpha = 0.0;
    EXPECT_THROW(solveL1Irls(p), Error);
}

}  // namespace
}  // namespace gdpt
