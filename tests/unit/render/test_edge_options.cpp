// The rule of `--edge-samples auto` (render/passes/edge_options.h) and the option's parsing.
#include <gtest/gtest.h>

#include "render/passes/edge_options.h"
#include "util/error.h"

namespace gdpt {
namespace {

TEST(EdgeOptions, AutoFactorFollowsTheEdgePixelsShare) {
    const std::uint64_t pixels = 256 * 256;
    // The figures the rule was drawn from (bench/RESULTS.md, "The factor on a detailed asset").
    EXPECT_EQ(autoEdgeSamples(1331, pixels), 4u);  // cornell_box, 2.0 %
    EXPECT_EQ(autoEdgeSamples(2141, pixels), 4u);  // open_scene, 3.3 %
    EXPECT_EQ(autoEdgeSamples(5813, pixels), 1u);  // 2CylinderEngine, 8.9 %
    // floor(0.15 / share), at most 4; no edges: the largest (nothing to add anyway).
    EXPECT_EQ(autoEdgeSamples(0, pixels), 4u);
    EXPECT_EQ(autoEdgeSamples(1, 1), 0u);
    EXPECT_EQ(autoEdgeSamples(15, 100), 1u);
    EXPECT_EQ(autoEdgeSamples(16, 100), 0u);
    EXPECT_EQ(autoEdgeSamples(5, 100), 3u);
    EXPECT_EQ(autoEdgeSamples(3, 100), 4u);
    // Never more as the share falls.
    std::uint32_t last = 0;
    for (std::uint64_t e = pixels; e > 0; e /= 2) {
        const std::uint32_t k = autoEdgeSamples(e, pixels);
        EXPECT_GE(k, last);
        EXPECT_LE(k, kAutoEdgeSamplesMax);
        last = k;
    }
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
