// gltf_internal.h — shared state and helpers of the glTF loader's translation units
// (gltf_loader.cpp: the file and the scene's instances; gltf_nodes.cpp: node graph, cameras,
// lights; gltf_precheck.cpp: checks of the JSON text before tinygltf parses it;
// gltf_geometry.cpp: accessors and primitives; gltf_materials.cpp: materials and textures;
// gltf_images.cpp: image decoding).
// Not part of the public API.
#pragma once

#include <tiny_gltf.h>

#include <cstdint>
#include <glm/glm.hpp>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "scene/animation.h"
#include "scene/gltf_loader.h"
#include "scene/scene.h"
#include "util/error.h"

namespace gdpt::gltf {

// Upper bounds that reject absurd files before allocating (a 2 GiB storage buffer is the
// most lavapipe offers, so anything beyond these could never be rendered anyway).
constexpr std::uint64_t kMaxAccessorCount = 1ull << 28;  // elements per accessor
constexpr std::uint64_t kMaxSceneVertices = 1ull << 30;  // vertices after instancing
constexpr std::uint64_t kMaxImagePixels = 1ull << 28;    // texels per image

// Deepest nesting of JSON arrays and objects accepted. glTF's own schema nests about ten
// levels (root > materials > material > extensions > extension > textureInfo > extensions >
// KHR_texture_transform > offset); the rest is room for `extras`. tinygltf converts JSON to
// its Value type recursively: 20,000 levels overflowed an 8 MiB stack (10,000 did not), so 128
// keeps the recursion two orders of magnitude below that.
constexpr int kMaxJsonDepth = 128;

// Accessors without a bufferView are zeros (glTF 2.0 §3.6.2.3) the file does not hold. The
// loader creates at most this much such data beyond the byteLength of the file's buffers, so
// that a file cannot make it allocate far more than its own size.
constexpr std::uint64_t kZeroFilledAllowance = 1ull << 20;  // bytes

// Supported size of a scene: the extent of its bounding box (largest side) and the
// magnitude of any vertex coordinate, in scene units. Triangle normals and areas are computed
// in single precision from |e1 x e2|, whose square grows as the fourth power of the triangle's
// size: at 2^31 even a triangle spanning the whole box has |e1 x e2|^2 <= 9 * 2^124, below
// FLT_MAX = 2^128, and at 2^-31 a right triangle as large as the scene still has
// |e1 x e2|^2 >= 2^-124, above the smallest normal float 2^-126 (GPUs may flush smaller
// values to zero). Outside, the normals overflow or vanish and the image is black (measured
// on lavapipe with the 2-unit Cornell box: scaled by 1e9 and 1e-10 it renders as unscaled, by
// 4e9 and 1e-11 wrongly; lavapipe keeps denormals, which is why 1e-10 still works there).
constexpr double kMaxSceneExtent = 2147483648.0;        // 2^31, about 2.1e9
constexpr double kMinSceneExtent = 1.0 / 2147483648.0;  // 2^-31, about 4.7e-10

// Extensions whose content gdpt renders; a file may require only these (glTF 2.0 §3.12).
bool supportedExtension(const std::string& name);

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
// A number in messages: "%g" ("-0.5", "1e+38", "nan").
std::string formatNumber(double v);

// The node graph (gltf_nodes.cpp). Local transform of a node: `matrix` (column-major) or
// T * R * S (glTF 2.0 §3.5.3), an animation's pose (if any) replacing the node's own
// translation, rotation or scale.
glm::dmat4 localMatrix(const tinygltf::Node& node, const NodePose* pose = nullptr);
// Checks the node graph (children in range, one parent each, no cycles); the parent of each
// node (-1 for none).
std::vector<int> checkNodeGraph(const tinygltf::Model& model);
// The root nodes of the default scene (every root node of a file without scenes).
std::vector<int> sceneRoots(const tinygltf::Model& model, const std::vector<int>& parent);
// The camera of `node`, placed by its world matrix, into ctx.scene.cameras.
void addCamera(Context& ctx, const tinygltf::Node& node, const glm::dmat4& world);
// A KHR_lights_punctual light of a node (its extension object `ext`) into ctx.scene.punctualLights;
// unsupported kinds are noted.
void addLight(Context& ctx, const tinygltf::Value& ext, const glm::dmat4& world);

// Checks of the JSON text (gltf_precheck.cpp), in order: nesting depth (kMaxJsonDepth),
// required extensions, bufferView strides, every accessor's count and byte range against its
// bufferView and buffer, the zero-filled data allowance; then estimates the instanced scene.
// Throws gdpt::Error naming the element. Returns nothing when the text is not JSON at all
// (tinygltf reports that).
std::optional<SceneEstimate> precheckJson(std::string_view text);

// Accessor readers (gltf_geometry.cpp). `role` names the use in messages ("POSITION").
// Throw gdpt::Error naming the accessor on any inconsistency.
std::vector<glm::vec3> readVec3(const tinygltf::Model& model, int accessor, const char* role);
std::vector<glm::vec2> readTexcoords(const tinygltf::Model& model, int accessor, const char* role);
std::vector<std::uint32_t> readIndices(const tinygltf::Model& model, int accessor);
// A SCALAR, VEC3 or VEC4 accessor (`type`) as (x, y, z, w) doubles, missing components 0, the
// values unchecked (animation keys; animation.h checks them): float components, or with
// `normalizedIntegers` also normalized (unsigned) bytes and shorts (rotations, glTF 2.0 §3.11).
std::vector<glm::dvec4> readKeyValues(const tinygltf::Model& model, int accessor, const char* role, int type,
                                      bool normalizedIntegers);

// The file's animations (gltf_animation.cpp), every channel checked (animation.h
// checkChannel) and named; channels gdpt does not apply (morph target weights, channels
// without a node) are noted as unsupported. Throws gdpt::Error naming the animation and
// channel.
std::vector<Animation> readAnimations(Context& ctx);

// Appends all triangle primitives of one mesh instance (gltf_geometry.cpp).
void addMeshInstance(Context& ctx, const MeshInstance& inst, bool sceneHasNormals, bool sceneHasUvs);

// Material index in scene.materials for glTF material `material` (-1 = default material)
// (gltf_materials.cpp). Converts all materials up front with convertMaterials.
void convertMaterials(Context& ctx);
std::uint32_t materialIndex(Context& ctx, int material);

// What decodeImage gets as its userData: the tinygltf::Model being loaded (to bounds-check
// bufferView images) and the memory left for images. A decoded image costs its 8- or 16-bit
// RGBA pixels plus the linear float texture made from them (imageToTexture); an image that
// does not fit is refused from its header, before it is decoded (a few KB of PNG can
// announce 2^28 pixels: 5 GiB).
struct ImageDecodeContext {
    const tinygltf::Model* model = nullptr;
    std::uint64_t bytesLeft = ~std::uint64_t{0};
};

// Decodes PNG/JPEG bytes for tinygltf (gltf_images.cpp); registered with SetImageLoader
// with userData = an ImageDecodeContext.
bool decodeImage(tinygltf::Image* image, int imageIndex, std::string* err, std::string* warn, int reqWidth,
                 int reqHeight, const unsigned char* bytes, int size, void* userData);

// Converts a decoded tinygltf image to a linear RGBA float texture (gltf_images.cpp).
Texture imageToTexture(const tinygltf::Image& image, bool srgb);

}  // namespace gdpt::gltf
