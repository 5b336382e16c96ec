// float4.h: the four-float box the builder bins with must give the scalar SAH's exact values,
// or the trees would depend on the instruction set (the builder's comment says both forms
// round alike).
#include <gtest/gtest.h>

#include <random>

#include "bvh/float4.h"

namespace gdpt {
namespace {

using bvh_simd::Box4;
using bvh_simd::load4;

float scalarHalfArea(const float lo[3], const float hi[3]) {
    if (lo[0] > hi[0] || lo[1] > hi[1] || lo[2] > hi[2]) return 0.0f;
    const float dx = hi[0] - lo[0];
    const float dy = hi[1] - lo[1];
    const float dz = hi[2] - lo[2];
    return dx * dy + dy * dz + dz * dx;
}

TEST(Float4Box, HalfAreaRoundsAsTheScalarExpression) {
    std::mt19937 rng(3);
    // Mixed magnitudes, so that the sum's rounding depends on the order of its terms.
    std::uniform_real_distribution<float> exponent(-20.0f, 20.0f);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    int differentFromOtherOrder = 0;
    for (int i = 0; i < 100000; ++i) {
        float lo[4];
        float hi[4];
        for (int a = 0; a < 3; ++a) {
            lo[a] = u(rng) * std::exp2(exponent(rng));
            hi[a] = lo[a] + std::abs(u(rng)) * std::exp2(exponent(rng));
        }
        lo[3] = hi[3] = 0.0f;
        Box4 box;
        box.grow(load4(lo), load4(hi));
        const float expected = scalarHalfArea(lo, hi);
        ASSERT_EQ(box.halfArea(), expected) << "box " << i;
        const float dx = hi[0] - lo[0];
        const float dy = hi[1] - lo[1];
        const float dz = hi[2] - lo[2];
        differentFromOtherOrder += (dz * dx + dy * dz) + dx * dy != expected ? 1 : 0;
    }
    // The check has power: another order of the same three terms rounds differently often.
    EXPECT_GT(differentFromOtherOrder, 1000);
}

TEST(Float4Box, EmptyBoxHasNoArea) {
    EXPECT_EQ(Box4{}.halfArea(), 0.0f);
    const float lo[4] = {0.0f, 1.0f, 0.0f, 0.0f};
    const float hi[4] = {1.0f, 0.5f, 1.0f, 0.0f};  // inverted in y
    Box4 box;
    box.grow(load4(lo), load4(hi));
    EXPECT_EQ(box.halfArea(), 0.0f);
    Box4 grown;
    grown.grow(load4(lo));
    EXPECT_EQ(grown.halfArea(), 0.0f);  // a point
}

}  // namespace
}  // namespace gdpt
