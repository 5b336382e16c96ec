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
#pragma once

#include <string>

#include "scene/scene.h"

namespace gdpt {

// Options of the loader. Empty for now; kept so that callers need not change later.
struct LoadOptions {};

// Loads `path` (.gltf or .glb, detected from the file's magic bytes). Throws gdpt::Error.
[[nodiscard]] Scene loadGltf(const std::string& path, const LoadOptions& opts = {});

// A camera used when the file has none: looks from +Z towards -Z at the centre of the
// scene bounds, far enough that the bounding sphere fits the 45° vertical field of view.
[[nodiscard]] Camera defaultCamera(const Scene& scene);

// A few lines summarising the scene (counts, bounds, cameras, unsupported features).
[[nodiscard]] std::string describeScene(const Scene& scene);

}  // namespace gdpt
