// The size advice of an image too large for the device: the largest image of the same shape
// that every per-pixel buffer allows, checked against brute force, and a render at the advised
// size of an image G-PT refuses succeeds.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "cli_runner.h"
#include "render/passes/pixel_buffers.h"

namespace gdpt {
namespace {

// Brute force: among images with at most maxPixels pixels whose aspect ratio is within one
// pixel of width:height, the largest pixel count.
std::uint64_t bestByBruteForce(std::uint32_t width, std::uint32_t height, std::uint64_t maxPixels) {
    std::uint64_t best = 0;
    for (std::uint32_t w = 1; w <= width; ++w) {
        // h nearest to w * height / width (either side), within the pixel budget.
        const double exact = double(w) * height / width;
        for (auto h : {std::uint32_t(exact), std::uint32_t(exact) + 1}) {
            if (h < 1 || h > height || std::abs(double(h) - exact) >= 1.0) continue;
            if (std::uint64_t{w} * h <= maxPixels) best = std::max(best, std::uint64_t{w} * h);
        }
    }
    return best;
}

TEST(PixelBuffers, LargestFittingImageKeepsTheShapeAndIsNearlyTheLargest) {
    const std::uint32_t shapes[][2] = {{1920, 1080}, {3840, 2160}, {1000, 1},
                                       {1, 777},     {4096, 4096}, {333, 1000}};
    for (const auto& s : shapes)
        for (std::uint64_t maxPixels : {1ull, 1000ull, 123457ull, 1ull << 20, 5000000ull}) {
            const Extent e = largestFittingImage(s[0], s[1], maxPixels);
            const std::uint64_t got = std::uint64_t{e.width} * e.height;
            if (std::uint64_t{s[0]} * s[1] <= maxPixels) {
                EXPECT_EQ(e.width, s[0]);
                EXPECT_EQ(e.height, s[1]);
                continue;
            }
            EXPECT_GE(e.width, 1u);
            EXPECT_GE(e.height, 1u);
            EXPECT_LE(got, maxPixels) << s[0] << "x" << s[1];
            // The shape: one side within two pixels of what the other side and the requested
            // ratio give (whole pixels, and the shrinking, move it by that much at most).
            const double heightError = std::abs(double(e.width) * s[1] / s[0] - double(e.height));
            const double widthError = std::abs(double(e.height) * s[0] / s[1] - double(e.width));
            EXPECT_LE(std::min(heightError, widthError), 2.0)
                << s[0] << "x" << s[1] << " -> " << e.width << "x" << e.height;
            // Nearly the largest: within 1 % of the brute-force best of the same shape (or a
            // few pixels for tiny budgets).
            const std::uint64_t best = bestByBruteForce(s[0], s[1], maxPixels);
            EXPECT_GE(double(got) + 2.0 * (e.width + e.height), double(best))
                << s[0] << "x" << s[1] << " max " << maxPixels;
        }
}

// G-PT at 1920x1080 exceeds lavapipe's 128 MiB storage-buffer range; the message names the
// largest 16:9 image that fits, and that image renders.
TEST(PixelBuffers, TheAdvisedSizeRenders) {
    const std::string scene = std::string(GDPT_SOURCE_DIR) + "/scenes/cornell_box.gltf";
    const std::string out = ::testing::TempDir() + "gdpt_advised.exr";
    const test::RunResult refused = test::runGdpt(
        "render " + scene + " --method gpt --width 1920 --height 1080 --spp 1 --quiet -o " + out);
    if (refused.code == 0) GTEST_SKIP() << "this device holds a 1080p G-PT render";
    ASSERT_EQ(refused.code, 1) << refused.output;
    const std::string advice = "image of this shape that fits is ";
    const std::size_t at = refused.output.find(advice);
    ASSERT_NE(at, std::string::npos) << refused.output;
    unsigned w = 0, h = 0;
    ASSERT_EQ(std::sscanf(refused.output.c_str() + at + advice.size(), "%ux%u", &w, &h), 2) << refused.output;
    EXPECT_NEAR(double(w) / h, 1920.0 / 1080.0, 0.01);
    const test::RunResult advised =
        test::runGdpt("render " + scene + " --method gpt --width " + std::to_string(w) + " --height " +
                      std::to_string(h) + " --spp 1 --quiet --recon l2 -o " + out);
    EXPECT_EQ(advised.code, 0) << advised.output;
    std::remove(out.c_str());
    std::remove((out.substr(0, out.size() - 4) + ".png").c_str());
}

}  // namespace
}  // namespace gdpt
