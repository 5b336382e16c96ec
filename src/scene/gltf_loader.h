// gltf_loader.h — loads a glTF 2.0 file (.gltf JSON or .glb binary) into the flattened CPU
// Scene: every triangle primitive of the chosen scene's node hierarchy in world space, its
// materials (metallic-roughness + KHR_materials_specular/ior/emissive_strength), decoded
// linear textures, KHR_lights_punctual point/spot lights and perspective cameras.
//
// Anything in the file that gdpt does not render is listed in Scene::unsupported (never
// silently dropped). Malformed input throws gdpt::Error whose message names the file and
// the element, e.g. "x.gltf: mesh 'Floor' primitive 2: accessor 7 (POSITION) has type VEC2,
// expected VEC3".
//
// Normals: a primitive with NORMAL keeps its (transformed, renormalised) normals. If no
// primitive of the scene has normals, Scene::normals stays empty (kernels use geometric
// normals). Otherwise primitives without NORMAL get flat normals, as glTF 2.0 §3.7.2.1
// requires ("client implementations MUST calculate flat normals"), by giving each of their
// triangles three own vertices carrying the face normal.
//
// Hostile input is refused before it costs anything: the JSON's nesting depth is bounded
// before any parser sees it, and every accessor, bufferView and the instanced scene's size are
// checked on the JSON alone (estimateGltf) before tinygltf reads a buffer or the loader
// allocates an element. Scenes too large for the memory budget or, through
// LoadOptions::checkEstimate, for the device are refused at that point.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "scene/animation.h"
#include "scene/scene.h"

namespace gdpt {

// What loading a file will produce and cost, worked out from its JSON alone (the default
// scene's node hierarchy and the counts of the accessors its meshes use).
struct SceneEstimate {
    std::uint64_t triangles = 0;  // after instancing; an upper bound (degenerate ones are dropped)
    std::uint64_t vertices = 0;   // after instancing, flat-shaded primitives counted 3 per triangle
    std::uint64_t bytes = 0;      // peak memory of the loader's scene arrays and per-primitive buffers
};

struct LoadOptions {
    // Called with the estimate after the file's structure has been checked and before any
    // buffer, image or accessor is read into memory; throwing gdpt::Error refuses the scene
    // (e.g. beyond a device limit). The loader prefixes the file name.
    std::function<void(const SceneEstimate&)> checkEstimate;
    // Most memory the loader may need (SceneEstimate::bytes); 0 = the machine's physical memory.
    std::uint64_t memoryBudget = 0;
    // Progress on stderr for scenes of at least this many (estimated) triangles, unless quiet.
    std::uint64_t progressTriangles = 1'000'000;
    bool quiet = false;
};

// A glTF file parsed and checked once (its materials and textures converted), from which
// scenes are instanced: the rest pose, or any time of one of its animations (animation.h),
// the animated nodes' transforms composed through the hierarchy as for a static scene
// (cameras and punctual lights included). A sequence of frames parses the file once.
class GltfAsset {
public:
    // Reads and parses `path` (.gltf or .glb, detected from the file's magic bytes) and checks
    // its animations. Throws gdpt::Error naming the file.
    explicit GltfAsset(const std::string& path, const LoadOptions& opts = {});
    ~GltfAsset();
    GltfAsset(GltfAsset&&) noexcept;
    GltfAsset& operator=(GltfAsset&&) noexcept;

    [[nodiscard]] const std::string& path() const;
    [[nodiscard]] const std::vector<Animation>& animations() const;
    // The index of the animation named `nameOrIndex` (its name, else a decimal index). Throws
    // gdpt::UsageError listing the animations if there is none such.
    [[nodiscard]] int findAnimation(const std::string& nameOrIndex) const;
    // The scene in its rest pose (animation < 0), or with animation `animation` at `time`
    // seconds (before 0 or after its duration the channels hold their first or last keys).
    // Throws gdpt::Error naming the file.
    [[nodiscard]] Scene instance(int animation = -1, double time = 0.0) const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// Loads `path` in its rest pose: GltfAsset(path, opts).instance(). Throws gdpt::Error.
[[nodiscard]] Scene loadGltf(const std::string& path, const LoadOptions& opts = {});

// The estimate of `path` from its JSON alone (a .glb's BIN chunk and external buffers are not
// read), after the same structural checks loadGltf makes first. Throws gdpt::Error.
[[nodiscard]] SceneEstimate estimateGltf(const std::string& path);

// A camera used when the file has none: looks from +Z towards -Z at the centre of the
// scene bounds, far enough that the bounding sphere fits the 45° vertical field of view.
[[nodiscard]] Camera defaultCamera(const Scene& scene);

// A few lines summarising the scene (counts, bounds, cameras, unsupported features).
[[nodiscard]] std::string describeScene(const Scene& scene);

// One line per animation: index, name, duration, what it drives.
[[nodiscard]] std::string describeAnimations(const std::vector<Animation>& animations);

}  // namespace gdpt
