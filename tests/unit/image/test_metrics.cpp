// test_metrics.cpp — relMSE (Kettunen et al. 2015), MSE, MAE, max error against hand-computed
// values, non-finite handling, and the shared Cornell-box reference.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "image/exr_io.h"
#include "image/metrics.h"
#include "shared_data.h"
#include "util/error.h"

namespace gdpt {
namespace {

Image makeImage(int w, int h, std::initializer_list<float> rgbValues) {
    Image image(w, h);
    auto it = rgbValues.begin();
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c) image.at(x, y, c) = *it++;
    return image;
}

// Reference p0 = (0.1, 0.2, 0.3): gray = 0.2, denominator = 1e-3 + 0.04 = 0.041.
// Test     p0 = (0.2, 0.2, 0.1): diffs (0.1, 0, -0.2), squares (0.01, 0, 0.04), sum 0.05
//          -> 0.05 / 0.041 = 1.219512195...
// Reference p1 = (0, 0, 0): gray = 0, denominator = 1e-3.
// Test     p1 = (0.01, 0, 0.02): squares (1e-4, 0, 4e-4), sum 5e-4 -> 5e-4 / 1e-3 = 0.5.
// relMSE = (1.219512195 + 0.5) / 2 = 0.859756098 (= 3 x mean over the 6 pixel-channels).
// MSE  = (0.01 + 0 + 0.04 + 1e-4 + 0 + 4e-4) / 6 = 0.0505 / 6
// MAE  = (0.1 + 0 + 0.2 + 0.01 + 0 + 0.02) / 6 = 0.33 / 6 = 0.055
// max  = 0.2;  bias = (0.1 + 0 - 0.2 + 0.01 + 0 + 0.02) / 6 = -0.07 / 6
TEST(Metrics, HandComputedTwoPixelImage) {
    const Image reference = makeImage(2, 1, {0.1f, 0.2f, 0.3f, 0.0f, 0.0f, 0.0f});
    const Image test = makeImage(2, 1, {0.2f, 0.2f, 0.1f, 0.01f, 0.0f, 0.02f});
    const ImageErrorStats s = compareImages(test, reference);
    // Inputs are float: allow float rounding of the inputs (relative ~1e-6).
    EXPECT_NEAR(s.relMse, (0.05 / 0.041 + 0.5) / 2.0, 1e-6);
    EXPECT_NEAR(s.mse, 0.0505 / 6.0, 1e-8);
    EXPECT_NEAR(s.mae, 0.055, 1e-7);
    EXPECT_NEAR(s.maxAbsError, 0.2, 1e-7);
    EXPECT_NEAR(s.meanBias, -0.07 / 6.0, 1e-7);
    EXPECT_NEAR(s.meanReference[2], 0.15, 1e-7);
    EXPECT_NEAR(s.meanTest[0], 0.105, 1e-7);
    EXPECT_EQ(s.finitePixels, 2u);
    EXPECT_EQ(s.nonFinitePixels, 0u);
    EXPECT_DOUBLE_EQ(relMse(test, reference), s.relMse);
    EXPECT_DOUBLE_EQ(mse(test, reference), s.mse);
    EXPECT_DOUBLE_EQ(mae(test, reference), s.mae);
    // Not symmetric: the denominator uses the reference's gray value.
    EXPECT_GT(std::abs(relMse(reference, test) - s.relMse), 0.1);
}

TEST(Metrics, NonFinitePixelsAreCountedAndExcluded) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    const Image reference =
        makeImage(4, 1, {0.1f, 0.2f, 0.3f, 0.0f, 0.0f, 0.0f, 1.0f, 1.0f, 1.0f, inf, 0.0f, 0.0f});
    const Image test =
        makeImage(4, 1, {0.2f, 0.2f, 0.1f, 0.01f, 0.0f, 0.02f, 1.0f, nan, 1.0f, 0.0f, 0.0f, 0.0f});
    const ImageErrorStats s = compareImages(test, reference);
    EXPECT_EQ(s.nonFinitePixels, 2u);
    EXPECT_EQ(s.finitePixels, 2u);
    EXPECT_NEAR(s.relMse, (0.05 / 0.041 + 0.5) / 2.0, 1e-6);
    EXPECT_TRUE(std::isfinite(s.mse));
    const Image allNan = makeImage(1, 1, {nan, nan, nan});
    EXPECT_TRUE(std::isnan(relMse(allNan, allNan)));
    EXPECT_EQ(compareImages(allNan, allNan).nonFinitePixels, 1u);
}

