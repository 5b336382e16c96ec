// The rule of `--edge-samples auto` (render/passes/edge_options.h) and the option's parsing.
#include <gtest/gtest.h>

#include "render/passes/edge_options.h"
#include "util/error.h"

namespace gdpt {
namespace {

TEST(EdgeOptions, AutoFactorFollowsTheListedPixelsShare) {
    const std::uint64_t pixels = 256 * 256;
    // The figures the rule was drawn from (bench/RESULTS.md, "Edge samples for both pixels of
    // a pair"): pixels listed (edge pixels and their neighbours) at 256².
    EXPECT_EQ(autoEdgeSamples(4017, pixels), 2u);   // cornell_box, 6.1 %
    EXPECT_EQ(autoEdgeSamples(6758, pixels), 2u);   // open_scene, 10.3 %
    EXPECT_EQ(autoEdgeSamples(16550, pixels), 2u);  // 2CylinderEngine, 25.3 %
    // floor(0.6 / share), at most 2; no edges: the largest (nothing to add anyway).
    EXPECT_EQ(autoEdgeSamples(0, pixels), 2u);
    EXPECT_EQ(autoEdgeSamples(1, 1), 0u);
    EXPECT_EQ(autoEdgeSamples(30, 100), 2u);
    EXPECT_EQ(autoEdgeSamples(31, 100), 1u);
    EXPECT_EQ(autoEdgeSamples(60, 100), 1u);
    EXPECT_EQ(autoEdgeSamples(61, 100), 0u);
    // Never more as the share falls.
    std::uint32_t last = 0;
    for (std::uint64_t e = pixels; e > 0; e /= 2) {
        const std::uint32_t k = autoEdgeSamples(e, pixels);
        EXPECT_GE(k, last);
        EXPECT_LE(k, kAutoEdgeSamplesMax);
        last = k;
    }
}

// The pixels that get the extra samples: the edge pixels and their four neighbours, in
// ascending order, once each, within the image.
TEST(EdgeOptions, TheSampledPixelsAreTheEdgePixelsAndTheirFourNeighbours) {
    const std::uint32_t w = 5, h = 4;
    std::vector<std::uint32_t> mask(w * h, 0u);
    mask[0] = 1;          // corner (0, 0): itself, (1, 0), (0, 1)
    mask[2 * w + 3] = 1;  // inside (3, 2): itself and four neighbours
    mask[2 * w + 4] = 1;  // its right neighbour (4, 2), on the border: adds (4, 1), (4, 3)
    const std::vector<std::uint32_t> expected = {0,         1,         w,         w + 3,     w + 4,
                                                 2 * w + 2, 2 * w + 3, 2 * w + 4, 3 * w + 3, 3 * w + 4};
    EXPECT_EQ(edgeSampleList(mask, w, h), expected);
    EXPECT_TRUE(edgeSampleList(std::vector<std::uint32_t>(w * h, 0u), w, h).empty());
    EXPECT_EQ(edgeSampleList(std::vector<std::uint32_t>(w * h, 7u), w, h).size(), std::size_t{w} * h);
    EXPECT_TRUE(edgeSampleList(mask, w, h + 1).empty());  // a mask of another size
}

// The rate of each pixel (gpt.comp's sample counts in the pair weights): 1 + factor in the
// listed pixels, 1 in the others; a list entry outside the image is ignored.
TEST(EdgeOptions, SampleRatesAreOnePlusTheFactorInTheListedPixels) {
    const std::uint32_t w = 4, h = 3;
    const std::vector<std::uint32_t> rates = edgeSampleRates({1, 5, 6, 11, 12}, 2, w, h);
    const std::vector<std::uint32_t> expected = {1, 3, 1, 1, 1, 3, 3, 1, 1, 1, 1, 3};
    EXPECT_EQ(rates, expected);
    EXPECT_EQ(edgeSampleRates({}, 2, w, h), std::vector<std::uint32_t>(w * h, 1u));
    EXPECT_EQ(edgeSampleRates({0, 1}, 0, w, h), std::vector<std::uint32_t>(w * h, 1u));
}

TEST(EdgeOptions, ParsesAutoAndWholeNumbersAndRefusesTheRest) {
    EXPECT_EQ(parseEdgeSamples("auto", "x"), kEdgeSamplesAuto);
    EXPECT_EQ(parseEdgeSamples("0", "x"), 0u);
    EXPECT_EQ(parseEdgeSamples("4", "x"), 4u);
    EXPECT_EQ(parseEdgeSamples("64", "x"), 64u);
    for (const char* bad : {"", "65", "-1", "4.0", "Auto", "1e1", "0004", " 4"}) {
        EXPECT_THROW((void)parseEdgeSamples(bad, "--edge-samples"), Error) << "'" << bad << "'";
    }
    EXPECT_EQ(edgeSamplesText(kEdgeSamplesAuto), "auto");
    EXPECT_EQ(edgeSamplesText(3), "3");
    EXPECT_EQ(parseEdgeSamples(edgeSamplesText(17), "x"), 17u);
}

}  // namespace
}  // namespace gdpt
