// Host/shader layout, check 2 of GUIDE §2: a kernel writes a sentinel into every field of
// the shared structs and the host reads them back through the C++ definitions. A field
// whose offset differs between C++ and GLSL reads the wrong sentinel.
#include <gtest/gtest.h>

#include "gdpt_shared.h"
#include "gpu_fixture.h"
#include "layout_probe.spv.h"
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
    vk::KernelDesc desc = vk::kernelDesc("layout_probe", kSpv_layout_probe);
    desc.bindings = {gpu::kBindTestInput, gpu::kBindTestOutput};
    vk::Kernel kernel(ctx(), desc);
    vk::Buffer a(ctx(), sizeof(ProbeA), "probe A");
    vk::Buffer b(ctx(), sizeof(ProbeB), "probe B");
    a.zero();
    b.zero();
    kernel.bind(gpu::kBindTestInput, a);
    kernel.bind(gpu::kBindTestOutput, b);
    vk::CommandStream cmd(ctx(), "layout probe");
    kernel.dispatch(cmd.begin(), 1, 1, 1);
    vk::computeBarrier(cmd.cmd());
    cmd.submitAndWait();
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

}  // namespace
}  // namespace gdpt
