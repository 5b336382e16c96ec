// scene_gpu.h — the scene on the device: BVH nodes, triangles (in BVH leaf order),
// materials, textures, light tables and per-scene constants, each in its own storage
// buffer, plus the specialisation constants derived from the scene's features.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "gdpt_shared.h"
#include "render/device_scene/features.h"
#include "render/device_scene/light_table.h"
#include "render/device_scene/scene_spec.h"
#include "scene/gltf_loader.h"
#include "scene/scene.h"
#include "util/progress.h"
#include "vk/buffer.h"
#include "vk/kernel.h"

namespace gdpt {

namespace vk {
class Context;
struct DeviceInfo;
}  // namespace vk

// Scenes of at least this many triangles show progress while SceneGpu builds them (the BVH
// of tens of millions of triangles takes minutes on a CPU device).
inline constexpr std::size_t kSceneProgressTriangles = 1'000'000;

// The most triangles `device` can hold: every per-triangle table is one texel buffer of at
// most maxTexelBufferElements texels, and the largest, TriangleShading, takes
// kTriangleShadingTexels texels per triangle. (The BVH, smaller per triangle, and the other
// tables are checked as they are uploaded.)
[[nodiscard]] std::uint64_t maxDeviceTriangles(const vk::DeviceInfo& device);

// Throws gdpt::Error naming `source` (the scene file) and the limit if `triangles` exceed
// maxDeviceTriangles(device).
void checkTrianglesFit(const vk::DeviceInfo& device, std::uint64_t triangles, const std::string& source);

// Host memory a render takes per triangle beyond the loaded scene (SceneEstimate::bytes): the
// BVH build's references and nodes, the four-wide nodes and the triangle tables (on a CPU device
// its memory is the host's). Measured 2026-12-04: a 5M-triangle textured scene peaked at 1.26 GB
// against 0.44 GB for loading it, 163 bytes per triangle; rounded up.
inline constexpr std::uint64_t kRenderBytesPerTriangle = 200;

// Throws gdpt::Error if the loaded scene plus kRenderBytesPerTriangle per triangle exceed the
// machine's memory (physicalMemory), naming the most triangles a scene like it could have.
void checkRenderMemory(const SceneEstimate& estimate);

// Load options for a scene that is to be rendered on the device `device` selects
// (vk::ContextOptions::device): the loader refuses a scene whose estimated triangles exceed
// maxDeviceTriangles, or whose render would not fit the machine's memory (checkRenderMemory),
// before it reads the scene's buffers, and shows progress unless quiet.
[[nodiscard]] LoadOptions deviceLoadOptions(const std::string& device, bool quiet);

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
    // Two frames of one animation at once, for kernels compiled with GDPT_TWO_FRAMES
    // (scene_geometry.glsl; tgpt_reconnect.comp): every per-triangle and light table holds frame
    // a's records, then frame b's, in one leaf order, under frame a's tree with its boxes grown to
    // hold frame b's triangles too (growBvhBoxes); the scene constants are [a, b] (constants()
    // is a's). The frames must have the same triangles, emitters and punctual lights (else
    // gdpt::Error). The kernels keep their traversal stack in memory.
    SceneGpu(const vk::Context& ctx, const Scene& a, const Scene& b, const SceneGpuOptions& options);

    // Binds the scene buffers (bindings kBindTriGeom..kBindSceneConst) to a kernel.
    void bindTo(vk::Kernel& kernel) const;
    // What the kernels are compiled for (SceneSpec), and its shorthands.
    [[nodiscard]] const SceneSpec& spec() const { return spec_; }
    [[nodiscard]] std::vector<std::pair<std::uint32_t, std::uint32_t>> specConstants() const {
        return spec_.specConstants();
    }
    [[nodiscard]] static std::vector<std::uint32_t> sceneBindings() { return SceneSpec::sceneBindings(); }
    [[nodiscard]] vk::KernelDesc kernelDesc(const TracingKernel& kernel, const vk::DeviceInfo& device,
                                            WorkgroupSize wg, const std::vector<std::uint32_t>& extraBindings,
                                            std::uint32_t pushBytes = sizeof(gpu::FrameParams)) const {
        return spec_.kernelDesc(kernel, device, wg, extraBindings, pushBytes);
    }

    [[nodiscard]] const SceneFeatures& features() const { return spec_.features(); }
    [[nodiscard]] const gpu::SceneConstants& constants() const { return constants_; }
    [[nodiscard]] const BvhBuildInfo& bvhInfo() const { return bvhInfo_; }
    // Bytes of the scene's buffers on the device (BVH nodes, triangle tables, textures, ...).
    [[nodiscard]] std::uint64_t deviceBytes() const;
    // Emissive material -> the probability that next-event estimation picks it (light_table.h),
    // and whether the light probe set them (`--light-selection probe` with two emitters or more).
    [[nodiscard]] const std::map<std::uint32_t, double>& lightShares() const { return lightShares_; }
    [[nodiscard]] bool lightProbed() const { return lightProbed_; }

private:
    // Builds the tables of `frames` (one, or the two of a frame pair) over `built`.
    void upload(const vk::Context& ctx, const std::vector<const Scene*>& frames,
                const SceneGpuOptions& options, const SceneBvh& built, std::optional<Progress>& progress);

    SceneSpec spec_;
    gpu::SceneConstants constants_{};
    BvhBuildInfo bvhInfo_;
    std::map<std::uint32_t, double> lightShares_;
    bool lightProbed_ = false;
    vk::Buffer triGeom_, triShading_, bvh_, materials_, texInfo_, texels_, lightTris_, punctual_, sceneConst_;
};

// Half the diagonal of the scene's bounds (SceneConstants::sceneRadius, the scale of the
// rays' origin offsets).
float sceneRadius(const Scene& scene);

// The table next-event estimation picks lights from for this scene, BVH (its leaf order) and
// options (light selection; the camera and image size, which the probe rule looks through).
LightTable sceneLightTable(const Scene& scene, const SceneBvh& bvh, const SceneGpuOptions& options);

// Builds the camera constants for an image of width × height (shared with tests).
void setCamera(gpu::SceneConstants& c, const Camera& camera, int width, int height);

// The camera a render of `scene` uses: Scene::cameras[index] (SceneGpuOptions::camera), or for
// -1 the first, or a framing default if the scene has none. Throws gdpt::Error if the index is
// out of range.
[[nodiscard]] Camera renderCamera(const Scene& scene, int index);

}  // namespace gdpt
