// test_scene_features.cpp — which triangles need their vertex normals (features.h): the rule
// that lets flat-shaded scenes compile the shading-normal interpolation out of the kernels
// (kSpecHasShadingNormals), and that it changes no image; the same for the specular lobe
// (kSpecHasSpecularLobe: a scene of Lambertian materials compiles the GGX code out).
#include <gtest/gtest.h>

#include "gpu_fixture.h"
#include "same_bits.h"
#include "render/features.h"
#include "render/gpt_renderer.h"
#include "render/renderer.h"
#include "scene/gltf_loader.h"
#include "scene/procedural.h"

namespace gdpt {
namespace {

// One triangle in the z = 0 plane (face normal +z, counter-clockwise) with the given normals.
Scene oneTriangle(glm::vec3 n0, glm::vec3 n1, glm::vec3 n2) {
    Scene s;
    s.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    s.normals = {n0, n1, n2};
    s.triangles = {{0, 1, 2}};
    s.triangleMaterial = {0};
    return s;
}

TEST(SceneFeatures, FlatNormalsOfEitherSignAreNotShadingNormals) {
    const glm::vec3 z(0, 0, 1);
    EXPECT_FALSE(triangleHasShadingNormals(oneTriangle(z, z, z), 0));
    EXPECT_FALSE(triangleHasShadingNormals(oneTriangle(-z, -z, -z), 0));
    EXPECT_FALSE(triangleHasShadingNormals(oneTriangle(2.0f * z, z, 0.5f * z), 0)) << "lengths do not matter";
    const glm::vec3 tilted = glm::normalize(glm::vec3(0.01f, 0, 1));
    EXPECT_TRUE(triangleHasShadingNormals(oneTriangle(z, z, tilted), 0));
    EXPECT_TRUE(triangleHasShadingNormals(oneTriangle(z, -z, z), 0)) << "mixed signs interpolate through zero";
    EXPECT_TRUE(triangleHasShadingNormals(oneTriangle(z, glm::vec3(0), z), 0)) << "a zero normal";
    Scene none = oneTriangle(z, z, z);
    none.normals.clear();
    EXPECT_FALSE(triangleHasShadingNormals(none, 0));
    EXPECT_FALSE(analyzeScene(oneTriangle(z, z, z), glm::vec3(0)).hasShadingNormals);
    EXPECT_TRUE(analyzeScene(oneTriangle(z, z, tilted), glm::vec3(0)).hasShadingNormals);
}

// The repository's scenes: the box is flat-shaded and Lambertian, the glossy spheres have
// shading normals and a metal/dielectric lobe.
TEST(SceneFeatures, ShippedScenesClassifyTheirNormalsAndSpecularLobes) {
    const SceneFeatures box = analyzeScene(loadGltf(GDPT_SOURCE_DIR "/scenes/cornell_box.gltf"), glm::vec3(0));
    const SceneFeatures glossy = analyzeScene(loadGltf(GDPT_SOURCE_DIR "/scenes/glossy_cornell.gltf"), glm::vec3(0));
    EXPECT_FALSE(box.hasShadingNormals);
    EXPECT_TRUE(glossy.hasShadingNormals);
    EXPECT_FALSE(box.hasSpecularLayer);
    EXPECT_TRUE(glossy.hasSpecularLayer);
}

class ShadingNormalSpecialisation : public test::GpuTest {};

// A flat-shaded scene renders the same bits with the interpolation compiled out
// (specialised) and with it kept behind the per-triangle flag (generic).
TEST_F(ShadingNormalSpecialisation, FlatSceneSameImageEitherWay) {
    const Scene scene = loadGltf(GDPT_SOURCE_DIR "/scenes/cornell_box.gltf");
    RenderOptions o = renderOptions(32, 32, 4, 3);
    const Image specialised = renderPt(ctx(), scene, o).image;
    o.scene.genericFeatures = 1u << gpu::kSpecHasShadingNormals;
    test::expectSameBits(specialised, renderPt(ctx(), scene, o).image, "pt");
}

class SpecularLobeSpecialisation : public test::GpuTest {};

// A Lambertian scene renders the same bits, PT and G-PT (every buffer the sampler writes),
// with the GGX lobe compiled out (specialised) and compiled in (generic: it is then evaluated
// with metallic = specular = 0).
TEST_F(SpecularLobeSpecialisation, LambertianSceneSameImageEitherWay) {
    const Scene scene = loadGltf(GDPT_SOURCE_DIR "/scenes/cornell_box.gltf");
    ASSERT_FALSE(analyzeScene(scene, glm::vec3(0)).hasSpecularLayer);
    RenderOptions o = renderOptions(32, 32, 4, 3);
    const Image pt = renderPt(ctx(), scene, o).image;
    const RenderResultGpt gpt = renderGpt(ctx(), scene, o);
    o.scene.genericFeatures = 1u << gpu::kSpecHasSpecularLobe;
    test::expectSameBits(pt, renderPt(ctx(), scene, o).image, "pt");
    test::expectSameGptBits(gpt, renderGpt(ctx(), scene, o), "gpt");
}

}  // namespace
}  // namespace gdpt
