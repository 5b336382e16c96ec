// G-PT's primal weight when --alpha is not given (gpt_alpha.h): the scene's light as the
// features see it, on the project's scenes with and without an environment or a sky of
// emissive triangles, and the α of each case.
#include <gtest/gtest.h>

#include <glm/glm.hpp>

#include "integrator/gpt_alpha.h"
#include "render/device_scene/features.h"
#include "scene/gltf_loader.h"
#include "scene/procedural.h"
#include "scene_builders.h"

namespace gdpt {
namespace {

SceneFeatures featuresOf(const char* scene, glm::vec3 env) {
    return analyzeScene(loadGltf(std::string(GDPT_SOURCE_DIR "/scenes/") + scene), env);
}

TEST(GptAlpha, EmissiveSurfacesAloneKeepThePublishedWeight) {
    for (const char* scene : {"cornell_box.gltf", "small_light.gltf", "glossy_cornell.gltf", "textured.gltf",
                              "indirect_gap.gltf"}) {
        EXPECT_EQ(gptLighting(featuresOf(scene, glm::vec3(0.0f))), GptLighting::Emitters) << scene;
    }
    EXPECT_EQ(gptDefaultAlpha(GptLighting::Emitters), 0.2);
}

TEST(GptAlpha, AnEnvironmentBesideEmittersWeighsThePrimalMore) {
    const SceneFeatures f = featuresOf("cornell_box.gltf", glm::vec3(0.0f, 0.0f, 0.3f));
    EXPECT_EQ(gptLighting(f), GptLighting::EnvironmentAndEmitters);
    EXPECT_EQ(gptDefaultAlpha(gptLighting(f)), 0.4);
}

TEST(GptAlpha, AnEnvironmentAloneWeighsThePrimalMost) {
    // The Cornell box's geometry with its lamp's emission taken away: lit by the sky alone.
    Scene scene = loadGltf(GDPT_SOURCE_DIR "/scenes/cornell_box.gltf");
    for (auto& m : scene.materials) m.flags &= ~gpu::kMatFlagEmissive;
    const SceneFeatures f = analyzeScene(scene, glm::vec3(1.0f));
    ASSERT_EQ(f.emissiveTriangles, 0u);
    EXPECT_EQ(gptLighting(f), GptLighting::Environment);
    EXPECT_EQ(gptDefaultAlpha(gptLighting(f)), 0.8);
    // A punctual light beside the environment counts as an emitter.
    SceneFeatures withPoint = f;
    withPoint.punctualLights = 1;
    withPoint.hasPunctual = true;
    EXPECT_EQ(gptLighting(withPoint), GptLighting::EnvironmentAndEmitters);
}

// The Cornell box (lamp included) with a box of a new material around it, emissive or not: six
// quads from lo to hi (procedural.h's addQuad, which keeps the scene's normals beside its
// positions).
Scene cornellBoxInside(glm::vec3 lo, glm::vec3 hi, bool emissive) {
    Scene scene = loadGltf(GDPT_SOURCE_DIR "/scenes/cornell_box.gltf");
    scene.materials.push_back(test::lambert(glm::vec3(0.0f), glm::vec3(emissive ? 1.0f : 0.0f)));
    const auto m = static_cast<std::uint32_t>(scene.materials.size() - 1);
    glm::vec3 c[8];
    for (int i = 0; i < 8; ++i)
        c[i] = glm::vec3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
    const int faces[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1},
                             {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
    for (const auto& f : faces) addQuad(scene, c[f[0]], c[f[1]], c[f[2]], c[f[3]], m);
    return scene;
}

TEST(GptAlpha, ASkyOfEmissiveTrianglesCountsAsASky) {
    // The project's scenes with one: the open scene's dome, and the furnace's sphere alone.
    for (const char* scene : {"open_scene.gltf", "furnace.gltf"}) {
        const SceneFeatures f = featuresOf(scene, glm::vec3(0.0f));
        EXPECT_TRUE(f.hasEmissiveEnclosure) << scene;
        EXPECT_EQ(gptLighting(f), GptLighting::EmissiveSky) << scene;
    }
    EXPECT_EQ(gptDefaultAlpha(GptLighting::EmissiveSky), 0.4);
    // The Cornell box (within [-1, 1] x [0, 2] x [-1, 1]) inside an emissive box: a sky.
    const glm::vec3 lo(-10.0f, -9.0f, -10.0f), hi(10.0f, 11.0f, 10.0f);
    EXPECT_EQ(gptLighting(analyzeScene(cornellBoxInside(lo, hi, true), glm::vec3(0.0f))),
              GptLighting::EmissiveSky);
    // Not one: the same box not emitting; a box that leaves part of the room outside; an
    // emissive panel as large as the scene but flat.
    EXPECT_EQ(gptLighting(analyzeScene(cornellBoxInside(lo, hi, false), glm::vec3(0.0f))),
              GptLighting::Emitters);
    EXPECT_EQ(
        gptLighting(analyzeScene(cornellBoxInside(lo, glm::vec3(10.0f, 1.5f, 10.0f), true), glm::vec3(0.0f))),
        GptLighting::Emitters);
    EXPECT_EQ(gptLighting(
                  analyzeScene(cornellBoxInside(lo, glm::vec3(10.0f, -9.0f, 10.0f), true), glm::vec3(0.0f))),
              GptLighting::Emitters);
    // An environment beside it decides as before (the sky of triangles is an emitter then).
    EXPECT_EQ(gptLighting(analyzeScene(cornellBoxInside(lo, hi, true), glm::vec3(1.0f))),
              GptLighting::EnvironmentAndEmitters);
}

TEST(GptAlpha, NamesEachCase) {
    EXPECT_STREQ(toString(GptLighting::Emitters), "emitters");
    EXPECT_STREQ(toString(GptLighting::EnvironmentAndEmitters), "environment and emitters");
    EXPECT_STREQ(toString(GptLighting::Environment), "environment");
    EXPECT_STREQ(toString(GptLighting::EmissiveSky), "emissive sky");
}

}  // namespace
}  // namespace gdpt
