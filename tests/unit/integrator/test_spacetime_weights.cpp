// The space-time reconstructions' row weights (integrator/spacetime_weights.h): each row gets
// the inverse of its (box-filtered, for wl1) variance, renormalised to mean 1, and for wl1 the
// weights are bounded to kDefaultVarianceWeightContrast around the median of all the window's
// rows. A still scene is the case that needs it: nothing moves, dt's variance is 0 and its rows'
// raw weight is 1/ε = 10⁴ times the others'. Bounded, they weigh 4 times the median row; wl2
// (unfiltered) and wl1 with the bound off keep the raw ratio (the test's power).
#include <gtest/gtest.h>

#include "integrator/spacetime_weights.h"

namespace gdpt {
namespace {

Image filled(int w, int h, float v) {
    Image im(w, h);
    for (int c = 0; c < 3; ++c)
        for (float& x : im.plane(c)) x = v;
    return im;
}

// A still two-frame window of 8 x 4: every spatial row's variance 1, dt's 0.
SpaceTimeProblem stillWindow(RowVariances& v) {
    SpaceTimeProblem p;
    p.width = 8;
    p.height = 4;
    p.frames = 2;
    for (int f = 0; f < 2; ++f) {
        v.primal.push_back(filled(8, 4, 1.0f));
        v.dx.push_back(filled(8, 4, 1.0f));
        v.dy.push_back(filled(8, 4, 1.0f));
    }
    v.dt.push_back(filled(8, 4, 0.0f));
    return p;
}

double dtOverPrimal(bool filtered, double contrast) {
    RowVariances v;
    SpaceTimeProblem p = stillWindow(v);
    setVarianceWeights(p, v, filtered, 1e-4, 1, contrast);
    EXPECT_EQ(p.weightDt.size(), 32u);
    EXPECT_EQ(p.weightPrimal.size(), 64u);
    return p.weightDt[5] / p.weightPrimal[5];
}

TEST(SpaceTimeWeights, Wl1BoundsAStillScenesTemporalRows) {
    EXPECT_NEAR(dtOverPrimal(true, kDefaultVarianceWeightContrast), kDefaultVarianceWeightContrast, 1e-9);
    EXPECT_NEAR(dtOverPrimal(true, 10.0), 10.0, 1e-9);
    // Power: unbounded, the ratio is (1 + ε) / ε.
    EXPECT_NEAR(dtOverPrimal(true, 0.0), (1.0 + 1e-4) / 1e-4, 1e-3);
    EXPECT_NEAR(dtOverPrimal(false, kDefaultVarianceWeightContrast), (1.0 + 1e-4) / 1e-4, 1e-3);
}

TEST(SpaceTimeWeights, WeightsAreRenormalisedToMeanOneOverTheRowsTheSolveHas) {
    RowVariances v;
    SpaceTimeProblem p = stillWindow(v);
    setVarianceWeights(p, v, true, 1e-4, 1);
    double sum = 0.0, rows = 0.0;
    for (const Field* f : {&p.weightPrimal, &p.weightDx, &p.weightDy, &p.weightDt})
        for (double w : *f)
            if (w > 0.0) sum += w, rows += 1.0;
    EXPECT_NEAR(sum / rows, 1.0, 1e-12);
    EXPECT_EQ(rows, 64.0 + 2 * 28 + 2 * 24 + 32);  // the rows the solve has (see below)
}

// The rows the solve does not have (dx of the last column, dy of the last row, dt of a pixel
// without a temporal partner) weigh 0 and stay out of the median and the mean. Here they are
// given the largest raw weights (variance 0), so that counted they would move both.
TEST(SpaceTimeWeights, RowsTheSolveLacksWeighNothing) {
    RowVariances v;
    SpaceTimeProblem p = stillWindow(v);
    v.dt[0] = filled(8, 4, 1.0f);
    for (int f = 0; f < 2; ++f)
        for (int c = 0; c < 3; ++c)
            for (int y = 0; y < 4; ++y) {
                v.dx[std::size_t(f)].plane(c)[std::size_t(y * 8 + 7)] = 0.0f;
                for (int x = 0; x < 8; ++x) v.dy[std::size_t(f)].plane(c)[std::size_t(3 * 8 + x)] = 0.0f;
            }
    p.temporalPartner.assign(32, 0u);
    for (std::uint32_t i = 0; i < 32; ++i) p.temporalPartner[i] = i;
    p.temporalPartner[9] = kNoTemporalPartner;
    v.dt[0].plane(0)[9] = v.dt[0].plane(1)[9] = v.dt[0].plane(2)[9] = 0.0f;
    setVarianceWeights(p, v, false, 1e-4, 1, 0.0);
    for (std::size_t f = 0; f < 2; ++f)
        for (std::size_t y = 0; y < 4; ++y) {
            EXPECT_EQ(p.weightDx[f * 32 + y * 8 + 7], 0.0);
            for (std::size_t x = 0; x < 8; ++x) EXPECT_EQ(p.weightDy[f * 32 + 24 + x], 0.0);
        }
    EXPECT_EQ(p.weightDt[9], 0.0);
    // Every other row has variance 1: equal weights, renormalised to exactly 1.
    EXPECT_NEAR(p.weightPrimal[0], 1.0, 1e-12);
    EXPECT_NEAR(p.weightDx[0], 1.0, 1e-12);
    EXPECT_NEAR(p.weightDt[0], 1.0, 1e-12);
}

}  // namespace
}  // namespace gdpt
