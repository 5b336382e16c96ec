#include "render/device_scene/scene_spec.h"

#include <algorithm>

#include "util/env_choice.h"
#include "util/error.h"
#include "util/timer.h"

namespace gdpt {

SceneBvh buildSceneBvh(const Scene& scene) {
    Timer timer;
    SceneBvh out;
    out.binary = buildBvh(scene.positions, scene.triangles);
    out.wide = collapseToWide(out.binary.nodes);
    out.buildMs = timer.ms();
    return out;
}

void checkHasTriangles(const Scene& scene) {
    if (!scene.triangles.empty()) return;
    throw Error((scene.sourcePath.empty() ? std::string("generated scene") : scene.sourcePath) +
                ": the scene has no triangles to render (its nodes instance no mesh with triangles, or "
                "every triangle is degenerate; `gdpt info` lists what was not rendered)");
}

SceneSpec::SceneSpec(const Scene& scene, const SceneGpuOptions& options)
    : features_(analyzeScene(scene, options.envRadiance, options.shiftThreshold)),
      width_(static_cast<std::uint32_t>(std::max(options.width, 0))),
      height_(static_cast<std::uint32_t>(std::max(options.height, 0))),
      shiftThreshold_(options.shiftThreshold),
      // Kernels loop to min(spec max depth, scene.maxDepth); a small user depth is also
      // compiled in so that the loop bound is a constant the compiler can see.
      maxDepthSpec_(std::min<std::uint32_t>(options.maxDepth + 1, 1024)),
      genericFeatures_(options.genericFeatures) {
    // Before any kernel is created from this spec (SceneGpu checks the same).
    checkHasTriangles(scene);
    if (options.width < 1 || options.height < 1) throw Error("image size must be at least 1x1");
    std::uint32_t lights = 0;
    for (std::size_t t = 0; t < scene.triangles.size(); ++t)
        if (emitterPower(scene, t, triangleArea(scene, t)) > 0.0) ++lights;
    features_.emissiveTriangles = lights;
    features_.hasLightTris = lights > 0;
    if (scene.triangles.size() <= kSpecBvhTriangles)
        bvh_ = std::make_shared<const SceneBvh>(buildSceneBvh(scene));
}

std::uint32_t SceneSpec::bvhRegisterStack() const {
    if (!bvh_ || bvh_->wide.maxStack > gpu::kBvhRegisterStackMax) return 0;
    if (genericFeatures_ & (1u << gpu::kSpecBvhRegisterStack)) return 0;
    return bvh_->wide.maxStack <= 8 ? 8u : gpu::kBvhRegisterStackMax;
}

std::vector<std::uint32_t> SceneSpec::sceneBindings() {
    return {gpu::kBindTriGeom,   gpu::kBindTriShading, gpu::kBindBvh,
            gpu::kBindMaterials, gpu::kBindTexInfo,    gpu::kBindTexels,
            gpu::kBindLightTris, gpu::kBindPunctual,   gpu::kBindSceneConst};
}

std::vector<std::pair<std::uint32_t, VkFormat>> SceneSpec::geometryTexelBindings() {
    return {{gpu::kBindTriGeom, VK_FORMAT_R32G32B32A32_SFLOAT}, {gpu::kBindBvh, VK_FORMAT_R32G32B32A32_UINT}};
}

std::vector<std::pair<std::uint32_t, VkFormat>> SceneSpec::sceneTexelBindings() {
    // shaders/lib/scene_geometry.glsl and scene_buffers.glsl: the triangles as textureBuffer,
    // the image texels (two packed halves) as RG32UI, the other tables as RGBA32UI.
    constexpr VkFormat kU4 = VK_FORMAT_R32G32B32A32_UINT;
    std::vector<std::pair<std::uint32_t, VkFormat>> texel = geometryTexelBindings();
    texel.insert(texel.end(), {{gpu::kBindTriShading, kU4},
                               {gpu::kBindMaterials, kU4},
                               {gpu::kBindTexInfo, kU4},
                               {gpu::kBindTexels, VK_FORMAT_R32G32_UINT},
                               {gpu::kBindLightTris, kU4},
                               {gpu::kBindPunctual, kU4}});
    return texel;
}

std::vector<std::pair<std::uint32_t, std::uint32_t>> SceneSpec::specConstants() const {
    auto b = [](bool v) { return v ? 1u : 0u; };
    std::vector<std::pair<std::uint32_t, std::uint32_t>> spec = {
        {gpu::kSpecHasTextures, b(features_.hasTextures)},
        {gpu::kSpecHasPunctual, b(features_.hasPunctual)},
        {gpu::kSpecHasLightTris, b(features_.hasLightTris)},
        {gpu::kSpecHasEnv, b(features_.hasEnv)},
        {gpu::kSpecHasGlossy, b(features_.hasGlossy)},
        {gpu::kSpecHasAlphaMask, b(features_.hasAlphaMask)},
        {gpu::kSpecHasShadingNormals, b(features_.hasShadingNormals)},
        {gpu::kSpecHasSpecularLobe, b(features_.hasSpecularLayer)},
        {gpu::kSpecMaxDepth, maxDepthSpec_}};
    for (auto& [id, value] : spec)
        if (genericFeatures_ & (1u << id)) value = id == gpu::kSpecMaxDepth ? 1024u : 1u;
    // Not a feature bit: bvhRegisterStack() is already 0 (the stack in memory) for the
    // generic kernel.
    spec.push_back({gpu::kSpecBvhRegisterStack, bvhRegisterStack()});
    return spec;
}

bool SceneSpec::bvhUnitSteps(const vk::DeviceInfo& device, bool bundles) const {
    const bool bundleTree = bundles && features_.triangles <= kBundleNodeStepsTriangles;
    return envChoice("GDPT_BVH_STEPS", "nodes", "units", device.lavapipeBeforeMesa23 && !bundleTree) &&
           bvhRegisterStack() == 0;
}

vk::KernelDesc SceneSpec::kernelDesc(const TracingKernel& kernel, const vk::DeviceInfo& device,
                                     WorkgroupSize wg, const std::vector<std::uint32_t>& extraBindings,
                                     std::uint32_t pushBytes, bool bundles) const {
    vk::KernelDesc base = bvhUnitSteps(device, bundles) ? kernel.unitSteps : kernel.nodeSteps;
    base.bindings = sceneBindings();
    base.texelBindings = sceneTexelBindings();
    base.bindings.insert(base.bindings.end(), extraBindings.begin(), extraBindings.end());
    base.pushConstantBytes = pushBytes;
    base.specConstants = specConstants();
    base.specConstants.push_back({gpu::kSpecWorkgroupX, wg.x});
    base.specConstants.push_back({gpu::kSpecWorkgroupY, wg.y});
    // Folded before lavapipe 22.3, the register-stack constant's branches inside the traversal
    // loop (bvh_traverse.glsl) change the loop's shape, and 22.3 runs it slower (bench/RESULTS.md,
    // "Kernels specialised before the driver"): the driver specialises it.
    base.driverSpecConstants = {gpu::kSpecBvhRegisterStack};
    base.localSizeX = wg.x;
    base.localSizeY = wg.y;
    return base;
}

}  // namespace gdpt
