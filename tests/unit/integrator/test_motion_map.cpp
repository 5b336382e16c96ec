// The motion between frames (integrator/motion_map.h) on scenes whose motion is known by
// construction: a still scene (every pixel its own partner, misses included, no shift), a
// camera moved sideways by 3.25 pixels (content moves the other way: three pixels and a
// quarter-pixel jitter shift; the pixels that leave the image have none), a square moved two pixels over a
// still background (the background it covers loses to it, the background it uncovers gets fresh streams), a
// square that comes out from behind a panel (found by carrying back: no source), and frames of different
// triangle lists (the same pixel). Square edges lie on pixel boundaries, so every pixel centre is half a
// pixel from an edge.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "integrator/motion_map.h"
#include "poisson/poisson_spacetime.h"
#include "scene/procedural.h"

namespace gdpt {
namespace {

constexpr int kSize = 32;
// The width of a pixel at distance d from makeEmissiveQuad's camera (yfov 45°, 32 pixels).
float pixelAt(float d) {
    return 2.0f * d * std::tan(0.5f * glm::radians(45.0f)) / float(kSize);
}

// A square of half-size `half` (world units) centred at (x, y) in the plane z, facing +Z.
void addSquare(Scene& s, float x, float y, float z, float half) {
    const auto base = static_cast<std::uint32_t>(s.positions.size());
    s.positions.push_back({x - half, y - half, z});
    s.positions.push_back({x + half, y - half, z});
    s.positions.push_back({x + half, y + half, z});
    s.positions.push_back({x - half, y + half, z});
    s.triangles.push_back({base, base + 1, base + 2});
    s.triangles.push_back({base, base + 2, base + 3});
    s.triangleMaterial.push_back(0);
    s.triangleMaterial.push_back(0);
}

std::uint32_t pixel(int x, int y) {
    return std::uint32_t(y * kSize + x);
}

MotionMap motion(const Scene& a, const Scene& b) {
    return motionBetween(a, primaryHits(a, -1, kSize, kSize), b, primaryHits(b, -1, kSize, kSize), -1, kSize,
                         kSize);
}

void expectDistinctStreams(const std::vector<gpu::PixelStream>& streams) {
    std::set<std::uint32_t> keys;
    for (const gpu::PixelStream& s : streams) keys.insert(s.key);
    EXPECT_EQ(keys.size(), streams.size());
}

TEST(MotionMap, AStillSceneIsItsOwnPartnerMissesIncluded) {
    Scene s = makeEmissiveQuad(glm::vec3(1.0f));
    s.positions.clear(), s.triangles.clear(), s.triangleMaterial.clear();
    addSquare(s, 0.0f, 0.0f, -1.0f, 4.0f * pixelAt(1.0f));  // 8x8 pixels; the rest misses
    const std::vector<PrimaryHit> hits = primaryHits(s, -1, kSize, kSize);
    EXPECT_NE(hits[pixel(16, 16)].triangle, gpu::kInvalidIndex);
    EXPECT_EQ(hits[pixel(2, 2)].triangle, gpu::kInvalidIndex);
    const MotionMap m = motion(s, s);
    EXPECT_TRUE(m.sameTopology);
    EXPECT_EQ(m.partnered, std::size_t(kSize * kSize));
    for (std::size_t p = 0; p < m.partner.size(); ++p) ASSERT_EQ(m.partner[p], p);
    const std::vector<gpu::PixelStream> streams = carriedStreams(m);
    for (std::size_t q = 0; q < streams.size(); ++q) {
        ASSERT_EQ(streams[q].key, q);
        ASSERT_EQ(streams[q].jitterShift, 0u);  // no motion, no shift
    }
}

TEST(MotionMap, ACameraMovedThreeAndAQuarterPixelsMovesTheImageBack) {
    // Pixel x's centre x + 0.5 lands at x - 2.75: in pixel x - 3, a quarter pixel left of its
    // centre (the jitter shift fract(-0.25) = 0.75).
    const Scene a = makeEmissiveQuad(glm::vec3(1.0f));
    Scene b = a;
    b.cameras[0].position.x += 3.25f * pixelAt(1.0f);
    const MotionMap m = motion(a, b);
    EXPECT_EQ(m.partnered, std::size_t(kSize * (kSize - 3)));
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
            ASSERT_EQ(m.partner[pixel(x, y)], x >= 3 ? pixel(x - 3, y) : kNoTemporalPartner) << x << "," << y;
            if (x < 3) continue;
            ASSERT_NEAR(m.subpixel[pixel(x, y)].x, -0.25f, 1e-3f) << x << "," << y;
            ASSERT_NEAR(m.subpixel[pixel(x, y)].y, 0.0f, 1e-3f) << x << "," << y;
        }
    const std::vector<gpu::PixelStream> streams = carriedStreams(m);
    expectDistinctStreams(streams);
    EXPECT_EQ(streams[pixel(0, 5)].key, pixel(3, 5));
    const std::uint32_t shift = streams[pixel(0, 5)].jitterShift;
    EXPECT_NEAR(double(shift & 0xFFFFu) / 65536.0, 0.75, 1e-3);
    const double dy = double(shift >> 16) / 65536.0;
    EXPECT_LT(std::min(dy, 1.0 - dy), 1e-3);  // no vertical motion (0, or a rounding below)
    // The columns that enter at the right have no source: streams of their own, unshifted.
    EXPECT_EQ(streams[pixel(kSize - 1, 5)].key, std::uint32_t(kSize * kSize) + pixel(kSize - 1, 5));
    EXPECT_EQ(streams[pixel(kSize - 1, 5)].jitterShift, 0u);
}

TEST(MotionMap, AMovingSquareCoversAndUncoversTheBackground) {
    const float px = pixelAt(0.5f);
    Scene a = makeEmissiveQuad(glm::vec3(1.0f));  // the background at z = -1
    Scene b = a;
    addSquare(a, 0.0f, 0.0f, -0.5f, 4.0f * px);       // pixels 12..19 in x and y
    addSquare(b, 2.0f * px, 0.0f, -0.5f, 4.0f * px);  // pixels 14..21
    const MotionMap m = motion(a, b);
    const auto inSquareA = [](int x, int y) { return x >= 12 && x <= 19 && y >= 12 && y <= 19; };
    const auto coveredInB = [](int x, int y) { return x >= 20 && x <= 21 && y >= 12 && y <= 19; };
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
            const std::uint32_t want = inSquareA(x, y)    ? pixel(x + 2, y)
                                       : coveredInB(x, y) ? kNoTemporalPartner
                                                          : pixel(x, y);
            ASSERT_EQ(m.partner[pixel(x, y)], want) << x << "," << y;
        }
    EXPECT_EQ(m.partnered, std::size_t(kSize * kSize - 16));
    const std::vector<gpu::PixelStream> streams = carriedStreams(m);
    expectDistinctStreams(streams);
    EXPECT_EQ(streams[pixel(16, 15)].key, pixel(14, 15));  // the square's paths follow it
    EXPECT_EQ(streams[pixel(5, 5)].key, pixel(5, 5));      // the still background keeps its own
    // Uncovered background (columns 12-13 of B): no pixel of A saw it.
    EXPECT_EQ(streams[pixel(12, 15)].key, std::uint32_t(kSize * kSize) + pixel(12, 15));
}

