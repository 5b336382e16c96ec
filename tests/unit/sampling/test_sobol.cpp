// sobol.glsl: the scrambled 2-D Sobol' points that emitter supersampling uses;
// sampler.glsl: the padded, shuffled patterns of the path decisions built from them.
// Checked against the definition of a (0,2)-sequence (every aligned block of 2^m points is
// a (0,m,2)-net: one point in each elementary interval of every shape 2^a x 2^(m-a)), and
// the scramble's uniformity: over scramble seeds, each single point is uniform on [0,1)^2
// (chi-square over a grid; that is what makes the supersampled estimate unbiased).
#include <gtest/gtest.h>

#include <vector>

#include "gdpt_shared.h"
#include "lib/rng.glsl"
#include "lib/sampler.glsl"
#include "lib/sobol.glsl"
#include "stats.h"

namespace {

using namespace gdpt::gpu;

// 2^m points put exactly one point into each of the 2^m elementary intervals of every
// shape 2^a x 2^(m-a).
bool isNet(const std::vector<vec2>& points, uint m) {
    const uint n = 1u << m;
    if (points.size() != n) return false;
    for (uint a = 0; a <= m; ++a) {
        std::vector<int> cells(n, 0);
        for (const vec2& p : points) {
            const uint cx = static_cast<uint>(p.x * static_cast<float>(1u << a));
            const uint cy = static_cast<uint>(p.y * static_cast<float>(1u << (m - a)));
            if (++cells[(cy << a) + cx] > 1) return false;
        }
    }
    return true;
}

// Points of indices [first, first + 2^m) of the scrambled sequence.
std::vector<vec2> block(uint first, uint m, uint seedX, uint seedY) {
    std::vector<vec2> points;
    for (uint i = 0; i < (1u << m); ++i) points.push_back(sobolScrambled2(first + i, seedX, seedY));
    return points;
}

TEST(Sobol, UnscrambledPointsAreTheSequence) {
    // Van der Corput and Sobol' dimension 2 of indices 0..3 (Bratley & Fox 1988).
    const float x[4] = {0.0f, 0.5f, 0.25f, 0.75f};
    const float y[4] = {0.0f, 0.5f, 0.75f, 0.25f};
    for (uint i = 0; i < 4; ++i) {
        EXPECT_EQ(float(sobolReverseBits(i) >> 8u) / 16777216.0f, x[i]) << i;
        EXPECT_EQ(float(sobolDim1(i) >> 8u) / 16777216.0f, y[i]) << i;
    }
}

TEST(Sobol, DimensionOneEqualsItsDirectionNumbers) {
    // The definition: XOR of the columns v_k (v_0 = 2^31, v_{k+1} = v_k ^ (v_k >> 1)) of the
    // index's set bits, against the transform sobolDim1 computes.
    uint index = 12345u;
    for (int n = 0; n < 100000; ++n) {
        index = index * 747796405u + 2891336453u;
        uint expected = 0u, v = 0x80000000u;
        for (uint k = 0; k < 32; ++k, v ^= v >> 1u)
            if ((index >> k) & 1u) expected ^= v;
        ASSERT_EQ(sobolDim1(index), expected) << index;
    }
}

TEST(Sobol, EveryAlignedBlockIsANetForEveryScramble) {
    for (uint seed = 0; seed < 16; ++seed) {
        const uint sx = seed * 0x9E3779B9u + 7u, sy = seed * 0x85EBCA6Bu + 3u;
        for (uint m = 0; m <= 10; ++m)
            for (uint b = 0; b < 4; ++b)
                ASSERT_TRUE(isNet(block(b << m, m, sx, sy), m))
                    << "seed " << seed << " m " << m << " block " << b;
    }
    // The check can tell: with van der Corput in both coordinates (no second generator
    // matrix) the first four points lie on the diagonal, two in each of two 2x2 cells.
    std::vector<vec2> diagonal;
    for (uint i = 0; i < 4; ++i) {
        const float v = float(sobolReverseBits(i) >> 8u) / 16777216.0f;
        diagonal.push_back(vec2(v, v));
    }
    EXPECT_FALSE(isNet(diagonal, 2));
}

TEST(Sobol, EachScrambledPointIsUniform) {
    // Point index 5 (any fixed index) over 2^16 scramble seed pairs, 16 x 16 cells:
    // expected 256 per cell. The seeds are hashed as in emitter_supersampling.comp: the scramble's first
    // k digits depend on the seed's low k bits only, so seeds that share their low bits
    // (such as s·a + b and s·c + d) would give correlated coordinates.
    constexpr int kCells = 16;
    constexpr uint kSeeds = 1u << 16;
    std::vector<double> counts(kCells * kCells, 0.0);
    for (uint s = 0; s < kSeeds; ++s) {
        const uint seedX = pcgHash(s);
        const vec2 p = sobolScrambled2(5u, seedX, pcgHash(seedX ^ 0x9e3779b9u));
        ASSERT_GE(p.x, 0.0f);
        ASSERT_LT(p.x, 1.0f);
        ASSERT_GE(p.y, 0.0f);
        ASSERT_LT(p.y, 1.0f);
        counts[static_cast<int>(p.y * kCells) * kCells + static_cast<int>(p.x * kCells)] += 1.0;
    }
    const std::vector<double> expected(counts.size(), double(kSeeds) / static_cast<double>(counts.size()));
    const auto r = gdpt::stats::chi2Test(counts, expected);
    EXPECT_GT(r.pValue, 1e-4) << "chi2 " << r.statistic << " dof " << r.dof;
}

// Every power-of-two prefix of a pixel's samples is a (0,m,2)-net in every 2-D decision, and
// stratified (one point per 1/2^m interval) in every 1-D one; the decisions are padded
// (decorrelated), not copies of one pattern.
TEST(Sampler, EveryPrefixIsANetInEveryDecision) {
    for (uint pixel = 0; pixel < 8; ++pixel) {
        for (uint dim = 0; dim < 9; ++dim) {
            for (uint m = 0; m <= 8; ++m) {
                std::vector<vec2> pairs;
                std::vector<int> strata(1u << m, 0);
                for (uint i = 0; i < (1u << m); ++i) {
                    const LdSample s = ldSampleInit(pixel, i, 77u);
                    pairs.push_back(ldGet2(s, dim));
                    ++strata[static_cast<uint>(ldGet1(s, dim) * static_cast<float>(1u << m))];
                }
                ASSERT_TRUE(isNet(pairs, m)) << "pixel " << pixel << " dim " << dim << " m " << m;
                for (int c : strata) ASSERT_EQ(c, 1) << "pixel " << pixel << " dim " << dim << " m " << m;
            }
        }
    }
    // Padding: the light point and the BSDF direction of one bounce differ sample by sample.
    int same = 0;
    for (uint i = 0; i < 64; ++i) {
        const LdSample s = ldSampleInit(3u, i, 77u);
        const vec3 a = ldLight(s, 0u), b = ldBsdf(s, 0u);
        same += (a.y == b.y && a.z == b.z) ? 1 : 0;
    }
    EXPECT_EQ(same, 0);
}

TEST(Sampler, EachSampleIsUniformOverPixels) {
    // Sample 3's BSDF direction at bounce 1 over 2^16 pixels, 16 x 16 cells (256 expected).
    constexpr int kCells = 16;
    std::vector<double> counts(kCells * kCells, 0.0);
    for (uint pixel = 0; pixel < (1u << 16); ++pixel) {
        const vec3 u = ldBsdf(ldSampleInit(pixel, 3u, 5u), 1u);
        counts[static_cast<int>(u.z * kCells) * kCells + static_cast<int>(u.y * kCells)] += 1.0;
    }
    const std::vector<double> expected(counts.size(), double(1u << 16) / static_cast<double>(counts.size()));
    const auto r = gdpt::stats::chi2Test(counts, expected);
    EXPECT_GT(r.pValue, 1e-4) << "chi2 " << r.statistic << " dof " << r.dof;
}

}  // namespace
