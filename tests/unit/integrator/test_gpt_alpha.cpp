// G-PT's primal weight when --alpha is not given (gpt_alpha.h): the scene's light as the
// features see it, on the project's scenes with and without an environment, and the α of each
// case.
#include <gtest/gtest.h>

#include <glm/glm.hpp>

#include "integrator/gpt_alpha.h"
#include "render/device_scene/features.h"
#include "scene/gltf_loader.h"

namespace gdpt {
namespace {

SceneFeatures featuresOf(const char* scene, glm::vec3 env) {
    return analyzeScene(loadGltf(std::string(GDPT_SOURCE_DIR "/scenes/") + scene), env);
}

TEST(GptAlpha, EmissiveSurfacesAloneKeepThePublishedWeight) {
    for (const char* scene :
         {"cornell_box.gltf", "small_light.gltf", "glossy_cornell.gltf", "open_scene.gltf"}) {
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

TEST(GptAlpha, NamesEachCase) {
    EXPECT_STREQ(toString(GptLighting::Emitters), "emitters");
    EXPECT_STREQ(toString(GptLighting::EnvironmentAndEmitters), "environment and emitters");
    EXPECT_STREQ(toString(GptLighting::Environment), "environment");
}

}  // namespace
}  // namespace gdpt
