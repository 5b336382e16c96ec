// The light table's selection probabilities (light_table.h) on a furnace sphere whose cap is a
// second emissive material of the same emission: every triangle's power is proportional to
// its area, so each rule's probabilities follow from the areas alone.
#include <gtest/gtest.h>

#include <numeric>

#include "render/device_scene/features.h"
#include "render/device_scene/light_table.h"
#include "scene/procedural.h"

namespace gdpt {
namespace {

TEST(LightTable, EachRuleGivesItsProbabilities) {
    const Scene s = makeTwoEmitterFurnace(0.5f, glm::vec3(0.5f), 2);
    std::vector<std::uint32_t> order(s.triangles.size());
    std::iota(order.begin(), order.end(), 0u);
    double area[2] = {0.0, 0.0}, total = 0.0;
    for (std::size_t t = 0; t < s.triangles.size(); ++t) {
        area[s.triangleMaterial[t]] += triangleArea(s, t);
        total += triangleArea(s, t);
    }
    ASSERT_GT(area[1], 0.05 * total);
    ASSERT_LT(area[1], 0.4 * total);
    for (LightSelection sel : {LightSelection::Power, LightSelection::Uniform, LightSelection::Mixed}) {
        const double u = sel == LightSelection::Power ? 0.0 : sel == LightSelection::Uniform ? 1.0 : 0.5;
        const LightTable t = makeLightTable(s, order, sel);
        ASSERT_EQ(t.lights.size(), s.triangles.size()) << toString(sel);
        EXPECT_EQ(t.emitters, 2u);
        double sum = 0.0, emitterSum[2] = {0.0, 0.0};
        float previous = 0.0f;
        for (const gpu::LightTriangle& l : t.lights) {
            const std::uint32_t m = s.triangleMaterial[order[l.triangle]];
            const double a = triangleArea(s, order[l.triangle]);
            const double expected = (1.0 - u) * a / total + u * a / (2.0 * area[m]);
            EXPECT_NEAR(l.pmf, expected, 1e-6 * expected) << toString(sel) << " triangle " << l.triangle;
            sum += l.pmf;
            emitterSum[m] += l.pmf;
            EXPECT_GE(l.cdf, previous);
            EXPECT_NEAR(l.cdf, sum, 1e-5);
            previous = l.cdf;
        }
        EXPECT_EQ(t.lights.back().cdf, 1.0f);
        EXPECT_NEAR(sum, 1.0, 1e-5);
        // The cap's share: its area fraction (power), 1/2 (uniform), their mean (mixed).
        EXPECT_NEAR(emitterSum[1], (1.0 - u) * area[1] / total + u * 0.5, 1e-5) << toString(sel);
    }
}

TEST(LightTable, NamesRoundTrip) {
    for (LightSelection sel : {LightSelection::Power, LightSelection::Uniform, LightSelection::Mixed})
        EXPECT_EQ(parseLightSelection(toString(sel)), sel);
    EXPECT_FALSE(parseLightSelection("area").has_value());
    for (const char* name : kLightSelectionChoices)
        EXPECT_EQ(toString(*parseLightSelection(name)), std::string(name));
}

}  // namespace
}  // namespace gdpt
