// scene_gpu.h — the scene on the device: BVH nodes, triangles (in BVH leaf order),
// materials, textures, light tables and per-scene constants, each in its own storage
// buffer, plus the specialisation constants derived from the scene's features.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "gdpt_shared.h"
#include "render/features.h"
#include "scene/scene.h"
#include "vk/buffer.h"
#include "vk/kernel.h"

namespace gdpt {

namespace vk {
class Context;
}  // namespace vk

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

struct BvhBuildInfo {
    double buildMs = 0.0;
    std::uint32_t nodes = 0;
    std::uint32_t maxDepth = 0;
};

class SceneGpu {
public:
    SceneGpu(const vk::Context& ctx, const Scene& scene, const SceneGpuOptions& options);

    // Binds the scene buffers (bindings kBindTriGeom..kBindSceneConst) to a kernel.
    void bindTo(vk::Kernel& kernel) const;
    // Specialisation constants for the scene features (ids from gdpt_shared.h).
    [[nodiscard]] std::vector<std::pair<std::uint32_t, std::uint32_t>> specConstants() const;
    [[nodiscard]] static std::vector<std::uint32_t> sceneBindings();
    // Completes `base` (name + SPIR-V) into the descriptor of a kernel that reads this scene:
    // the scene bindings plus `extraBindings`, `pushBytes` of push constants, the scene's
    // feature specialisation constants and the workgroup size.
    [[nodiscard]] vk::KernelDesc kernelDesc(vk::KernelDesc base, WorkgroupSize wg,
                                            const std::vector<std::uint32_t>& extraBindings,
                                            std::uint32_t pushBytes = sizeof(gpu::FrameParams)) const;

    [[nodiscard]] const SceneFeatures& features() const { return features_; }
    [[nodiscard]] const gpu::SceneConstants& constants() const { return constants_; }
    [[nodiscard]] const BvhBuildInfo& bvhInfo() const { return bvhInfo_; }
    [[nodiscard]] std::uint64_t deviceBytes() const;

private:
    SceneFeatures features_;
    gpu::SceneConstants constants_{};
    BvhBuildInfo bvhInfo_;
    std::uint32_t maxDepthSpec_ = 1024;
    std::uint32_t genericFeatures_ = 0;
    vk::Buffer triGeom_, triShading_, bvh_, materials_, texInfo_, texels_, lightTris_, punctual_,
        sceneConst_;
};

// Builds the camera constants for an image of width × height (shared with tests).
void setCamera(gpu::SceneConstants& c, const Camera& camera, int width, int height);

}  // namespace gdpt