TEST(Metrics, ErrorMapAndBrightnessQuartersSplitRelMse) {
    // Four pixels, references of gray 0.2, 0 (the darkest), 1, and a NaN test value; the
    // hand-computed terms of the two-pixel test above, and 0.25 / 1.001 for the gray-1 pixel.
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const Image reference =
        makeImage(4, 1, {0.1f, 0.2f, 0.3f, 0.0f, 0.0f, 0.0f, 1.0f, 1.0f, 1.0f, 0.5f, 0.5f, 0.5f});
    const Image test =
        makeImage(4, 1, {0.2f, 0.2f, 0.1f, 0.01f, 0.0f, 0.02f, 1.5f, 1.0f, 1.0f, nan, 0.5f, 0.5f});
    const Image map = relMseMap(test, reference);
    EXPECT_NEAR(map.at(0, 0, 0), 0.05 / 0.041, 1e-6);
    EXPECT_NEAR(map.at(1, 0, 2), 0.5, 1e-6);
    EXPECT_NEAR(map.at(2, 0, 1), 0.25 / 1.001, 1e-6);
    EXPECT_TRUE(std::isnan(map.at(3, 0, 0)));
    const ImageErrorStats s = compareImages(test, reference);
    // Three finite pixels by gray: 0 (quarter 0), 0.2 (quarter 1), 1 (quarter 2); none in 3.
    EXPECT_NEAR(s.relMseByQuarter[0], 0.5 / 3.0, 1e-6);
    EXPECT_NEAR(s.relMseByQuarter[1], 0.05 / 0.041 / 3.0, 1e-6);
    EXPECT_NEAR(s.relMseByQuarter[2], 0.25 / 1.001 / 3.0, 1e-6);
    EXPECT_EQ(s.relMseByQuarter[3], 0.0);
    EXPECT_NEAR(s.relMseByQuarter[0] + s.relMseByQuarter[1] + s.relMseByQuarter[2], s.relMse, 1e-12);
    EXPECT_THROW(relMseMap(Image(2, 2), Image(2, 3)), Error);
}

TEST(Metrics, SizeMismatchThrows) {
    EXPECT_THROW(compareImages(Image(2, 2), Image(2, 3)), Error);
    EXPECT_THROW(relMse(Image(3, 1), Image(1, 3)), Error);
}

TEST(Image, AddImagesSumsEveryChannelAndRefusesOtherSizes) {
    Image a(2, 1, 1.0f), b(2, 1, 0.0f);
    b.at(1, 0, 2) = 2.5f;
    const Image sum = addImages(a, b);
    EXPECT_EQ(sum.at(0, 0, 2), 1.0f);
    EXPECT_EQ(sum.at(1, 0, 2), 3.5f);
    EXPECT_EQ(sum.at(1, 0, 0), 1.0f);
    EXPECT_THROW((void)addImages(a, Image(1, 2)), Error);
}

TEST(Metrics, CboxReferenceAgainstItselfAndReadmeMean) {
    const std::string file = test::sharedDataPath("scenes/cbox/reference.exr");
    GDPT_REQUIRE_SHARED_DATA(file);
    const Image reference = readExrLayer(file);
    EXPECT_EQ(reference.width(), 256);
    EXPECT_EQ(reference.height(), 256);
    const ImageErrorStats s = compareImages(reference, reference);
    EXPECT_EQ(s.relMse, 0.0);
    EXPECT_EQ(s.mse, 0.0);
    EXPECT_EQ(s.nonFinitePixels, 0u);
    // The mean RGB published with the reference image (rounded to 5 decimals).
    const auto mean = reference.meanRgb();
    EXPECT_NEAR(mean[0], 0.19617, 1e-4);
    EXPECT_NEAR(mean[1], 0.12765, 1e-4);
    EXPECT_NEAR(mean[2], 0.03613, 1e-4);
}

}  // namespace
}  // namespace gdpt

