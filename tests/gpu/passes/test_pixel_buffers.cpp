// The size advice of an image too large for the device: the largest image of the same shape
// that every per-pixel buffer allows, checked against brute force, and G-PT refusing an image
// beyond the device's allocation limit with that advice.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "cli_runner.h"
#include "gpu_fixture.h"
#include "render/passes/pixel_buffers.h"
#include "vk/context.h"

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

// G-PT at 7680x4320 needs its resolved images (96 bytes per pixel, 3.2 GB) in one allocation,
// above lavapipe's maxMemoryAllocationSize (2 GiB): refused at once, naming the largest 16:9
// image whose every per-pixel buffer fits. (That the advised size renders is a slow test:
// tests/slow/test_real_sizes.cpp.)
TEST(PixelBuffers, AnImageBeyondTheAllocationLimitIsRefusedWithTheLargestThatFits) {
    const std::string scene = std::string(GDPT_SOURCE_DIR) + "/scenes/cornell_box.gltf";
    const std::string out = ::testing::TempDir() + "gdpt_refused.exr";
    const std::uint64_t maxAllocation = test::gpuContext().info().maxMemoryAllocationSize;
    if (maxAllocation >= 7680ull * 4320ull * 96ull) GTEST_SKIP() << "this device holds an 8K G-PT render";
    // As if the machine had 10 TB, so that its memory (checked first) does not bind.
    const test::RunResult refused = test::runGdpt(
        "render " + scene + " --method gpt --width 7680 --height 4320 --spp 1 --quiet -o " + out,
        "GDPT_TEST_MEMORY_BYTES=10000000000000");
    ASSERT_EQ(refused.code, 1) << refused.output;
    EXPECT_NE(refused.output.find("maxMemoryAllocationSize"), std::string::npos) << refused.output;
    const std::string advice = "image of this shape that fits is ";
    const std::size_t at = refused.output.find(advice);
    ASSERT_NE(at, std::string::npos) << refused.output;
    unsigned w = 0, h = 0;
    ASSERT_EQ(std::sscanf(refused.output.c_str() + at + advice.size(), "%ux%u", &w, &h), 2) << refused.output;
    EXPECT_NEAR(double(w) / h, 7680.0 / 4320.0, 0.01);
    // Every buffer of the advised image fits, and a 1 % larger one would not.
    EXPECT_LE(std::uint64_t{w} * h * 96u, maxAllocation);
    EXPECT_GT(std::uint64_t{w} * h * 96u * 102u / 100u, maxAllocation);
}

// The memory check of a whole render: an image that fits is not refused, the advised image
// fits, and one a pixel larger on each side does not (so the advice is nearly the largest of
// its width steps); methods not measured are not checked.
TEST(PixelBuffers, ImageMemoryRefusalAdvisesTheLargestImageThatFits) {
    const std::uint64_t memory = 2'000'000'000;
    for (const std::string method : {"pt", "gpt"}) {
        const std::uint64_t perPixel = imageBytesPerMegapixel(method);
        ASSERT_GT(perPixel, 0u) << method;
        EXPECT_EQ(imageMemoryRefusal(method, 256, 256, memory), "") << method;
        const std::uint32_t width = method == "gpt" ? 2000 : 6000;
        const std::uint32_t height = method == "gpt" ? 1500 : 3000;
        const std::string refusal = imageMemoryRefusal(method, width, height, memory);
        const auto at = refusal.find("fits is ");
        ASSERT_NE(at, std::string::npos) << refusal;
        unsigned w = 0, h = 0;
        ASSERT_EQ(std::sscanf(refusal.c_str() + at + 8, "%ux%u", &w, &h), 2) << refusal;
        EXPECT_EQ(imageMemoryRefusal(method, w, h, memory), "") << method << " " << w << "x" << h;
        EXPECT_NE(imageMemoryRefusal(method, w + 1, h + 1, memory), "") << method;
        // The advice holds nearly all the memory allows: within a row or column of it.
        const double allowed = double(memory) / double(perPixel) * 1e6;
        EXPECT_GT(double(w) * double(h), allowed - double(std::max(w, h)) - 1.0) << method;
    }
    EXPECT_EQ(imageMemoryRefusal("gmlt", 100000, 100000, memory), "");
}

}  // namespace
}  // namespace gdpt
