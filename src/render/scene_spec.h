// scene_spec.h — what the scene kernels are compiled for: the scene's features (features.h)
// as specialisation constants, and the descriptor of a kernel that reads the scene buffers.
// It needs no BVH and no device memory, so a pass can start creating its pipelines
// (vk::PipelineCreation::Background) before SceneGpu builds and uploads the scene.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "gdpt_shared.h"
#include "render/features.h"
#include "scene/scene.h"
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
    float shiftThreshold = 0.001f;
    // Bits (1u << kSpec*) of scene features to compile in whatever the scene needs (the
    // generic kernel; kSpecMaxDepth: the 1024-bounce cap). For `gdpt bench-features`, which
    // measures what each specialisation saves; renders leave it 0.
    std::uint32_t genericFeatures = 0;
};

class SceneSpec {
public:
    SceneSpec(const Scene& scene, const SceneGpuOptions& options);

    // The features, with the emissive-triangle count of the light table SceneGpu uploads
    // (emitters with zero area or power are not lights).
    [[nodiscard]] const SceneFeatures& features() const { return features_; }
    [[nodiscard]] std::uint32_t width() const { return width_; }
    [[nodiscard]] std::uint32_t height() const { return height_; }
    // Specialisation constants for the scene features (ids from gdpt_shared.h).
    [[nodiscard]] std::vector<std::pair<std::uint32_t, std::uint32_t>> specConstants() const;
    // The bindings of the scene (kBindTriGeom..kBindSceneConst).
    [[nodiscard]] static std::vector<std::uint32_t> sceneBindings();
    // The scene bindings that the kernels read as texel buffers, with their view formats;
    // the geometry's (triangles and BVH, scene_geometry.glsl) alone for ray-query kernels.
    [[nodiscard]] static std::vector<std::pair<std::uint32_t, VkFormat>> geometryTexelBindings();
    [[nodiscard]] static std::vector<std::pair<std::uint32_t, VkFormat>> sceneTexelBindings();
    // Completes `base` (name + SPIR-V) into the descriptor of a kernel that reads the scene:
    // the scene bindings plus `extraBindings`, `pushBytes` of push constants, the scene's
    // feature specialisation constants and the workgroup size.
    [[nodiscard]] vk::KernelDesc kernelDesc(vk::KernelDesc base, WorkgroupSize wg,
                                            const std::vector<std::uint32_t>& extraBindings,
                                            std::uint32_t pushBytes = sizeof(gpu::FrameParams)) const;

private:
    SceneFeatures features_;
    std::uint32_t width_ = 0, height_ = 0;
    std::uint32_t maxDepthSpec_ = 1024;
    std::uint32_t genericFeatures_ = 0;
};

}  // namespace gdpt