namespace gdpt {
namespace {

Image constantImage(int w, int h, float r, float g, float b) {
    Image im(w, h);
    for (std::size_t i = 0; i < im.pixelCount(); ++i) {
        im.plane(0)[i] = r;
        im.plane(1)[i] = g;
        im.plane(2)[i] = b;
    }
    return im;
}

TEST(TemporalRelMse, HandComputedValues) {
    // Reference frames 1 and 3 (grey 1, 3: mean gray 2); a test that follows the change exactly
    // has no temporal error, even if both its frames are off by the same amount.
    const Image r0 = constantImage(2, 2, 1, 1, 1), r1 = constantImage(2, 2, 3, 3, 3);
    EXPECT_EQ(
        temporalRelMse(constantImage(2, 2, 1.5f, 1.5f, 1.5f), constantImage(2, 2, 3.5f, 3.5f, 3.5f), r0, r1),
        0.0);
    // A test that does not change: per pixel Σ_c (0 − 2)² / (1e-3 + 4) = 12 / 4.001.
    EXPECT_NEAR(temporalRelMse(r0, r0, r0, r1), 12.0 / 4.001, 1e-12);
    // Flicker: one pixel off by +1 in frame 0 only: (−1)² · 3 / 4.001 over 4 pixels.
    Image t0 = r0;
    for (int c = 0; c < 3; ++c) t0.plane(c)[2] += 1.0f;
    EXPECT_NEAR(temporalRelMse(t0, r1, r0, r1), 3.0 / 4.001 / 4.0, 1e-12);
    EXPECT_THROW((void)temporalRelMse(r0, constantImage(2, 3, 1, 1, 1), r0, r1), Error);
}

TEST(TemporalRelMse, AlongTheMotionPairsEachPixelWithItsSource) {
    // A 4x1 ramp (1, 2, 3, 4) moving one pixel right: frame 1 is (x, 1, 2, 3), where pixel 0's
    // content is new. The motion layer says so: offset -1 and a source for pixels 1..3.
    const auto ramp = [](float first) {
        Image im(4, 1);
        for (int c = 0; c < 3; ++c)
            for (int x = 0; x < 4; ++x) im.plane(c)[std::size_t(x)] = first + float(x);
        return im;
    };
    const Image r0 = ramp(1.0f), r1 = ramp(0.0f);
    Image motion(4, 1);
    for (int x = 1; x < 4; ++x) {
        motion.plane(0)[std::size_t(x)] = -1.0f;
        motion.plane(2)[std::size_t(x)] = 1.0f;
    }
    // An error that stays on the content (+0.5 on the value 2 in both frames): none along the
    // motion, but a moving error pattern at the same pixel.
    Image t0 = r0, t1 = r1;
    for (int c = 0; c < 3; ++c) t0.plane(c)[1] += 0.5f, t1.plane(c)[2] += 0.5f;
    EXPECT_EQ(temporalRelMse(t0, t1, r0, r1, &motion), 0.0);
    EXPECT_GT(temporalRelMse(t0, t1, r0, r1), 0.1);
    // Flicker on the content: +0.5 on the value 3 in frame 1 only (pixel 3): per channel 0.25,
    // normalised by the gray of (3 + 3) / 2 and averaged over the 3 pixels with a source.
    Image f1 = r1;
    for (int c = 0; c < 3; ++c) f1.plane(c)[3] += 0.5f;
    EXPECT_NEAR(temporalRelMse(r0, f1, r0, r1, &motion), 3 * 0.25 / (1e-3 + 9.0) / 3.0, 1e-12);
    // Pixel 0 has no source: a change there is not counted along the motion.
    Image n1 = r1;
    for (int c = 0; c < 3; ++c) n1.plane(c)[0] += 7.0f;
    EXPECT_EQ(temporalRelMse(r0, n1, r0, r1, &motion), 0.0);
    const Image small(2, 1);
    EXPECT_THROW((void)temporalRelMse(r0, r1, r0, r1, &small), Error);
}

}  // namespace
}  // namespace gdpt
