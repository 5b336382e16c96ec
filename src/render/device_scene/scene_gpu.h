// scene_gpu.h — the scene on the device: BVH nodes, triangles (in BVH leaf order),
// materials, textures, light tables and per-scene constants, each in its own storage
// buffer, plus the specialisation constants derived from the scene's features.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "gdpt_shared.h"
#include "render/device_scene/features.h"
#include "render/device_scene/scene_spec.h"
#include "scene/scene.h"
#include "vk/buffer.h"
#include "vk/kernel.h"

namespace gdpt {

namespace vk {
class Context;
}  // namespace vk

struct BvhBuildInfo {
    double buildMs = 0.0;
    std::uint32_t nodes = 0;
    std::uint32_t maxDepth = 0;
};

class SceneGpu {
public:
    SceneGpu(const vk::Context& ctx, const Scene& scene, const SceneGpuOptions& options);
    // The same from a spec made of this scene and options already (saves recomputing it).
    SceneGpu(const vk::Context& ctx, const Scene& scene, const SceneGpuOptions& options, SceneSpec spec);

    // Binds the scene buffers (bindings kBindTriGeom..kBindSceneConst) to a kernel.
    void bindTo(vk::Kernel& kernel) const;
    // What the kernels are compiled for (SceneSpec), and its shorthands.
    [[nodiscard]] const SceneSpec& spec() const { return spec_; }
    [[nodiscard]] std::vector<std::pair<std::uint32_t, std::uint32_t>> specConstants() const {
        return spec_.specConstants();
    }
    [[nodiscard]] static std::vector<std::uint32_t> sceneBindings() { return SceneSpec::sceneBindings(); }
    [[nodiscard]] vk::KernelDesc kernelDesc(vk::KernelDesc base, WorkgroupSize wg,
                                            const std::vector<std::uint32_t>& extraBindings,
                                            std::uint32_t pushBytes = sizeof(gpu::FrameParams)) const {
        return spec_.kernelDesc(std::move(base), wg, extraBindings, pushBytes);
    }

    [[nodiscard]] const SceneFeatures& features() const { return spec_.features(); }
    [[nodiscard]] const gpu::SceneConstants& constants() const { return constants_; }
    [[nodiscard]] const BvhBuildInfo& bvhInfo() const { return bvhInfo_; }

private:
    SceneSpec spec_;
    gpu::SceneConstants constants_{};
    BvhBuildInfo bvhInfo_;
    vk::Buffer triGeom_, triShading_, bvh_, materials_, texInfo_, texels_, lightTris_, punctual_, sceneConst_;
};

// Builds the camera constants for an image of width × height (shared with tests).
void setCamera(gpu::SceneConstants& c, const Camera& camera, int width, int height);

}  // namespace gdpt
