// gltf_internal.h — shared state and helpers of the glTF loader's translation units
// (gltf_loader.cpp: file, node graph, cameras, lights; gltf_geometry.cpp: accessors and
// primitives; gltf_materials.cpp: materials and textures; gltf_images.cpp: image decoding).
// Not part of the public API.
#pragma once

#include <tiny_gltf.h>

#include <cstdint>
#include <glm/glm.hpp>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "scene/scene.h"
#include "util/error.h"

namespace gdpt::gltf {

// Upper bounds that reject absurd files before allocating (a 2 GiB storage buffer is the
// most lavapipe offers, so anything beyond these could never be rendered anyway).
constexpr std::uint64_t kMaxAccessorCount = 1ull << 28;  // elements per accessor
constexpr std::uint64_t kMaxSceneVertices = 1ull << 30;  // vertices after instancing
constexpr std::uint64_t kMaxImagePixels = 1ull << 28;    // texels per image

// One mesh instance found by the node traversal: mesh index and its world matrix.
struct MeshInstance {
    int mesh = -1;
    int node = -1;
    glm::dmat4 world{1.0};
};

// Loader state shared by all stages.
struct Context {
    const tinygltf::Model& model;
    Scene& scene;
    // (texture index, sRGB?) -> index into scene.textures; a texture used both as colour
    // and as data becomes two entries (glTF 2.0 §3.9.2: baseColor/emissive are sRGB).
    std::map<std::pair<int, bool>, int> textureCache;
    int defaultMaterial = -1;  // index of the glTF default material once created

    // Adds an unsupported-feature note once.
    void unsupported(const std::string& what);
};

// "mesh 'Floor'" when the element has a name, else "mesh 3".
std::string elementName(const char* kind, int index, const std::string& name);

// Accessor readers (gltf_geometry.cpp). `role` names the use in messages ("POSITION").
// Throw gdpt::Error naming the accessor on any inconsistency.
std::vector<glm::vec3> readVec3(const tinygltf::Model& model, int accessor, const char* role);
std::vector<glm::vec2> readTexcoords(const tinygltf::Model& model, int accessor, const char* role);
std::vector<std::uint32_t> readIndices(const tinygltf::Model& model, int accessor);

// Appends all triangle primitives of one mesh instance (gltf_geometry.cpp).
void addMeshInstance(Context& ctx, const MeshInstance& inst, bool sceneHasNormals, bool sceneHasUvs);

// Material index in scene.materials for glTF material `material` (-1 = default material)
// (gltf_materials.cpp). Converts all materials up front with convertMaterials.
void convertMaterials(Context& ctx);
std::uint32_t materialIndex(Context& ctx, int material);

// Decodes PNG/JPEG bytes for tinygltf (gltf_images.cpp); registered with SetImageLoader
// with userData = the tinygltf::Model being loaded (used to bounds-check bufferView images).
bool decodeImage(tinygltf::Image* image, int imageIndex, std::string* err, std::string* warn, int reqWidth,
                 int reqHeight, const unsigned char* bytes, int size, void* userData);

// Converts a decoded tinygltf image to a linear RGBA float texture (gltf_images.cpp).
Texture imageToTexture(const tinygltf::Image& image, bool srgb);

}  // namespace gdpt::gltf
