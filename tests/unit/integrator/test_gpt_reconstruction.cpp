// G-PT's final reconstruction when --recon is not given (gpt_reconstruction.h): the scene's
// surfaces as the features see them, on the project's scenes and on a Cornell box given a
// mirror, and the reconstruction of each case.
#include <gtest/gtest.h>

#include <glm/glm.hpp>

#include "integrator/gpt_reconstruction.h"
#include "render/device_scene/features.h"
#include "scene/gltf_loader.h"

namespace gdpt {
namespace {

Scene sceneFile(const char* name) {
    return loadGltf(std::string(GDPT_SOURCE_DIR "/scenes/") + name);
}

TEST(GptReconstruction, RoughScenesKeepWeightedL1) {
    for (const char* scene : {"cornell_box.gltf", "small_light.gltf", "textured.gltf", "indirect_gap.gltf",
                              "open_scene.gltf", "furnace.gltf"}) {
        const SceneFeatures f = analyzeScene(sceneFile(scene), glm::vec3(0.0f));
        EXPECT_EQ(gptSurfaces(f), GptSurfaces::Rough) << scene;
    }
    EXPECT_EQ(gptDefaultReconstruction(GptSurfaces::Rough), Reconstruction::WeightedL1);
}

TEST(GptReconstruction, AMirrorChoosesWeightedL2) {
    // The glossy box's mirror sphere (roughness 0).
    EXPECT_EQ(gptSurfaces(analyzeScene(sceneFile("glossy_cornell.gltf"), glm::vec3(0.0f))),
              GptSurfaces::Glossy);
    EXPECT_EQ(gptDefaultReconstruction(GptSurfaces::Glossy), Reconstruction::WeightedL2);
    // The Cornell box with its red wall made a mirror; then that wall a GGX metal of roughness
    // 0.02, rough for the default --shift-threshold (0.001) and glossy for a threshold above it,
    // as the shift classifies its vertices.
    Scene box = sceneFile("cornell_box.gltf");
    ASSERT_GE(box.materials.size(), 2u);
    gpu::Material& wall = box.materials[1];
    wall.metallic = 1.0f;
    wall.roughness = 0.0f;
    EXPECT_EQ(gptSurfaces(analyzeScene(box, glm::vec3(0.0f))), GptSurfaces::Glossy);
    wall.roughness = 0.02f;
    EXPECT_EQ(gptSurfaces(analyzeScene(box, glm::vec3(0.0f), 0.001f)), GptSurfaces::Rough);
    EXPECT_EQ(gptSurfaces(analyzeScene(box, glm::vec3(0.0f), 0.03f)), GptSurfaces::Glossy);
}

TEST(GptReconstruction, NamesEachCase) {
    EXPECT_STREQ(toString(GptSurfaces::Rough), "rough");
    EXPECT_STREQ(toString(GptSurfaces::Glossy), "glossy vertices");
}

}  // namespace
}  // namespace gdpt
