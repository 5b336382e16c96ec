// The light probe (light_probe.h) and the table it sets (light_table.h, LightSelection::Probe),
// on the Cornell box with a second emitter that no visible surface can see (behind the back
// wall), and with a second light facing away from the room or into it.
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

#include "render/device_scene/light_probe.h"
#include "render/device_scene/light_table.h"
#include "render/device_scene/scene_gpu.h"
#include "scene/procedural.h"
#include "scene_builders.h"

namespace gdpt {
namespace {

constexpr std::uint32_t kCeilingLight = 3;  // makeCornellBox's light material

gpu::SceneConstants cameraOf(const Scene& s, int width, int height) {
    gpu::SceneConstants c{};
    setCamera(c, renderCamera(s, -1), width, height);
    return c;
}

std::vector<std::uint32_t> identityOrder(const Scene& s) {
    std::vector<std::uint32_t> order(s.triangles.size());
    std::iota(order.begin(), order.end(), 0u);
    return order;
}

// The probe rule's shares are rounded to sixteenths (light_table.cpp, alignedShares).
double sixteenths(double share) {
    return std::round(16.0 * share) / 16.0;
}

TEST(LightProbe, AnEmitterNoVisibleSurfaceSeesScoresZeroAndKeepsHalfItsMixedShare) {
    std::uint32_t hidden = 0;
    const Scene s = test::cornellBoxWithHiddenEmitter(hidden);
    const SceneBvh bvh = buildSceneBvh(s);
    const EmitterProbe probe = probeEmitters(s, bvh, cameraOf(s, 64, 64), sceneRadius(s));
    EXPECT_EQ(probe.points, 32u * 32u);  // every probe ray hits the closed room
    ASSERT_EQ(probe.secondMoment.size(), 2u);
    EXPECT_EQ(probe.secondMoment.at(hidden), 0.0);
    EXPECT_GT(probe.secondMoment.at(kCeilingLight), 0.0);

    std::map<std::uint32_t, double> weights;
    for (const auto& [m, m2] : probe.secondMoment) weights[m] = std::sqrt(m2);
    const std::vector<std::uint32_t> order = identityOrder(s);
    const LightTable mixed = makeLightTable(s, order, LightSelection::Mixed);
    const LightTable probed = makeLightTable(s, order, LightSelection::Probe, weights);
    EXPECT_TRUE(probed.probed);
    // Half its `mixed` share (0.364), in sixteenths.
    EXPECT_EQ(probed.shares.at(hidden), sixteenths(0.5 * mixed.shares.at(hidden)));
    EXPECT_EQ(probed.shares.at(kCeilingLight), 1.0 - probed.shares.at(hidden));
    EXPECT_EQ(probed.lights.back().cdf, 1.0f);
}

// A second light of the ceiling light's size and radiance across the open front of the box
// (z = 0.999), facing out (towards the camera: nothing in the room receives its light) or in.
TEST(LightProbe, AnEmitterFacingAwayFromTheVisibleSurfacesScoresZero) {
    for (const bool in : {false, true}) {
        SCOPED_TRACE(in ? "facing in" : "facing out");
        Scene s = makeCornellBox();
        const glm::vec3 a{0.3f, 0.3f, 0.999f}, b{0.77f, 0.3f, 0.999f}, c{0.77f, 0.68f, 0.999f},
            d{0.3f, 0.68f, 0.999f};
        const glm::vec3 le = s.materials[kCeilingLight].emissive;
        const std::uint32_t twin =
            in ? test::addEmitterQuad(s, d, c, b, a, le) : test::addEmitterQuad(s, a, b, c, d, le);
        const SceneBvh bvh = buildSceneBvh(s);
        const EmitterProbe probe = probeEmitters(s, bvh, cameraOf(s, 64, 64), sceneRadius(s));
        ASSERT_EQ(probe.secondMoment.size(), 2u);
        EXPECT_GT(probe.secondMoment.at(kCeilingLight), 0.0);
        if (in)
            EXPECT_GT(probe.secondMoment.at(twin), 0.0);
        else
            EXPECT_EQ(probe.secondMoment.at(twin), 0.0);
    }
}

TEST(LightProbe, SameProbeOnEveryRun) {
    std::uint32_t hidden = 0;
    const Scene s = test::cornellBoxWithHiddenEmitter(hidden);
    const SceneBvh bvh = buildSceneBvh(s);
    const EmitterProbe a = probeEmitters(s, bvh, cameraOf(s, 48, 40), sceneRadius(s));
    const EmitterProbe b = probeEmitters(s, bvh, cameraOf(s, 48, 40), sceneRadius(s));
    EXPECT_EQ(a.points, b.points);
    EXPECT_EQ(a.secondMoment, b.secondMoment);
}

TEST(LightProbe, OneEmitterIsNotProbed) {
    const Scene s = makeCornellBox();
    const EmitterProbe probe = probeEmitters(s, buildSceneBvh(s), cameraOf(s, 16, 16), sceneRadius(s));
    EXPECT_TRUE(probe.secondMoment.empty());
    EXPECT_EQ(probe.points, 0u);
}

// The probe's half follows the weights exactly; without usable weights, or with one emitter,
// the table is `mixed`'s bit for bit.
TEST(LightTable, ProbeRuleMixesTheWeightsHalfAndHalfWithMixed) {
    std::uint32_t hidden = 0;
    const Scene s = test::cornellBoxWithHiddenEmitter(hidden);
    const std::vector<std::uint32_t> order = identityOrder(s);
    const LightTable mixed = makeLightTable(s, order, LightSelection::Mixed);
    const LightTable probed =
        makeLightTable(s, order, LightSelection::Probe, {{kCeilingLight, 3.0}, {hidden, 1.0}});
    EXPECT_TRUE(probed.probed);
    EXPECT_EQ(probed.shares.at(kCeilingLight), sixteenths(0.5 * mixed.shares.at(kCeilingLight) + 0.375));
    EXPECT_EQ(probed.shares.at(hidden), sixteenths(0.5 * mixed.shares.at(hidden) + 0.125));
    EXPECT_EQ(probed.shares.at(kCeilingLight) + probed.shares.at(hidden), 1.0);
    // Each emitter's triangles are one run of the table, starting and ending on a sixteenth of
    // the CDF, their probabilities in proportion to their power.
    std::map<std::uint32_t, int> runs;
    std::uint32_t previous = UINT32_MAX;
    float start = 0.0f;
    for (const gpu::LightTriangle& l : probed.lights) {
        const std::uint32_t m = s.triangleMaterial[order[l.triangle]];
        if (m != previous) {
            ++runs[m];
            EXPECT_EQ(start * 16.0f, std::round(start * 16.0f)) << "emitter " << m << " starts at " << start;
            previous = m;
        }
        start = l.cdf;
    }
    EXPECT_EQ(runs.at(kCeilingLight), 1);
    EXPECT_EQ(runs.at(hidden), 1);

    for (const std::map<std::uint32_t, double>& w :
         {std::map<std::uint32_t, double>{}, std::map<std::uint32_t, double>{{hidden, 0.0}},
          std::map<std::uint32_t, double>{{kCeilingLight, std::nan("")}}}) {
        const LightTable t = makeLightTable(s, order, LightSelection::Probe, w);
        EXPECT_FALSE(t.probed);
        ASSERT_EQ(t.lights.size(), mixed.lights.size());
        for (std::size_t i = 0; i < t.lights.size(); ++i) {
            EXPECT_EQ(t.lights[i].pmf, mixed.lights[i].pmf);
            EXPECT_EQ(t.lights[i].cdf, mixed.lights[i].cdf);
        }
    }
    const Scene one = makeCornellBox();
    const LightTable single =
        makeLightTable(one, identityOrder(one), LightSelection::Probe, {{kCeilingLight, 1.0}});
    const LightTable singleMixed = makeLightTable(one, identityOrder(one), LightSelection::Mixed);
    EXPECT_FALSE(single.probed);
    for (std::size_t i = 0; i < single.lights.size(); ++i)
        EXPECT_EQ(single.lights[i].pmf, singleMixed.lights[i].pmf);
}

// With 40 emitters `mixed` gives each small one less than a sixteenth: shares that would round
// to zero leave every share as the half-and-half formula gives it.
TEST(LightTable, ProbeSharesBelowHalfASixteenthAreNotRounded) {
    Scene s = makeCornellBox();
    std::map<std::uint32_t, double> weights{{kCeilingLight, 1.0}};
    for (int k = 0; k < 39; ++k) {
        const float x = -0.9f + 0.04f * float(k);
        weights[test::addEmitterQuad(s, {x, 0.01f, 0.5f}, {x + 0.02f, 0.01f, 0.5f}, {x + 0.02f, 0.01f, 0.48f},
                                     {x, 0.01f, 0.48f}, glm::vec3(1.0f))] = 0.0;
    }
    const std::vector<std::uint32_t> order = identityOrder(s);
    const LightTable mixed = makeLightTable(s, order, LightSelection::Mixed);
    const LightTable probed = makeLightTable(s, order, LightSelection::Probe, weights);
    ASSERT_TRUE(probed.probed);
    ASSERT_EQ(probed.emitters, 40u);
    double sum = 0.0;
    for (const auto& [m, share] : probed.shares) {
        EXPECT_NEAR(share, 0.5 * mixed.shares.at(m) + (m == kCeilingLight ? 0.5 : 0.0), 1e-12)
            << "material " << m;
        sum += share;
    }
    EXPECT_NEAR(sum, 1.0, 1e-12);
    EXPECT_EQ(probed.lights.back().cdf, 1.0f);
}

}  // namespace
}  // namespace gdpt
