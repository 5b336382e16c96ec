#include "render/device_scene/scene_gpu.h"

#include <algorithm>
#include <cmath>
#include <glm/gtc/packing.hpp>
#include <optional>

#include "bvh/builder.h"
#include "bvh/wide_bvh.h"
#include "lib/common.glsl"
#include "render/device_scene/light_probe.h"
#include "render/device_scene/light_table.h"
#include "scene/gltf_loader.h"
#include "util/error.h"
#include "util/memory.h"
#include "util/parallel.h"
#include "util/progress.h"
#include "util/timer.h"
#include "vk/context.h"
#include "vk/kernel.h"

namespace gdpt {
namespace {

constexpr float kPi = 3.14159265358979f;

// A scene binding's size checked against the limit of how the kernels read it: a texel buffer
// of its SceneSpec::sceneTexelBindings format, else a storage buffer.
void checkSceneBuffer(const vk::Context& ctx, std::uint64_t bytes, const std::string& name,
                      std::uint32_t binding) {
    const VkFormat format = vk::texelFormat(SceneSpec::sceneTexelBindings(), binding);
    if (format != VK_FORMAT_UNDEFINED)
        ctx.checkTexelBufferSize(bytes / vk::texelBytes(format), name);
    else
        ctx.checkStorageBufferSize(bytes, name);
}

// The buffer of scene binding `binding` holding `data`.
template <typename T>
vk::Buffer makeBuffer(const vk::Context& ctx, const std::vector<T>& data, const std::string& name,
                      std::uint32_t binding) {
    const std::uint64_t bytes = data.size() * sizeof(T);
    checkSceneBuffer(ctx, bytes, name, binding);
    vk::Buffer b(ctx, bytes, name);
    b.uploadVector(data);
    return b;
}

// Records per leaf position handed to the threads in ranges of this many.
constexpr std::size_t kTableGrain = std::size_t{1} << 16;

// The buffer of scene binding `binding` holding `count` records that fill(out, begin, end)
// writes for leaf positions [begin, end), on every thread: in place when the buffer is mapped
// (a CPU device: no second copy of a table of hundreds of MiB), else through a vector.
template <typename T, typename Fill>
vk::Buffer makeFilledBuffer(const vk::Context& ctx, std::size_t count, const std::string& name,
                            std::uint32_t binding, const Fill& fill) {
    checkSceneBuffer(ctx, std::uint64_t{count} * sizeof(T), name, binding);
    vk::Buffer b(ctx, std::uint64_t{count} * sizeof(T), name);
    if (auto* out = static_cast<T*>(b.mapped())) {
        parallelRanges(0, count, kTableGrain, [&](std::size_t s, std::size_t e) { fill(out + s, s, e); });
    } else {
        std::vector<T> v(count);
        parallelRanges(0, count, kTableGrain,
                       [&](std::size_t s, std::size_t e) { fill(v.data() + s, s, e); });
        b.uploadVector(v);
    }
    return b;
}

// Each light triangle's leaf position and its entry in the light table, by leaf position (the
// table itself is in leaf order, or grouped by emitter: light_table.h).
std::vector<std::pair<std::uint32_t, std::uint32_t>> lightEntries(
    const std::vector<gpu::LightTriangle>& lights) {
    std::vector<std::pair<std::uint32_t, std::uint32_t>> byLeaf(lights.size());
    for (std::size_t k = 0; k < lights.size(); ++k)
        byLeaf[k] = {lights[k].triangle, static_cast<std::uint32_t>(k)};
    std::sort(byLeaf.begin(), byLeaf.end());
    return byLeaf;
}

// Triangle shading records for leaf positions [begin, end); `lights` (lightEntries) gives each
// emitter's index in the light table.
void writeShading(const Scene& scene, const std::vector<std::uint32_t>& order,
                  const std::vector<std::pair<std::uint32_t, std::uint32_t>>& lights, std::size_t begin,
                  std::size_t end, gpu::TriangleShading* out) {
    const bool normals = !scene.normals.empty();
    const bool uvs = !scene.uvs.empty();
    for (std::size_t i = begin; i < end; ++i) {
        const glm::uvec3 t = scene.triangles[order[i]];
        gpu::TriangleShading s{};
        s.material = scene.triangleMaterial[order[i]];
        s.area = triangleArea(scene, order[i]);
        if (normals && triangleHasShadingNormals(scene, order[i])) {
            s.n0 = scene.normals[t.x];
            s.n1 = scene.normals[t.y];
            s.n2 = scene.normals[t.z];
            s.flags |= gpu::kTriFlagHasNormals;
        }
        if (uvs) {
            s.uv0 = scene.uvs[t.x];
            s.uv1 = scene.uvs[t.y];
            s.uv2 = scene.uvs[t.z];
        }
        s.lightIndex = gpu::kInvalidIndex;
        if (materialIsEmissive(scene, order[i])) {
            const auto it =
                std::lower_bound(lights.begin(), lights.end(),
                                 std::pair<std::uint32_t, std::uint32_t>(static_cast<std::uint32_t>(i), 0u));
            if (it != lights.end() && it->first == i) s.lightIndex = it->second;
        }
        out[i - begin] = s;
    }
}

}  // namespace

std::uint64_t maxDeviceTriangles(const vk::DeviceInfo& device) {
    return device.maxTexelBufferElements / gpu::kTriangleShadingTexels;
}

namespace {

// "N triangles, more than the K that device 'X' can hold (...)".
std::string beyondDevice(std::uint64_t triangles, const vk::DeviceInfo& device) {
    return std::to_string(triangles) + " triangles, more than the " +
           std::to_string(maxDeviceTriangles(device)) + " that device '" + device.name +
           "' can hold (maxTexelBufferElements = " + std::to_string(device.maxTexelBufferElements) +
           " texels, " + std::to_string(gpu::kTriangleShadingTexels) +
           " per triangle's shading record); use a smaller scene";
}

}  // namespace

void checkTrianglesFit(const vk::DeviceInfo& device, std::uint64_t triangles, const std::string& source) {
    if (triangles <= maxDeviceTriangles(device)) return;
    throw Error((source.empty() ? std::string("generated scene") : source) + ": the scene has " +
                beyondDevice(triangles, device));
}

void checkRenderMemory(const SceneEstimate& estimate) {
    const std::uint64_t memory = physicalMemory();
    if (memory == 0 || estimate.triangles == 0) return;
    const std::uint64_t needed = estimate.bytes + kRenderBytesPerTriangle * estimate.triangles;
    if (needed <= memory) return;
    const double perTriangle =
        double(estimate.bytes) / double(estimate.triangles) + double(kRenderBytesPerTriangle);
    const auto fits = static_cast<std::uint64_t>(double(memory) / perTriangle);
    throw Error("rendering the scene (" + std::to_string(estimate.triangles) + " triangles) needs about " +
                memoryText(needed) + " of memory (the loaded scene, its BVH and its tables), more than " +
                availableMemoryText(memory) + ": a scene like it fits with up to about " +
                std::to_string(fits) + " triangles");
}

LoadOptions deviceLoadOptions(const std::string& device, bool quiet) {
    LoadOptions options;
    options.quiet = quiet;
    options.checkEstimate = [device](const SceneEstimate& estimate) {
        // Every device holds this many (Vulkan's required minimum of maxTexelBufferElements is
        // 65536); larger scenes are compared with the device's own limit, read from a
        // short-lived context that chooses the device as the render's will.
        if (estimate.triangles > 65536 / gpu::kTriangleShadingTexels) {
            vk::ContextOptions probe;
            probe.device = device;
            std::optional<vk::Context> ctx;
            try {
                ctx.emplace(probe);
            } catch (const Error& e) {
                // The loader puts the scene's name in front; say that the device is the problem.
                throw e.withContext("no device to check the scene's size against");
            }
            if (estimate.triangles > maxDeviceTriangles(ctx->info()))
                throw Error("the scene has up to " + beyondDevice(estimate.triangles, ctx->info()));
        }
        checkRenderMemory(estimate);
    };
    return options;
}

void setCamera(gpu::SceneConstants& c, const Camera& camera, int width, int height) {
    c.camPosition = camera.position;
    c.camForward = glm::normalize(camera.forward);
    c.camRight = glm::normalize(glm::cross(c.camForward, camera.up));
    c.camUp = glm::cross(c.camRight, c.camForward);
    c.tanHalfFovY = std::tan(0.5f * camera.yfov);
    c.aspect = static_cast<float>(width) / static_cast<float>(height);
    c.width = static_cast<std::uint32_t>(width);
    c.height = static_cast<std::uint32_t>(height);
}

Camera renderCamera(const Scene& scene, int index) {
    if (index >= 0) {
        if (index >= static_cast<int>(scene.cameras.size()))
            throw Error("--camera " + std::to_string(index) + " is out of range: the scene has " +
                        std::to_string(scene.cameras.size()) + " camera(s)");
        return scene.cameras[static_cast<std::size_t>(index)];
    }
    return scene.cameras.empty() ? defaultCamera(scene) : scene.cameras.front();
}

float sceneRadius(const Scene& scene) {
    const Bounds b = scene.bounds();
    return 0.5f * glm::length(b.max - b.min);
}

LightTable sceneLightTable(const Scene& scene, const SceneBvh& bvh, const SceneGpuOptions& options) {
    std::map<std::uint32_t, double> probeWeights;
    if (options.lightSelection == LightSelection::Probe) {
        gpu::SceneConstants camera{};
        setCamera(camera, renderCamera(scene, options.camera), options.width, options.height);
        const EmitterProbe probe = probeEmitters(scene, bvh, camera, sceneRadius(scene));
        for (const auto& [material, m2] : probe.secondMoment) probeWeights[material] = std::sqrt(m2);
    }
    return makeLightTable(scene, bvh.binary.triangleOrder, options.lightSelection, probeWeights);
}

SceneGpu::SceneGpu(const vk::Context& ctx, const Scene& scene, const SceneGpuOptions& options)
    : SceneGpu(ctx, scene, options, SceneSpec(scene, options)) {}

SceneGpu::SceneGpu(const vk::Context& ctx, const Scene& scene, const SceneGpuOptions& options, SceneSpec spec)
    : spec_(std::move(spec)) {
    checkHasTriangles(scene);
    if (options.width < 1 || options.height < 1) throw Error("image size must be at least 1x1");
    // Before the BVH is built: the per-triangle tables must fit the device (makeBuffer checks
    // every table again on upload).
    checkTrianglesFit(ctx.info(), scene.triangles.size(), scene.sourcePath);
    std::optional<Progress> progress;
    if (!options.quiet && scene.triangles.size() >= kSceneProgressTriangles)
        progress.emplace("building " + std::to_string(scene.triangles.size()) + " triangles", 3.0, false);

    // BVH over the world-space triangles (the spec's, for a small scene); everything
    // per-triangle is laid out in leaf order.
    std::shared_ptr<const SceneBvh> built = spec_.bvh();
    if (progress) progress->update(0.0, "BVH");
    if (!built) built = std::make_shared<const SceneBvh>(buildSceneBvh(scene));
    if (progress) progress->update(1.0, "triangle tables");
    upload(ctx, {&scene}, options, *built, progress);
}

namespace {

SceneGpuOptions framePairOptions(SceneGpuOptions options) {
    // The tree is frame a's with grown boxes, whose collapse may hold more stack entries than
    // the spec's own tree: the kernels keep the stack in memory.
    options.genericFeatures |= 1u << gpu::kSpecBvhRegisterStack;
    return options;
}

std::shared_ptr<const SceneBvh> framePairBvh(const Scene& a, const Scene& b) {
    Timer timer;
    auto out = std::make_shared<SceneBvh>();
    out->binary = buildBvh(a.positions, a.triangles);
    growBvhBoxes(out->binary, b.positions, b.triangles);
    out->wide = collapseToWide(out->binary.nodes);
    out->buildMs = timer.ms();
    return out;
}

}  // namespace

SceneGpu::SceneGpu(const vk::Context& ctx, const Scene& a, const Scene& b, const SceneGpuOptions& options)
    : spec_(a, framePairOptions(options)) {
    checkHasTriangles(a);
    if (options.width < 1 || options.height < 1) throw Error("image size must be at least 1x1");
    if (a.triangles != b.triangles)
        throw Error("two frames on the device at once need the same triangles (" +
                    std::to_string(a.triangles.size()) + " and " + std::to_string(b.triangles.size()) +
                    "): a mesh's topology changes between them");
    checkTrianglesFit(ctx.info(), 2 * a.triangles.size(), a.sourcePath);
    std::optional<Progress> progress;
    upload(ctx, {&a, &b}, options, *framePairBvh(a, b), progress);
}

void SceneGpu::upload(const vk::Context& ctx, const std::vector<const Scene*>& frames,
                      const SceneGpuOptions& options, const SceneBvh& built,
                      std::optional<Progress>& progress) {
    const Scene& scene = *frames.front();
    const Bvh& bvh = built.binary;
    bvhInfo_.buildMs = built.buildMs;
    bvhInfo_.nodes = static_cast<std::uint32_t>(bvh.nodes.size());
    bvhInfo_.maxDepth = bvh.stats.maxDepth;

    // Per frame: its light table (each frame's emitters in the same leaf order) and constants.
    std::vector<gpu::LightTriangle> lights;
    std::vector<std::vector<std::pair<std::uint32_t, std::uint32_t>>> entries;
    std::vector<gpu::PunctualLight> punctual;
    std::vector<gpu::SceneConstants> constants;
    for (const Scene* frame : frames) {
        const LightTable lightTable = sceneLightTable(*frame, built, options);
        if (frame == frames.front()) {
            lightShares_ = lightTable.shares;
            lightProbed_ = lightTable.probed;
        }
        // The spec counted the same lights (emitterPower) to specialise the kernels.
        if (lightTable.lights.size() != spec_.features().emissiveTriangles)
            throw Error("the frames have different emitters (" + std::to_string(lightTable.lights.size()) +
                        " and " + std::to_string(spec_.features().emissiveTriangles) + " light triangles)");
        double punctualPower = 0.0;
        for (const auto& l : frame->punctualLights)
            punctualPower += 4.0 * kPi * std::max(1e-12, double(gpu::luminance(l.intensity)));
        gpu::SceneConstants c{};
        setCamera(c, renderCamera(*frame, options.camera), options.width, options.height);
        c.envRadiance = options.envRadiance;
        c.numLightTriangles = static_cast<std::uint32_t>(lightTable.lights.size());
        c.numPunctualLights = static_cast<std::uint32_t>(frame->punctualLights.size());
        c.lightTrianglePower = static_cast<float>(lightTable.totalPower);
        c.punctualPower = static_cast<float>(punctualPower);
        c.maxDepth = options.maxDepth;
        c.rrDepth = options.rrDepth;
        c.numTriangles = static_cast<std::uint32_t>(bvh.triangleOrder.size());
        c.sceneRadius = sceneRadius(*frame);
        if (!constants.empty() && (c.numPunctualLights != constants.front().numPunctualLights))
            throw Error("the frames have different punctual lights");
        constants.push_back(c);
        entries.push_back(lightEntries(lightTable.lights));
        lights.insert(lights.end(), lightTable.lights.begin(), lightTable.lights.end());
        punctual.insert(punctual.end(), frame->punctualLights.begin(), frame->punctualLights.end());
    }
    constants_ = constants.front();

    // Textures: linear RGBA as packed halves.
    std::vector<gpu::TextureInfo> texInfo;
    std::vector<glm::uvec2> texels;
    for (const Texture& t : scene.textures) {
        gpu::TextureInfo info{};
        info.offset = static_cast<std::uint32_t>(texels.size());
        info.width = static_cast<std::uint32_t>(t.width);
        info.height = static_cast<std::uint32_t>(t.height);
        for (const glm::vec4& c : t.texels)
            texels.emplace_back(glm::packHalf2x16(glm::vec2(c.x, c.y)),
                                glm::packHalf2x16(glm::vec2(c.z, c.w)));
        texInfo.push_back(info);
    }

    if (progress) progress->update(2.0, "upload");
    const std::vector<std::uint32_t>& order = bvh.triangleOrder;
    const std::size_t count = order.size();
    // Records [begin, end) of the frames' tables one after the other: write(frame, begin, end, out)
    // for each frame's part, in that frame's leaf positions.
    const auto byFrame = [&](std::size_t begin, std::size_t end, const auto& write) {
        for (std::size_t f = begin / count; f * count < end; ++f) {
            const std::size_t b = std::max(begin, f * count), e = std::min(end, (f + 1) * count);
            write(f, b - f * count, e - f * count, b - begin);
        }
    };
    triGeom_ = makeFilledBuffer<gpu::TriangleGeom>(
        ctx, frames.size() * count, "triangle geometry", gpu::kBindTriGeom,
        [&](gpu::TriangleGeom* out, std::size_t begin, std::size_t end) {
            byFrame(begin, end, [&](std::size_t f, std::size_t b, std::size_t e, std::size_t at) {
                writeTriangleGeoms(frames[f]->positions, frames[f]->triangles, order, b, e, out + at);
            });
        });
    triShading_ = makeFilledBuffer<gpu::TriangleShading>(
        ctx, frames.size() * count, "triangle shading", gpu::kBindTriShading,
        [&](gpu::TriangleShading* out, std::size_t begin, std::size_t end) {
            byFrame(begin, end, [&](std::size_t f, std::size_t b, std::size_t e, std::size_t at) {
                writeShading(*frames[f], order, entries[f], b, e, out + at);
            });
        });
    bvh_ = makeBuffer(ctx, built.wide.nodes, "BVH nodes (4-wide)", gpu::kBindBvh);
    materials_ = makeBuffer(ctx, scene.materials, "materials", gpu::kBindMaterials);
    texInfo_ = makeBuffer(ctx, texInfo, "texture table", gpu::kBindTexInfo);
    texels_ = makeBuffer(ctx, texels, "texels", gpu::kBindTexels);
    lightTris_ = makeBuffer(ctx, lights, "light triangles", gpu::kBindLightTris);
    punctual_ = makeBuffer(ctx, punctual, "punctual lights", gpu::kBindPunctual);
    sceneConst_ = makeBuffer(ctx, constants, "scene constants", gpu::kBindSceneConst);
    if (progress) {
        progress->update(3.0);
        progress->finish("uploaded");
    }
}

std::uint64_t SceneGpu::deviceBytes() const {
    std::uint64_t bytes = 0;
    for (const vk::Buffer* b : {&triGeom_, &triShading_, &bvh_, &materials_, &texInfo_, &texels_, &lightTris_,
                                &punctual_, &sceneConst_})
        bytes += b->size();
    return bytes;
}

void SceneGpu::bindTo(vk::Kernel& kernel) const {
    kernel.bind(gpu::kBindTriGeom, triGeom_);
    kernel.bind(gpu::kBindTriShading, triShading_);
    kernel.bind(gpu::kBindBvh, bvh_);
    kernel.bind(gpu::kBindMaterials, materials_);
    kernel.bind(gpu::kBindTexInfo, texInfo_);
    kernel.bind(gpu::kBindTexels, texels_);
    kernel.bind(gpu::kBindLightTris, lightTris_);
    kernel.bind(gpu::kBindPunctual, punctual_);
    kernel.bind(gpu::kBindSceneConst, sceneConst_);
}

}  // namespace gdpt
