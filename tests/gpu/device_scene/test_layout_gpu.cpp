// Host/shader layout, device side (the host side is tests/unit/util/test_shared_layout.cpp):
// a kernel writes a sentinel into every field of
// the shared structs and the host reads them back through the C++ definitions. A field
// whose offset differs between C++ and GLSL reads the wrong sentinel.
#include <gtest/gtest.h>

#include <cstring>
#include <glm/gtc/packing.hpp>
#include <vector>

#include "gdpt_shared.h"
#include "gpu_fixture.h"
#include "layout_probe.spv.h"
#include "render/device_scene/scene_spec.h"
#include "table_probe.spv.h"
#include "util/error.h"
#include "vk/buffer.h"
#include "vk/commands.h"
#include "vk/kernel.h"

namespace gdpt {
namespace {

struct ProbeA {
    gpu::BvhNode node;
    gpu::TriangleShading shading;
    gpu::Material material;
};
struct ProbeB {
    gpu::SceneConstants sc;
    gpu::PixelStats stats;
    gpu::PunctualLight light;
    gpu::BvhWideNode wide;
};

class LayoutGpu : public test::GpuTest {};

TEST_F(LayoutGpu, EveryFieldMatchesBetweenCppAndGlsl) {
    vk::KernelDesc desc = vk::kernelDesc("layout_probe", GDPT_KERNEL_SPIRV(layout_probe));
    desc.bindings = {gpu::kBindTestInput, gpu::kBindTestOutput};
    vk::Kernel kernel(ctx(), desc);
    vk::Buffer a(ctx(), sizeof(ProbeA), "probe A");
    vk::Buffer b(ctx(), sizeof(ProbeB), "probe B");
    a.zero();
    b.zero();
    kernel.bind(gpu::kBindTestInput, a);
    kernel.bind(gpu::kBindTestOutput, b);
    dispatchOnce(kernel, "layout probe");
    ProbeA pa{};
    ProbeB pb{};
    a.download(&pa, sizeof pa);
    b.download(&pb, sizeof pb);

    EXPECT_EQ(pa.node.lmin, glm::vec3(1, 2, 3));
    EXPECT_EQ(pa.node.left, 4u);
    EXPECT_EQ(pa.node.lmax, glm::vec3(5, 6, 7));
    EXPECT_EQ(pa.node.leftCount, 8u);
    EXPECT_EQ(pa.node.rmin, glm::vec3(9, 10, 11));
    EXPECT_EQ(pa.node.right, 12u);
    EXPECT_EQ(pa.node.rmax, glm::vec3(13, 14, 15));
    EXPECT_EQ(pa.node.rightCount, 16u);

    EXPECT_EQ(pb.wide.origin, glm::vec3(1, 2, 3));
    EXPECT_EQ(pb.wide.exponents, 4u);
    EXPECT_EQ(pb.wide.qMin, glm::uvec4(5, 6, 7, 8));
    EXPECT_EQ(pb.wide.qMax, glm::uvec4(9, 10, 11, 12));
    EXPECT_EQ(pb.wide.child, glm::uvec4(13, 14, 15, 16));

    EXPECT_EQ(pa.shading.n0, glm::vec3(1, 2, 3));
    EXPECT_EQ(pa.shading.material, 4u);
    EXPECT_EQ(pa.shading.n1, glm::vec3(5, 6, 7));
    EXPECT_EQ(pa.shading.area, 8.0f);
    EXPECT_EQ(pa.shading.n2, glm::vec3(9, 10, 11));
    EXPECT_EQ(pa.shading.flags, 12u);
    EXPECT_EQ(pa.shading.uv0, glm::vec2(13, 14));
    EXPECT_EQ(pa.shading.uv1, glm::vec2(15, 16));
    EXPECT_EQ(pa.shading.uv2, glm::vec2(17, 18));
    EXPECT_EQ(pa.shading.lightIndex, 19u);
    EXPECT_EQ(pa.shading.pad3, 20u);

    EXPECT_EQ(pa.material.baseColor, glm::vec4(1, 2, 3, 4));
    EXPECT_EQ(pa.material.emissive, glm::vec3(5, 6, 7));
    EXPECT_EQ(pa.material.metallic, 8.0f);
    EXPECT_EQ(pa.material.specularColor, glm::vec3(9, 10, 11));
    EXPECT_EQ(pa.material.roughness, 12.0f);
    EXPECT_EQ(pa.material.specular, 13.0f);
    EXPECT_EQ(pa.material.ior, 14.0f);
    EXPECT_EQ(pa.material.alphaCutoff, 15.0f);
    EXPECT_EQ(pa.material.flags, 16u);
    EXPECT_EQ(pa.material.baseColorTex, 17);
    EXPECT_EQ(pa.material.metallicRoughnessTex, 18);
    EXPECT_EQ(pa.material.emissiveTex, 19);
    EXPECT_EQ(pa.material.normalTex, 20);

    EXPECT_EQ(pb.sc.camPosition, glm::vec3(1, 2, 3));
    EXPECT_EQ(pb.sc.tanHalfFovY, 4.0f);
    EXPECT_EQ(pb.sc.camRight, glm::vec3(5, 6, 7));
    EXPECT_EQ(pb.sc.aspect, 8.0f);
    EXPECT_EQ(pb.sc.camUp, glm::vec3(9, 10, 11));
    EXPECT_EQ(pb.sc.width, 12u);
    EXPECT_EQ(pb.sc.camForward, glm::vec3(13, 14, 15));
    EXPECT_EQ(pb.sc.height, 16u);
    EXPECT_EQ(pb.sc.envRadiance, glm::vec3(17, 18, 19));
    EXPECT_EQ(pb.sc.numLightTriangles, 20u);
    EXPECT_EQ(pb.sc.numPunctualLights, 21u);
    EXPECT_EQ(pb.sc.lightTrianglePower, 22.0f);
    EXPECT_EQ(pb.sc.punctualPower, 23.0f);
    EXPECT_EQ(pb.sc.maxDepth, 24u);
    EXPECT_EQ(pb.sc.sceneRadius, 25.0f);
    EXPECT_EQ(pb.sc.rrDepth, 26u);
    EXPECT_EQ(pb.sc.numTriangles, 27u);
    EXPECT_EQ(pb.sc.pad, 28u);

    EXPECT_EQ(pb.stats.mean, glm::vec3(1, 2, 3));
    EXPECT_EQ(pb.stats.count, 4u);
    EXPECT_EQ(pb.stats.m2, glm::vec3(5, 6, 7));
    EXPECT_EQ(pb.stats.pad, 8u);

    EXPECT_EQ(pb.light.position, glm::vec3(1, 2, 3));
    EXPECT_EQ(pb.light.type, 4u);
    EXPECT_EQ(pb.light.intensity, glm::vec3(5, 6, 7));
    EXPECT_EQ(pb.light.cosInner, 8.0f);
    EXPECT_EQ(pb.light.direction, glm::vec3(9, 10, 11));
    EXPECT_EQ(pb.light.cosOuter, 12.0f);
}

// The scene tables are read as texel buffers through accessors (shaders/lib/
// scene_geometry.glsl, scene_buffers.glsl) that rebuild each struct from its texels. Each
// table holds two elements whose 32-bit words are all distinct (element 1 is the one read,
// so the accessors' index arithmetic is checked too); what the kernel writes back through a
// scalar block (pinned above) must be what was uploaded, field for field.
struct TableProbe {
    gpu::TriangleGeom geom;
    gpu::BvhWideNode node;
    gpu::TriangleShading shading;
    gpu::Material material;
    gpu::TextureInfo tex;
    gpu::LightTriangle light;
    gpu::PunctualLight punctual;
    glm::vec4 texel;
    glm::vec3 unitNormal;
};

// Two elements of T whose words are distinct floats (exact small integers, so any word read
// as a float, uint or int survives unchanged).
template <typename T>
std::vector<T> sentinelTable(std::uint32_t table) {
    static_assert(sizeof(T) % 4 == 0);
    std::vector<T> v(2);
    std::vector<float> words(2 * sizeof(T) / 4);
    for (std::size_t k = 0; k < words.size(); ++k) words[k] = static_cast<float>(1000 * table + k + 1);
    std::memcpy(v.data(), words.data(), sizeof(T) * 2);
    return v;
}

template <typename T>
vk::Buffer tableBuffer(const vk::Context& ctx, const std::vector<T>& data, const char* name) {
    vk::Buffer b(ctx, data.size() * sizeof(T), name);
    b.uploadVector(data);
    return b;
}

TEST_F(LayoutGpu, TexelAccessorsReturnTheUploadedStructs) {
    const auto geom = sentinelTable<gpu::TriangleGeom>(1);
    const auto nodes = sentinelTable<gpu::BvhWideNode>(2);
    const auto shading = sentinelTable<gpu::TriangleShading>(3);
    const auto materials = sentinelTable<gpu::Material>(4);
    const auto texInfo = sentinelTable<gpu::TextureInfo>(5);
    const auto lights = sentinelTable<gpu::LightTriangle>(6);
    const auto punctual = sentinelTable<gpu::PunctualLight>(7);
    const std::vector<glm::uvec2> texels = {
        {glm::packHalf2x16({0.5f, 1.5f}), glm::packHalf2x16({2.5f, 3.5f})},
        {glm::packHalf2x16({-4.0f, 0.25f}), glm::packHalf2x16({8.0f, 1024.0f})}};

    vk::KernelDesc desc = vk::kernelDesc("table_probe", GDPT_KERNEL_SPIRV(table_probe));
    desc.bindings = SceneSpec::sceneBindings();
    desc.bindings.push_back(gpu::kBindTestOutput);
    desc.texelBindings = SceneSpec::sceneTexelBindings();
    vk::Kernel kernel(ctx(), desc);
    vk::Buffer bufs[] = {tableBuffer(ctx(), geom, "geom"),        tableBuffer(ctx(), nodes, "nodes"),
                         tableBuffer(ctx(), shading, "shading"),  tableBuffer(ctx(), materials, "materials"),
                         tableBuffer(ctx(), texInfo, "tex info"), tableBuffer(ctx(), texels, "texels"),
                         tableBuffer(ctx(), lights, "lights"),    tableBuffer(ctx(), punctual, "punctual")};
    const std::uint32_t bindings[] = {gpu::kBindTriGeom,   gpu::kBindBvh,     gpu::kBindTriShading,
                                      gpu::kBindMaterials, gpu::kBindTexInfo, gpu::kBindTexels,
                                      gpu::kBindLightTris, gpu::kBindPunctual};
    for (std::size_t i = 0; i < std::size(bindings); ++i) kernel.bind(bindings[i], bufs[i]);
    vk::Buffer sceneConst(ctx(), sizeof(gpu::SceneConstants), "scene constants");
    sceneConst.zero();
    kernel.bind(gpu::kBindSceneConst, sceneConst);
    vk::Buffer out(ctx(), sizeof(TableProbe), "probe");
    out.zero();
    kernel.bind(gpu::kBindTestOutput, out);
    dispatchOnce(kernel, "table probe");
    TableProbe p{};
    out.download(&p, sizeof p);

    // TriangleGeom's pads are not read (the accessor sets them to zero).
    EXPECT_EQ(p.geom.v0, geom[1].v0);
    EXPECT_EQ(p.geom.e1, geom[1].e1);
    EXPECT_EQ(p.geom.e2, geom[1].e2);
    EXPECT_EQ(0, std::memcmp(&p.node, &nodes[1], sizeof p.node));
    EXPECT_EQ(0, std::memcmp(&p.shading, &shading[1], sizeof p.shading));
    EXPECT_EQ(0, std::memcmp(&p.material, &materials[1], sizeof p.material));
    EXPECT_EQ(0, std::memcmp(&p.tex, &texInfo[1], sizeof p.tex));
    EXPECT_EQ(0, std::memcmp(&p.light, &lights[1], sizeof p.light));
    EXPECT_EQ(0, std::memcmp(&p.punctual, &punctual[1], sizeof p.punctual));
    EXPECT_EQ(p.texel, glm::vec4(-4.0f, 0.25f, 8.0f, 1024.0f));
    const glm::vec3 n = glm::normalize(glm::cross(geom[1].e1, geom[1].e2));
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(p.unitNormal[c], n[c], 1e-6f);
}

// A scene table beyond the device's texel-buffer limit is refused with the limit named.
TEST_F(LayoutGpu, TexelTableBeyondTheLimitIsRefused) {
    const std::uint64_t limit = ctx().info().maxTexelBufferElements;
    EXPECT_NO_THROW(ctx().checkTexelBufferSize(limit, "triangle geometry"));
    try {
        ctx().checkTexelBufferSize(limit + 1, "triangle geometry");
        FAIL() << "no error";
    } catch (const Error& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("maxTexelBufferElements"), std::string::npos) << what;
        EXPECT_NE(what.find("triangle geometry"), std::string::npos) << what;
    }
}

}  // namespace
}  // namespace gdpt
