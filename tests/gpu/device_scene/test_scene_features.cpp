// test_scene_features.cpp — which triangles need their vertex normals (features.h): the rule
// that lets flat-shaded scenes compile the shading-normal interpolation out of the kernels
// (kSpecHasShadingNormals), and that it changes no image; the same for the specular lobe
// (kSpecHasSpecularLobe: a scene of Lambertian materials compiles the GGX code out), and for
// the register traversal stack (kSpecBvhRegisterStack, chosen from the tree SceneSpec builds
// for a small scene).
#include <gtest/gtest.h>
#include <stdlib.h>

#include "gpu_fixture.h"
#include "integrator/gpt_sampler.h"
#include "integrator/pt_sampler.h"
#include "integrator/render_options.h"
#include "render/device_scene/features.h"
#include "render/device_scene/scene_spec.h"
#include "same_bits.h"
#include "scene/gltf_loader.h"
#include "scene/procedural.h"
#include "util/error.h"

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
    EXPECT_TRUE(triangleHasShadingNormals(oneTriangle(z, -z, z), 0))
        << "mixed signs interpolate through zero";
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
    const SceneFeatures box =
        analyzeScene(loadGltf(GDPT_SOURCE_DIR "/scenes/cornell_box.gltf"), glm::vec3(0));
    const SceneFeatures glossy =
        analyzeScene(loadGltf(GDPT_SOURCE_DIR "/scenes/glossy_cornell.gltf"), glm::vec3(0));
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

// The stack the spec picks: the fewest register entries (8, 16) that hold the tree's
// maxStack, and the stack in memory for a tree that needs more or a scene too large to be
// built before the pipelines.
TEST(BvhRegisterStack, SpecPicksTheSmallestStackThatHoldsTheTree) {
    const auto registerStack = [](const SceneSpec& spec) {
        for (const auto& [id, value] : spec.specConstants())
            if (id == gpu::kSpecBvhRegisterStack) return value;
        ADD_FAILURE() << "no kSpecBvhRegisterStack constant";
        return 99u;
    };
    // The traversal's form (bvh_traverse.glsl): unit steps with the stack in memory on lavapipe
    // before Mesa 23 only.
    vk::DeviceInfo lavapipe22;
    lavapipe22.lavapipeBeforeMesa23 = true;
    const vk::DeviceInfo otherDevice;
    SceneGpuOptions o;
    for (const char* name : {"cornell_box", "indirect_gap", "glossy_cornell", "furnace"}) {
        const SceneSpec spec(loadGltf(std::string(GDPT_SOURCE_DIR "/scenes/") + name + ".gltf"), o);
        ASSERT_TRUE(spec.bvh()) << name;
        const std::uint32_t need = spec.bvh()->wide.maxStack;
        const std::uint32_t expected = need <= 8 ? 8u : need <= 16 ? 16u : 0u;
        EXPECT_EQ(registerStack(spec), expected) << name << " needs " << need;
        EXPECT_EQ(spec.bvhUnitSteps(lavapipe22), expected == 0u)
            << name << ": unit steps with the stack in memory";
        EXPECT_FALSE(spec.bvhUnitSteps(otherDevice)) << name;
    }
    const SceneSpec large(makeTriangleScene(10000, 1), o);
    EXPECT_FALSE(large.bvh()) << "built with the upload, after the pipelines";
    EXPECT_EQ(registerStack(large), 0u);
    EXPECT_TRUE(large.bvhUnitSteps(lavapipe22));
    EXPECT_FALSE(large.bvhUnitSteps(otherDevice)) << "node steps on drivers not measured to gain";
    // G-PT's split build (bundles) keeps node steps up to kBundleNodeStepsTriangles triangles.
    EXPECT_FALSE(large.bvhUnitSteps(lavapipe22, /*bundles=*/true));
    const std::uint32_t limit = static_cast<std::uint32_t>(kBundleNodeStepsTriangles);
    // (makeTriangleScene's count is a target, met within a few per cent.)
    const SceneSpec below(makeTriangleScene(limit - limit / 8, 1), o);
    ASSERT_LE(below.features().triangles, limit);
    const SceneSpec beyond(makeTriangleScene(limit + limit / 8, 1), o);
    ASSERT_GT(beyond.features().triangles, limit);
    EXPECT_FALSE(below.bvhUnitSteps(lavapipe22, true)) << below.features().triangles << " triangles";
    EXPECT_TRUE(beyond.bvhUnitSteps(lavapipe22, true)) << beyond.features().triangles << " triangles";
    EXPECT_TRUE(beyond.bvhUnitSteps(lavapipe22));
    EXPECT_FALSE(beyond.bvhUnitSteps(otherDevice, true));
    // GDPT_BVH_STEPS overrides the device's choice, units only with the stack in memory.
    ::setenv("GDPT_BVH_STEPS", "nodes", 1);
    EXPECT_FALSE(large.bvhUnitSteps(lavapipe22));
    EXPECT_FALSE(beyond.bvhUnitSteps(lavapipe22, true));
    ::setenv("GDPT_BVH_STEPS", "units", 1);
    EXPECT_TRUE(large.bvhUnitSteps(otherDevice));
    EXPECT_TRUE(large.bvhUnitSteps(lavapipe22, true));
    EXPECT_FALSE(SceneSpec(makeCornellBox(), o).bvhUnitSteps(otherDevice)) << "its stack is in registers";
    ::setenv("GDPT_BVH_STEPS", "fast", 1);
    EXPECT_THROW((void)large.bvhUnitSteps(lavapipe22), Error);
    ::unsetenv("GDPT_BVH_STEPS");
    o.genericFeatures = 1u << gpu::kSpecBvhRegisterStack;
    EXPECT_EQ(registerStack(SceneSpec(makeCornellBox(), o)), 0u) << "the generic kernel keeps it in memory";
    EXPECT_TRUE(SceneSpec(makeCornellBox(), o).bvhUnitSteps(lavapipe22));
}

class BvhRegisterStackSpecialisation : public test::GpuTest {};

// The same bits, PT and G-PT, with the stack in registers (node steps) and in memory (unit
// steps, bvh_traverse.glsl): cornell_box's tree takes the 8-entry stack, glossy_cornell's the
// 16-entry one.
TEST_F(BvhRegisterStackSpecialisation, SameImageEitherWay) {
    for (const char* name : {"cornell_box", "glossy_cornell"}) {
        const Scene scene = loadGltf(std::string(GDPT_SOURCE_DIR "/scenes/") + name + ".gltf");
        RenderOptions o = renderOptions(32, 32, 4, 3);
        const RenderResult pt = renderPt(ctx(), scene, o);
        const RenderResultGpt gpt = renderGpt(ctx(), scene, o);
        EXPECT_NE(pt.stats.bvhRegisterStack, 0u) << name;
        o.scene.genericFeatures = 1u << gpu::kSpecBvhRegisterStack;
        const RenderResult ptMemory = renderPt(ctx(), scene, o);
        EXPECT_EQ(ptMemory.stats.bvhRegisterStack, 0u);
        test::expectSameBits(pt.image, ptMemory.image, std::string(name) + " pt");
        test::expectSameGptBits(gpt, renderGpt(ctx(), scene, o), std::string(name) + " gpt");
    }
}

}  // namespace
}  // namespace gdpt
