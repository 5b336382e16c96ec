// scene_spec.h — what the scene kernels are compiled for: the scene's features (features.h)
// as specialisation constants, and the descriptor of a kernel that reads the scene buffers.
// It needs no device memory, so a pass can start creating its pipelines
// (vk::PipelineCreation::Background) before SceneGpu uploads the scene. A small scene's BVH
// (at most kSpecBvhTriangles triangles: a few milliseconds at most) is built here, so
// that the kernels can be specialised to its tree (the register traversal stack); a larger
// one is built by SceneGpu while the pipelines are created.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <memory>
#include <utility>
#include <vector>

#include "bvh/builder.h"
#include "bvh/wide_bvh.h"
#include "gdpt_shared.h"
#include "render/device_scene/features.h"
#include "render/device_scene/light_table.h"
#include "scene/scene.h"
#include "vk/context.h"
#include "vk/kernel.h"

namespace gdpt {

// Compute workgroup size (a specialisation constant of every scene kernel).
struct WorkgroupSize {
    std::uint32_t x = 8;
    std::uint32_t y = 8;
};

struct SceneGpuOptions {
    int width = 256;
    int height = 256;
    std::uint32_t maxDepth = 64;  // bounces
    std::uint32_t rrDepth = 5;    // Russian roulette from this many segments on
    glm::vec3 envRadiance{0.0f};
    int camera = -1;  // index into Scene::cameras; -1 = first, or a framing default
    // G-PT: perceptual roughness at or below which a vertex is glossy (half-vector shift)
    // instead of reconnectable; the one place this setting is held.
    float shiftThreshold = 0.001f;
    // How next-event estimation picks among the emitters (light_table.h).
    LightSelection lightSelection = LightSelection::Probe;
    // Bits (1u << kSpec*) of scene features to compile in whatever the scene needs (the
    // generic kernel; kSpecMaxDepth: the 1024-bounce cap; kSpecBvhRegisterStack: the stack
    // in memory, which every tree fits). For `gdpt bench-features`, which
    // measures what each specialisation saves; renders leave it 0.
    std::uint32_t genericFeatures = 0;
    // No progress output while SceneGpu builds a large scene (kSceneProgressTriangles).
    bool quiet = false;
};

// The scene's BVH: the binary tree (its triangle order lays out every per-triangle table)
// and the four-wide tree the kernels traverse.
struct SceneBvh {
    Bvh binary;
    WideBvh wide;
    double buildMs = 0.0;  // both trees
};
SceneBvh buildSceneBvh(const Scene& scene);

// Scenes up to this many triangles have their BVH built by SceneSpec, before the pipelines
// (cbox's 36 take 0.08 ms, 5k triangles about 5 ms); larger trees need more than
// kBvhRegisterStackMax stack entries anyway (a 5k-triangle soup of spheres needs 20).
inline constexpr std::size_t kSpecBvhTriangles = 4096;

// G-PT's split build on lavapipe before Mesa 23 traverses trees of up to this many triangles in
// node steps, with its fan, bundles and beams, although their stack is in memory: 12-20 % less
// time per sample than the unit-step build on a 110k-triangle asset under a sky and on 50k- and
// 100k-triangle terrains, 21 % more on a 200k-triangle terrain and twice as much on 1M
// (bench/RESULTS.md, "Node steps for G-PT's bundles up to 2^17 triangles").
inline constexpr std::size_t kBundleNodeStepsTriangles = std::size_t{1} << 17;

// The two builds of a kernel that traces rays (shaders/lib/bvh_traverse.glsl): its traversal
// loop in node steps (the stack in registers or memory) and in unit steps (GDPT_BVH_UNIT_STEPS,
// the stack in memory). GDPT_TRACING_KERNEL(label, name) names the embedded SPIR-V of both
// (kSpv_<name>* and kSpv_<name>_units*).
struct TracingKernel {
    vk::KernelDesc nodeSteps;
    vk::KernelDesc unitSteps;
};
#define GDPT_TRACING_KERNEL(label, name)                                   \
    ::gdpt::TracingKernel {                                                \
        ::gdpt::vk::kernelDesc(label, GDPT_KERNEL_SPIRV(name)),            \
            ::gdpt::vk::kernelDesc(label, GDPT_KERNEL_SPIRV(name##_units)) \
    }

// Throws gdpt::Error naming the scene's file if it has no triangles to render.
void checkHasTriangles(const Scene& scene);

class SceneSpec {
public:
    SceneSpec(const Scene& scene, const SceneGpuOptions& options);

    // The features, with the emissive-triangle count of the light table SceneGpu uploads
    // (emitters with zero area or power are not lights).
    [[nodiscard]] const SceneFeatures& features() const { return features_; }
    [[nodiscard]] std::uint32_t width() const { return width_; }
    [[nodiscard]] std::uint32_t height() const { return height_; }
    // G-PT: perceptual roughness at or below which a vertex is glossy (half-vector shift).
    [[nodiscard]] float shiftThreshold() const { return shiftThreshold_; }
    // The BVH built with the spec (small scenes), or null: SceneGpu builds it.
    [[nodiscard]] const std::shared_ptr<const SceneBvh>& bvh() const { return bvh_; }
    // Entries of the register traversal stack the kernels use (kSpecBvhRegisterStack: 8 or
    // 16, the fewest that hold the tree's maxStack), or 0: the stack in memory (the tree is
    // not known yet, or needs more than kBvhRegisterStackMax; or the generic kernel).
    [[nodiscard]] std::uint32_t bvhRegisterStack() const;
    // Specialisation constants for the scene features (ids from gdpt_shared.h).
    [[nodiscard]] std::vector<std::pair<std::uint32_t, std::uint32_t>> specConstants() const;
    // The bindings of the scene (kBindTriGeom..kBindSceneConst).
    [[nodiscard]] static std::vector<std::uint32_t> sceneBindings();
    // The scene bindings that the kernels read as texel buffers, with their view formats;
    // the geometry's (triangles and BVH, scene_geometry.glsl) alone for ray-query kernels.
    [[nodiscard]] static std::vector<std::pair<std::uint32_t, VkFormat>> geometryTexelBindings();
    [[nodiscard]] static std::vector<std::pair<std::uint32_t, VkFormat>> sceneTexelBindings();
    // Whether the kernels on `device` traverse the BVH in unit steps or in node steps
    // (bvh_traverse.glsl): unit steps where the stack is in memory (a tree that the register
    // stack does not hold, or not known before the pipelines) on lavapipe before Mesa 23, the
    // driver they were measured to pay on (bench/RESULTS.md, "Unit steps for large trees"), and
    // node steps everywhere else. `bundles`: the kernel is G-PT's split build, whose node-step
    // form traces the camera fan, the ray bundles and the occlusion beams (gpt_trace.glsl,
    // GDPT_GPT_BEAMS) and whose unit-step form does not; it keeps node steps up to
    // kBundleNodeStepsTriangles triangles. GDPT_BVH_STEPS=nodes|units in the environment
    // overrides the device's choice (units still only with the stack in memory); throws for
    // another value.
    [[nodiscard]] bool bvhUnitSteps(const vk::DeviceInfo& device, bool bundles = false) const;
    // Completes the build of `kernel` that the scene's tree takes on `device` (bvhUnitSteps)
    // into the descriptor of a kernel that reads the scene: the scene bindings plus
    // `extraBindings`, `pushBytes` of push constants, the scene's feature specialisation
    // constants and the workgroup size.
    [[nodiscard]] vk::KernelDesc kernelDesc(const TracingKernel& kernel, const vk::DeviceInfo& device,
                                            WorkgroupSize wg, const std::vector<std::uint32_t>& extraBindings,
                                            std::uint32_t pushBytes = sizeof(gpu::FrameParams),
                                            bool bundles = false) const;

private:
    SceneFeatures features_;
    std::uint32_t width_ = 0, height_ = 0;
    float shiftThreshold_ = 0.001f;
    std::uint32_t maxDepthSpec_ = 1024;
    std::uint32_t genericFeatures_ = 0;
    std::shared_ptr<const SceneBvh> bvh_;
};

}  // namespace gdpt
