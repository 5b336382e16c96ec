// test_light_sources.cpp — hasLightSource / blackImageWarning: each kind of light source
// counts on its own, and an emitter that cannot emit (black emission, zero area, unused
// material, zero intensity) does not.
#include <gtest/gtest.h>

#include "scene/light_sources.h"
#include "scene/procedural.h"

namespace gdpt {
namespace {

constexpr std::uint32_t kLight = 3;  // makeCornellBox's light material

// The Cornell box with its light switched off: no light source at all.
Scene darkBox() {
    Scene s = makeCornellBox();
    s.materials[kLight].emissive = glm::vec3(0.0f);
    s.materials[kLight].flags &= ~gpu::kMatFlagEmissive;
    return s;
}

gpu::PunctualLight pointLight(glm::vec3 intensity) {
    gpu::PunctualLight l{};
    l.position = glm::vec3(0.0f, 1.0f, 0.0f);
    l.type = gpu::kPunctualPoint;
    l.intensity = intensity;
    return l;
}

TEST(LightSources, CornellBoxHasOne) {
    const Scene s = makeCornellBox();
    EXPECT_TRUE(hasLightSource(s, glm::vec3(0.0f)));
    EXPECT_FALSE(blackImageWarning(s, glm::vec3(0.0f)).has_value());
}

TEST(LightSources, DarkSceneWarnsNamingTheFileAndTheFix) {
    Scene s = darkBox();
    s.sourcePath = "scenes/dark.gltf";
    EXPECT_FALSE(hasLightSource(s, glm::vec3(0.0f)));
    EXPECT_EQ(
        blackImageWarning(s, glm::vec3(0.0f)),
        "scenes/dark.gltf: no light source (no emissive surface, no punctual light, no --env): the image "
        "will be black; try --env 1,1,1");
    EXPECT_EQ(blackImageWarning(s, glm::vec3(0.0f), /*envOption=*/false),
              "scenes/dark.gltf: no light source (no emissive surface, no punctual light): the image will be "
              "black");
}

TEST(LightSources, EachKindCountsOnItsOwn) {
    EXPECT_TRUE(hasLightSource(darkBox(), {0.0f, 0.0f, 0.5f}));  // environment
    Scene punctual = darkBox();
    punctual.punctualLights.push_back(pointLight({0.0f, 2.0f, 0.0f}));
    EXPECT_TRUE(hasLightSource(punctual, glm::vec3(0.0f)));
    Scene red = darkBox();  // an emitter with one positive channel
    red.materials[kLight].emissive = {1.0f, 0.0f, 0.0f};
    red.materials[kLight].flags |= gpu::kMatFlagEmissive;
    EXPECT_TRUE(hasLightSource(red, glm::vec3(0.0f)));
}

TEST(LightSources, EmittersThatCannotEmitDoNotCount) {
    // Zero intensity punctual light; negative environment components (not light).
    Scene s = darkBox();
    s.punctualLights.push_back(pointLight(glm::vec3(0.0f)));
    EXPECT_FALSE(hasLightSource(s, {-1.0f, 0.0f, 0.0f}));

    // The light's triangles collapsed to zero area.
    Scene flat = makeCornellBox();
    for (std::size_t t = 0; t < flat.triangles.size(); ++t)
        if (flat.triangleMaterial[t] == kLight) {
            const glm::uvec3 tri = flat.triangles[t];
            flat.positions[tri.y] = flat.positions[tri.x];
        }
    EXPECT_FALSE(hasLightSource(flat, glm::vec3(0.0f)));

    // An emissive material that no triangle uses.
    Scene unused = makeCornellBox();
    for (std::uint32_t& m : unused.triangleMaterial)
        if (m == kLight) m = 0;
    EXPECT_FALSE(hasLightSource(unused, glm::vec3(0.0f)));
}

}  // namespace
}  // namespace gdpt
