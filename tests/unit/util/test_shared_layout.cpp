// Host/shader layout, host side: sizes and offsets of every shared struct are
// pinned here. GLSL's scalar layout packs members at their natural 4-byte alignment, so the
// C++ offsets below must equal the sums of the member sizes (the GPU sentinel test
// tests/gpu/device_scene/test_layout_gpu.cpp checks the GLSL side).
#include <gtest/gtest.h>

#include <cstddef>

#include "gdpt_shared.h"

namespace gdpt::gpu {

static_assert(sizeof(vec3) == 12 && alignof(vec3) == 4, "glm vec3 must be 12 bytes");
static_assert(sizeof(TriangleGeom) == 48);
static_assert(offsetof(TriangleGeom, e1) == 16 && offsetof(TriangleGeom, e2) == 32);
static_assert(sizeof(TriangleShading) == 80);
static_assert(offsetof(TriangleShading, material) == 12 && offsetof(TriangleShading, area) == 28);
static_assert(offsetof(TriangleShading, uv0) == 48 && offsetof(TriangleShading, lightIndex) == 72);
static_assert(sizeof(BvhNode) == 64);
static_assert(offsetof(BvhNode, leftCount) == 28 && offsetof(BvhNode, rightCount) == 60);
static_assert(sizeof(BvhWideNode) == 64);
static_assert(offsetof(BvhWideNode, exponents) == 12 && offsetof(BvhWideNode, qMin) == 16);
static_assert(offsetof(BvhWideNode, qMax) == 32 && offsetof(BvhWideNode, child) == 48);
static_assert(sizeof(VisibleCounter) == 32 &&
              offsetof(VisibleCounter, groupsX) == 16);  // an indirect dispatch
static_assert(sizeof(Material) == 80);
static_assert(offsetof(Material, emissive) == 16 && offsetof(Material, specularColor) == 32);
static_assert(offsetof(Material, flags) == 60 && offsetof(Material, normalTex) == 76);
static_assert(sizeof(TextureInfo) == 16);
static_assert(sizeof(LightTriangle) == 16);
static_assert(sizeof(PunctualLight) == 48);
// The kernels read these tables as uniform texel buffers of 16-byte texels
// (shaders/lib/scene_geometry.glsl, scene_buffers.glsl), TriangleGeom and BvhWideNode
// included: each struct must be whole texels, and its texel count as the shaders assume.
static_assert(sizeof(TriangleGeom) == 16 * kTriangleGeomTexels);
static_assert(sizeof(BvhWideNode) == 16 * kBvhWideNodeTexels);
static_assert(sizeof(TriangleShading) == 16 * kTriangleShadingTexels);
static_assert(sizeof(Material) == 16 * kMaterialTexels);
static_assert(sizeof(PunctualLight) == 16 * kPunctualLightTexels);
static_assert(sizeof(SceneConstants) == 112);
static_assert(offsetof(SceneConstants, envRadiance) == 64 && offsetof(SceneConstants, pad) == 108);
static_assert(sizeof(FrameParams) == 32 && sizeof(FrameParams) <= 128);
static_assert(sizeof(PixelStats) == 32);
static_assert(sizeof(Counters) == 24);
static_assert(offsetof(Counters, shiftFailures) == 20);
static_assert(sizeof(TestRay) == 32);

TEST(SharedLayout, BindingsAreDistinct) {
    const uint bindings[] = {kBindTriGeom,  kBindTriShading, kBindBvh,        kBindMaterials,  kBindTexInfo,
                             kBindTexels,   kBindLightTris,  kBindPunctual,   kBindSceneConst, kBindAccum,
                             kBindCounters, kBindTestInput,  kBindTestOutput, kBindTestOutput2};
    for (std::size_t i = 0; i < std::size(bindings); ++i)
        for (std::size_t j = i + 1; j < std::size(bindings); ++j) EXPECT_NE(bindings[i], bindings[j]);
}

}  // namespace gdpt::gpu