TEST(MotionMap, WhatComesOutFromBehindAPanelHasNoSource) {
    // A square hidden behind a nearer panel (the same pixels, 8..15 x 12..19) moves ten pixels
    // right, onto background. The background pixels it then covers land where nothing of the
    // frame before competes, but the square seen there came from behind the panel: carried
    // back, it lands ten pixels away, so they get no partner.
    Scene a = makeEmissiveQuad(glm::vec3(1.0f));
    const float p3 = pixelAt(0.3f), p5 = pixelAt(0.5f);
    addSquare(a, -4.0f * p3, 0.0f, -0.3f, 4.0f * p3);  // the panel
    Scene b = a;
    addSquare(a, -4.0f * p5, 0.0f, -0.5f, 4.0f * p5);  // behind the panel
    addSquare(b, 6.0f * p5, 0.0f, -0.5f, 4.0f * p5);   // pixels 18..25
    const MotionMap m = motion(a, b);
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
            const bool revealed = x >= 18 && x <= 25 && y >= 12 && y <= 19;
            ASSERT_EQ(m.partner[pixel(x, y)], revealed ? kNoTemporalPartner : pixel(x, y)) << x << "," << y;
        }
    EXPECT_EQ(m.partnered, std::size_t(kSize * kSize - 64));
}

TEST(MotionMap, FramesOfDifferentTrianglesReplayAtTheSamePixel) {
    const Scene a = makeEmissiveQuad(glm::vec3(1.0f));
    Scene b = a;
    addSquare(b, 0.0f, 0.0f, -0.5f, 0.01f);
    b.cameras[0].position.x += 0.1f;
    const MotionMap m = motion(a, b);
    EXPECT_FALSE(m.sameTopology);
    EXPECT_EQ(m.partnered, std::size_t(kSize * kSize));
    for (std::size_t p = 0; p < m.partner.size(); ++p) ASSERT_EQ(m.partner[p], p);
}

}  // namespace
}  // namespace gdpt
