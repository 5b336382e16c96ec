// gltf_loader.cpp — entry point of the glTF loader: reads the file, lets tinygltf parse it,
// checks extensions, walks the node hierarchy of the chosen scene (glTF 2.0 §3.5) and
// collects mesh instances, cameras (§3.10) and KHR_lights_punctual lights. Geometry and
// materials are converted in gltf_geometry.cpp and gltf_materials.cpp.
#include "scene/gltf_loader.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <initializer_list>
#include <map>
#include <optional>
#include <sstream>
#include <string_view>

#include "scene/gltf_internal.h"
#include "util/huge_pages.h"
#include "util/interrupt.h"
#include "util/memory.h"
#include "util/progress.h"

namespace gdpt {
namespace gltf {

void Context::unsupported(const std::string& what) {
    auto& list = scene.unsupported;
    if (std::find(list.begin(), list.end(), what) == list.end()) list.push_back(what);
}

std::string elementName(const char* kind, int index, const std::string& name) {
    return name.empty() ? std::string(kind) + " " + std::to_string(index)
                        : std::string(kind) + " '" + name + "'";
}

std::string formatNumber(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", v);
    return text;
}

namespace {

constexpr std::uintmax_t kMaxFileBytes = 2ull << 30;

bool isGlb(const std::vector<unsigned char>& bytes) {
    return bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
}

// Reads `path`; with jsonOnly, a .glb only up to the end of its JSON chunk (a 12-byte header,
// then the chunk's length, its type and its data; glTF 2.0 §4.4), so that the JSON can be
// checked before the BIN chunk is read.
std::vector<unsigned char> readFile(const std::string& path, bool jsonOnly) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw Error("cannot open file: it does not exist");
    if (!std::filesystem::is_regular_file(path, ec)) throw Error("cannot open file: not a regular file");
    const std::uintmax_t size = std::filesystem::file_size(path, ec);
    if (ec) throw Error("cannot read file size: " + ec.message());
    if (size > kMaxFileBytes) throw Error("file is larger than 2 GiB");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(std::string("cannot open file: ") + std::strerror(errno));
    std::uintmax_t wanted = size;
    if (jsonOnly && size >= 20) {
        unsigned char header[20];
        if (!in.read(reinterpret_cast<char*>(header), 20)) throw Error("cannot read file");
        std::uint32_t jsonLength = 0;
        std::memcpy(&jsonLength, header + 12, 4);
        if (std::memcmp(header, "glTF", 4) == 0)
            wanted = std::min<std::uintmax_t>(size, 20 + std::uintmax_t(jsonLength));
        in.seekg(0);
    }
    std::vector<unsigned char> bytes(static_cast<std::size_t>(wanted));
    if (wanted > 0 && !in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(wanted)))
        throw Error("cannot read file");
    return bytes;
}

// tinygltf reads external buffers and images whole before comparing their size with the
// declared byteLength; refuse files it could not use before reading them.
bool readExternalFile(std::vector<unsigned char>* out, std::string* err, const std::string& path,
                      void* user) {
    std::error_code ec;
    const std::uintmax_t size = std::filesystem::file_size(path, ec);
    if (!ec && size > kMaxFileBytes) {
        if (err) *err += "File " + path + " is larger than 2 GiB\n";
        return false;
    }
    return tinygltf::ReadWholeFile(out, err, path, user);
}

// tinygltf's messages are newline-separated; join them into one line.
std::string oneLine(std::string s) {
    while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
    std::replace(s.begin(), s.end(), '\n', ';');
    return s;
}

void checkFinite(const std::vector<double>& v, const std::string& what) {
    for (double x : v)
        if (!std::isfinite(x)) throw Error(what + " is not finite");
}

// Local transform of a node: `matrix` (column-major) or T * R * S (glTF 2.0 §3.5.3), where an
// animation's pose (if any) replaces the node's own translation, rotation or scale (animated
// nodes have no matrix: readAnimations refuses them).
glm::dmat4 localMatrix(const tinygltf::Node& node, const NodePose* pose = nullptr) {
    if (!node.matrix.empty()) {
        if (node.matrix.size() != 16) throw Error("matrix must have 16 numbers");
        checkFinite(node.matrix, "matrix");
        return glm::make_mat4(node.matrix.data());
    }
    glm::dmat4 t(1.0), r(1.0), s(1.0);
    std::optional<glm::dvec3> translation = pose ? pose->translation : std::nullopt;
    if (!translation && !node.translation.empty()) {
        if (node.translation.size() != 3) throw Error("translation must have 3 numbers");
        checkFinite(node.translation, "translation");
        translation = glm::dvec3(node.translation[0], node.translation[1], node.translation[2]);
    }
    if (translation) t[3] = glm::dvec4(*translation, 1.0);
    std::optional<glm::dquat> rotation = pose ? pose->rotation : std::nullopt;
    if (!rotation && !node.rotation.empty()) {
        if (node.rotation.size() != 4) throw Error("rotation must have 4 numbers");
        checkFinite(node.rotation, "rotation");
        // glTF stores (x, y, z, w); glm's constructor takes (w, x, y, z).
        rotation = glm::dquat(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]);
    }
    if (rotation) {
        const double len = glm::length(*rotation);
        if (!(len > 1e-12)) throw Error("rotation is a zero quaternion");
        r = glm::mat4_cast(*rotation / len);
    }
    std::optional<glm::dvec3> scale = pose ? pose->scale : std::nullopt;
    if (!scale && !node.scale.empty()) {
        if (node.scale.size() != 3) throw Error("scale must have 3 numbers");
        checkFinite(node.scale, "scale");
        scale = glm::dvec3(node.scale[0], node.scale[1], node.scale[2]);
    }
    if (scale) s = glm::scale(glm::dmat4(1.0), *scale);
    return t * r * s;
}

// The JSON text of a .gltf file, or the JSON chunk of a .glb (a 12-byte header, then the
// first chunk's length, its type "JSON" and its data); empty if the container is malformed,
// which the parser reports.
std::string_view jsonText(const std::vector<unsigned char>& bytes, bool binary) {
    const char* data = reinterpret_cast<const char*>(bytes.data());
    if (!binary) return {data, bytes.size()};
    if (bytes.size() < 20) return {};
    std::uint32_t length = 0, type = 0;
    std::memcpy(&length, data + 12, 4);
    std::memcpy(&type, data + 16, 4);
    if (type != 0x4E4F534Au || length > bytes.size() - 20) return {};  // 'JSON', little endian
    return {data + 20, length};
}

void checkExtensions(gltf::Context& ctx) {
    const tinygltf::Model& model = ctx.model;
    for (const auto& ext : model.extensionsUsed)
        if (!gltf::supportedExtension(ext)) ctx.unsupported("extension " + ext);
    if (!model.skins.empty()) ctx.unsupported("skins (meshes rendered in their bind pose)");
}

// Checks the node graph: child indices in range, at most one parent per node (glTF 2.0
// §3.5.2: "node hierarchy MUST be a set of disjoint strict trees"), no cycles. Returns the
// parent of each node (-1 for none).
std::vector<int> checkNodeGraph(const tinygltf::Model& model) {
    const int n = static_cast<int>(model.nodes.size());
    std::vector<int> parent(static_cast<std::size_t>(n), -1);
    for (int i = 0; i < n; ++i) {
        const auto& node = model.nodes[static_cast<std::size_t>(i)];
        for (int c : node.children) {
            const std::string label = elementName("node", i, node.name);
            if (c < 0 || c >= n)
                throw Error(label + ": child " + std::to_string(c) + " out of range (file has " +
                            std::to_string(n) + " nodes)");
            if (c == i) throw Error(label + " is its own child (cyclic node graph)");
            if (parent[static_cast<std::size_t>(c)] >= 0)
                throw Error("node " + std::to_string(c) + " is used twice as a child (by node " +
                            std::to_string(parent[static_cast<std::size_t>(c)]) + " and node " +
                            std::to_string(i) + ")");
            parent[static_cast<std::size_t>(c)] = i;
        }
    }
    // With one parent each, a cycle is a chain of parents that returns to its start.
    std::vector<int> state(static_cast<std::size_t>(n), 0);  // 0 new, 1 on chain, 2 done
    for (int i = 0; i < n; ++i) {
        std::vector<int> chain;
        int p = i;
        while (p >= 0 && state[static_cast<std::size_t>(p)] == 0) {
            state[static_cast<std::size_t>(p)] = 1;
            chain.push_back(p);
            p = parent[static_cast<std::size_t>(p)];
        }
        if (p >= 0 && state[static_cast<std::size_t>(p)] == 1)
            throw Error("cyclic node graph: node " + std::to_string(p) + " is its own ancestor");
        for (int c : chain) state[static_cast<std::size_t>(c)] = 2;
    }
    return parent;
}

std::vector<int> sceneRoots(const tinygltf::Model& model, const std::vector<int>& parent) {
    std::vector<int> roots;
    if (model.scenes.empty()) {
        // No scenes: render every root node (§3.5.1 leaves this to the application).
        for (std::size_t i = 0; i < parent.size(); ++i)
            if (parent[i] < 0) roots.push_back(static_cast<int>(i));
        return roots;
    }
    const int s = model.defaultScene >= 0 ? model.defaultScene : 0;
    if (static_cast<std::size_t>(s) >= model.scenes.size())
        throw Error("scene " + std::to_string(s) + " out of range (file has " +
                    std::to_string(model.scenes.size()) + " scenes)");
    const auto& scene = model.scenes[static_cast<std::size_t>(s)];
    for (int r : scene.nodes) {
        const std::string label = elementName("scene", s, scene.name);
        if (r < 0 || static_cast<std::size_t>(r) >= model.nodes.size())
            throw Error(label + ": node " + std::to_string(r) + " out of range (file has " +
                        std::to_string(model.nodes.size()) + " nodes)");
        if (parent[static_cast<std::size_t>(r)] >= 0)
            throw Error(label + ": root node " + std::to_string(r) + " is also a child of node " +
                        std::to_string(parent[static_cast<std::size_t>(r)]));
        if (std::find(roots.begin(), roots.end(), r) != roots.end())
            throw Error(label + ": root node " + std::to_string(r) + " is listed twice");
        roots.push_back(r);
    }
    return roots;
}

void addCamera(gltf::Context& ctx, const tinygltf::Node& node, const glm::dmat4& world) {
    const auto& model = ctx.model;
    if (static_cast<std::size_t>(node.camera) >= model.cameras.size())
        throw Error("camera " + std::to_string(node.camera) + " out of range (file has " +
                    std::to_string(model.cameras.size()) + " cameras)");
    const tinygltf::Camera& cam = model.cameras[static_cast<std::size_t>(node.camera)];
    const std::string label = elementName("camera", node.camera, cam.name);
    if (cam.type != "perspective") {
        ctx.unsupported(label + ": " + cam.type + " cameras (only perspective)");
        return;
    }
    const double yfov = cam.perspective.yfov;
    if (!(yfov > 0.0 && yfov < glm::pi<double>()))
        throw Error(label + ": yfov " + std::to_string(yfov) + " is not in (0, pi)");
    Camera out;
    out.name = cam.name.empty() ? node.name : cam.name;
    out.position = glm::vec3(world * glm::dvec4(0, 0, 0, 1));
    // Camera looks down local -Z with local +Y up (§3.10.1); scale is removed by
    // normalising and the up vector is made orthogonal (Gram-Schmidt).
    // Degenerate means relative to the transform's own scale: a camera in a scene scaled by
    // 1e-12 is fine (the scene's size is checked on its own, see kMinSceneExtent).
    const glm::dvec3 fwd = glm::dmat3(world) * glm::dvec3(0, 0, -1);
    const glm::dvec3 up = glm::dmat3(world) * glm::dvec3(0, 1, 0);
    const double fl = glm::length(fwd);
    if (!(fl > 0.0) || !std::isfinite(fl)) throw Error(label + ": degenerate camera transform");
    const glm::dvec3 f = fwd / fl;
    const glm::dvec3 u = up - glm::dot(up, f) * f;
    const double ul = glm::length(u);
    if (!(ul > 1e-9 * glm::length(up)) || !std::isfinite(ul))
        throw Error(label + ": degenerate camera transform");
    out.forward = glm::vec3(f);
    out.up = glm::vec3(u / ul);
    out.yfov = static_cast<float>(yfov);
    out.aspectRatio =
        cam.perspective.aspectRatio > 0.0 ? static_cast<float>(cam.perspective.aspectRatio) : 0.0f;
    ctx.scene.cameras.push_back(out);
}

void addLight(gltf::Context& ctx, const tinygltf::Value& ext, const glm::dmat4& world) {
    const auto& model = ctx.model;
    if (!ext.IsObject() || !ext.Has("light") || !ext.Get("light").IsInt())
        throw Error("KHR_lights_punctual: 'light' is missing or not an integer");
    const int index = ext.Get("light").GetNumberAsInt();
    if (index < 0 || static_cast<std::size_t>(index) >= model.lights.size())
        throw Error("KHR_lights_punctual light " + std::to_string(index) + " out of range (file has " +
                    std::to_string(model.lights.size()) + " lights)");
    const tinygltf::Light& light = model.lights[static_cast<std::size_t>(index)];
    const std::string label = elementName("light", index, light.name);
    gpu::PunctualLight out{};
    glm::dvec3 color(1.0);
    if (!light.color.empty()) {
        if (light.color.size() != 3) throw Error(label + ": color must have 3 numbers");
        color = glm::dvec3(light.color[0], light.color[1], light.color[2]);
    }
    // KHR_lights_punctual light.schema.json: color components in [0, 1]; a negative or NaN
    // color or intensity would emit negative or NaN radiance.
    for (int c = 0; c < 3; ++c)
        if (!(color[c] >= 0.0 && color[c] <= 1.0))
            throw Error(label + ": color component " + std::to_string(c) + " is " +
                        gltf::formatNumber(color[c]) + ", outside [0, 1] (KHR_lights_punctual)");
    if (!(light.intensity >= 0.0) || !std::isfinite(light.intensity))
        throw Error(label + ": intensity " + gltf::formatNumber(light.intensity) +
                    " is not a finite value >= 0");
    // Intensity in candela, treated as W/sr (see gdpt_shared.h PunctualLight).
    out.intensity = glm::vec3(color * light.intensity);
    out.position = glm::vec3(world * glm::dvec4(0, 0, 0, 1));
    glm::dvec3 dir = glm::dmat3(world) * glm::dvec3(0, 0, -1);  // lights point down local -Z
    const double dl = glm::length(dir);
    out.direction = dl > 0.0 ? glm::vec3(dir / dl) : glm::vec3(0, 0, -1);
    if (light.range > 0.0 && std::isfinite(light.range))
        ctx.unsupported(label + ": range ignored (lights have unlimited range)");
    if (light.type == "point") {
        out.type = gpu::kPunctualPoint;
        out.cosInner = out.cosOuter = -1.0f;
    } else if (light.type == "spot") {
        const double inner = light.spot.innerConeAngle, outer = light.spot.outerConeAngle;
        if (!(inner >= 0.0 && inner < outer && outer <= glm::half_pi<double>()))
            throw Error(label + ": spot cone angles must satisfy 0 <= inner < outer <= pi/2");
        out.type = gpu::kPunctualSpot;
        out.cosInner = static_cast<float>(std::cos(inner));
        out.cosOuter = static_cast<float>(std::cos(outer));
    } else {
        ctx.unsupported(label + ": " + light.type + " lights (only point and spot)");
        return;
    }
    ctx.scene.punctualLights.push_back(out);
}

// A file that is neither a .glb (magic "glTF") nor JSON whose first character (after a
// UTF-8 byte order mark and white space) opens an object is refused by what it is, before a
// JSON check reads an image's bytes as brackets.
void refuseNonGltf(const std::vector<unsigned char>& bytes) {
    if (isGlb(bytes)) return;
    const auto starts = [&](std::initializer_list<unsigned char> magic) {
        return bytes.size() >= magic.size() && std::equal(magic.begin(), magic.end(), bytes.begin());
    };
    std::size_t i = starts({0xEF, 0xBB, 0xBF}) ? 3 : 0;
    while (i < bytes.size() && (bytes[i] == ' ' || bytes[i] == '\t' || bytes[i] == '\n' || bytes[i] == '\r'))
        ++i;
    if (i < bytes.size() && bytes[i] == '{') return;
    std::string what;
    if (bytes.empty() || i == bytes.size())
        what = "the file is empty";
    else if (starts({0x76, 0x2F, 0x31, 0x01}))
        what = "this is an OpenEXR image";
    else if (starts({0x89, 'P', 'N', 'G'}))
        what = "this is a PNG image";
    else if (starts({0xFF, 0xD8, 0xFF}))
        what = "this is a JPEG image";
    else {
        char byte[8];
        std::snprintf(byte, sizeof byte, "0x%02X", static_cast<unsigned>(bytes[i]));
        what = std::string("it starts with byte ") + byte + " at offset " + std::to_string(i);
    }
    throw Error("not a glTF 2.0 file (a .gltf is a JSON object, a .glb starts with \"glTF\"): " + what);
}

// The checks of the file's JSON (precheckJson) and the estimate of what loading it costs;
// an empty estimate if the JSON is not parseable (tinygltf reports that).
SceneEstimate precheck(const std::vector<unsigned char>& jsonBytes) {
    refuseNonGltf(jsonBytes);
    return gltf::precheckJson(jsonText(jsonBytes, isGlb(jsonBytes))).value_or(SceneEstimate{});
}

// LoadOptions::memoryBudget, else the machine's memory (0 if unknown).
std::uint64_t memoryBudget(const LoadOptions& opts) {
    return opts.memoryBudget != 0 ? opts.memoryBudget : physicalMemory();
}

// Refuses a scene beyond the loader's limits or the caller's (LoadOptions::checkEstimate).
void refuseBeyondLimits(const SceneEstimate& e, const LoadOptions& opts) {
    if (e.vertices > gltf::kMaxSceneVertices)
        throw Error("the scene has " + std::to_string(e.vertices) +
                    " vertices after instancing, more than the limit " +
                    std::to_string(gltf::kMaxSceneVertices));
    const std::uint64_t budget = memoryBudget(opts);
    if (budget != 0 && e.bytes > budget)
        throw Error("loading the scene (" + std::to_string(e.triangles) + " triangles, " +
                    std::to_string(e.vertices) + " vertices after instancing) needs about " +
                    gibibytes(e.bytes) + ", more than the memory budget of " + gibibytes(budget) +
                    (opts.memoryBudget != 0 ? "" : " (" + availableMemoryText(budget) + ")"));
    if (opts.checkEstimate) opts.checkEstimate(e);
}

// Refuses a scene whose size single precision cannot render (see kMaxSceneExtent).
void checkSceneExtent(const Scene& scene) {
    if (scene.triangles.empty()) return;
    const Bounds b = scene.bounds();
    const glm::vec3 size = b.max - b.min;
    const double extent = std::max({size.x, size.y, size.z});
    if (extent >= gltf::kMinSceneExtent && extent <= gltf::kMaxSceneExtent) return;
    char text[200];
    std::snprintf(text, sizeof text,
                  "the scene is %.3g units across; gdpt renders scenes from %.2g to %.2g units across "
                  "(single-precision triangle normals and areas), so scale it into that range",
                  extent, gltf::kMinSceneExtent, gltf::kMaxSceneExtent);
    throw Error(text);
}

}  // namespace
}  // namespace gltf

struct GltfAsset::Impl {
    std::string path;
    LoadOptions opts;
    SceneEstimate estimate;
    tinygltf::Model model;
    // What every instance shares: materials, textures, the unsupported-feature notes.
    Scene base;
    std::map<std::pair<int, bool>, int> textureCache;
    int defaultMaterial = -1;
    std::vector<int> roots;
    std::vector<Animation> animations;

    void parse();
    [[nodiscard]] Scene instance(int animation, double time) const;
};

void GltfAsset::Impl::parse() {
    // The JSON alone first: its checks and the estimate come before the parser, a .glb's BIN
    // chunk and any external buffer are read, and before anything is allocated per element.
    std::vector<unsigned char> bytes = gltf::readFile(path, /*jsonOnly=*/true);
    estimate = gltf::precheck(bytes);
    gltf::refuseBeyondLimits(estimate, opts);
    std::optional<Progress> progress;
    if (!opts.quiet && estimate.triangles >= opts.progressTriangles) {
        progress.emplace("reading " + path, 1.0, false);
        progress->update(0.0, "reading buffers");
    }
    const bool binary = gltf::isGlb(bytes);
    if (binary) bytes = gltf::readFile(path, /*jsonOnly=*/false);

    tinygltf::TinyGLTF parser;
    // Images get the memory budget that the geometry leaves (see ImageDecodeContext).
    const std::uint64_t budget = gltf::memoryBudget(opts);
    gltf::ImageDecodeContext imageDecode{&model, budget == 0               ? ~std::uint64_t{0}
                                                 : budget > estimate.bytes ? budget - estimate.bytes
                                                                           : 0};
    parser.SetImageLoader(&gltf::decodeImage, &imageDecode);
    parser.SetFsCallbacks({&tinygltf::FileExists, &tinygltf::ExpandFilePath, &gltf::readExternalFile,
                           &tinygltf::WriteWholeFile, nullptr});
    std::string err, warn;
    std::string baseDir = std::filesystem::path(path).parent_path().string();
    if (baseDir.empty()) baseDir = ".";
    const bool ok =
        binary ? parser.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(),
                                             static_cast<unsigned int>(bytes.size()), baseDir)
               : parser.LoadASCIIFromString(&model, &err, &warn, reinterpret_cast<const char*>(bytes.data()),
                                            static_cast<unsigned int>(bytes.size()), baseDir);
    if (!ok) throw Error("glTF parse error: " + gltf::oneLine(err.empty() ? "unknown error" : err));
    bytes = {};
    throwIfInterrupted("loading");  // SIGINT/SIGTERM (util/interrupt.h): between the stages

    base.sourcePath = path;
    gltf::Context ctx{model, base, {}, -1};
    if (!warn.empty()) ctx.unsupported("tinygltf warning: " + gltf::oneLine(warn));
    gltf::checkExtensions(ctx);
    gltf::convertMaterials(ctx);
    textureCache = ctx.textureCache;
    defaultMaterial = ctx.defaultMaterial;
    roots = gltf::sceneRoots(model, gltf::checkNodeGraph(model));
    animations = gltf::readAnimations(ctx);
    if (progress) progress->finish("parsed");
}

Scene GltfAsset::Impl::instance(int animation, double time) const {
    std::map<int, NodePose> pose;
    if (animation >= 0) pose = poseAt(animations.at(static_cast<std::size_t>(animation)), time);
    Scene scene = base;
    gltf::Context ctx{model, scene, textureCache, defaultMaterial};
    std::optional<Progress> progress;
    if (!opts.quiet && estimate.triangles >= opts.progressTriangles)
        progress.emplace("loading " + path, static_cast<double>(estimate.triangles), false);

    // Depth-first traversal with an explicit stack (deep hierarchies must not overflow
    // the call stack); children are pushed in reverse so the order matches recursion.
    std::vector<gltf::MeshInstance> instances;
    std::vector<std::pair<int, glm::dmat4>> stack;
    for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.emplace_back(*it, glm::dmat4(1.0));
    while (!stack.empty()) {
        const auto [index, parentWorld] = stack.back();
        stack.pop_back();
        const tinygltf::Node& node = model.nodes[static_cast<std::size_t>(index)];
        try {
            const auto posed = pose.find(index);
            const glm::dmat4 local = gltf::localMatrix(node, posed == pose.end() ? nullptr : &posed->second);
            const glm::dmat4 world = parentWorld * local;
            if (node.mesh >= 0) {
                if (static_cast<std::size_t>(node.mesh) >= model.meshes.size())
                    throw Error("mesh " + std::to_string(node.mesh) + " out of range (file has " +
                                std::to_string(model.meshes.size()) + " meshes)");
                instances.push_back({node.mesh, index, world});
            }
            if (node.camera >= 0) gltf::addCamera(ctx, node, world);
            if (node.skin >= 0) ctx.unsupported("skins (meshes rendered in their bind pose)");
            if (!node.weights.empty()) ctx.unsupported("morph target weights");
            for (const auto& [name, value] : node.extensions) {
                if (name == "KHR_lights_punctual")
                    gltf::addLight(ctx, value, world);
                else
                    ctx.unsupported("node extension " + name);
            }
            for (auto c = node.children.rbegin(); c != node.children.rend(); ++c)
                stack.emplace_back(*c, world);
        } catch (const Error& e) {
            throw e.withContext(gltf::elementName("node", index, node.name));
        }
    }

    // Normals/uvs are all-or-nothing per scene (see gltf_loader.h).
    bool anyNormals = false, anyUvs = false;
    for (const auto& inst : instances)
        for (const auto& prim : model.meshes[static_cast<std::size_t>(inst.mesh)].primitives) {
            anyNormals = anyNormals || prim.attributes.count("NORMAL") > 0;
            anyUvs = anyUvs || prim.attributes.count("TEXCOORD_0") > 0;
        }
    // The estimate bounds what the instances add (fewer when triangles are degenerate).
    reserveHuge(scene.positions, static_cast<std::size_t>(estimate.vertices));
    if (anyNormals) reserveHuge(scene.normals, static_cast<std::size_t>(estimate.vertices));
    if (anyUvs) reserveHuge(scene.uvs, static_cast<std::size_t>(estimate.vertices));
    reserveHuge(scene.triangles, static_cast<std::size_t>(estimate.triangles));
    reserveHuge(scene.triangleMaterial, static_cast<std::size_t>(estimate.triangles));
    for (const auto& inst : instances) {
        throwIfInterrupted("loading");
        gltf::addMeshInstance(ctx, inst, anyNormals, anyUvs);
        if (progress)
            progress->update(static_cast<double>(scene.triangles.size()),
                             std::to_string(scene.triangles.size()) + " triangles");
    }
    if (progress) progress->finish(std::to_string(scene.triangles.size()) + " triangles");
    gltf::checkSceneExtent(scene);
    return scene;
}

namespace {

// Runs `f`, giving every error the file's name (and turning foreign exceptions into ours).
template <typename F>
auto withFileContext(const std::string& path, F&& f) -> decltype(f()) {
    try {
        return f();
    } catch (const Interrupted&) {
        throw;  // not a problem of the file
    } catch (const UsageError&) {
        throw;
    } catch (const Error& e) {
        throw e.withContext(path);
    } catch (const std::bad_alloc&) {
        throw Error(path + ": out of memory while loading");
    } catch (const std::exception& e) {
        // tinygltf or the standard library threw something other than our errors.
        throw Error(path + ": " + e.what());
    }
}

}  // namespace

GltfAsset::GltfAsset(const std::string& path, const LoadOptions& opts) : impl_(std::make_unique<Impl>()) {
    impl_->path = path;
    impl_->opts = opts;
    withFileContext(path, [&] { impl_->parse(); });
}

GltfAsset::~GltfAsset() = default;
GltfAsset::GltfAsset(GltfAsset&&) noexcept = default;
GltfAsset& GltfAsset::operator=(GltfAsset&&) noexcept = default;

const std::string& GltfAsset::path() const {
    return impl_->path;
}

const std::vector<Animation>& GltfAsset::animations() const {
    return impl_->animations;
}

int GltfAsset::findAnimation(const std::string& nameOrIndex) const {
    const auto& list = impl_->animations;
    for (std::size_t i = 0; i < list.size(); ++i)
        if (list[i].name == nameOrIndex) return static_cast<int>(i);
    const bool digits =
        !nameOrIndex.empty() && nameOrIndex.size() < 10 &&
        std::all_of(nameOrIndex.begin(), nameOrIndex.end(), [](char c) { return c >= '0' && c <= '9'; });
    if (digits && std::stoul(nameOrIndex) < list.size()) return std::stoi(nameOrIndex);
    std::string known;
    for (std::size_t i = 0; i < list.size(); ++i)
        known +=
            (i ? ", " : "") + std::to_string(i) + (list[i].name.empty() ? "" : " '" + list[i].name + "'");
    throw UsageError("--animation " + nameOrIndex + ": " + impl_->path +
                     (list.empty() ? " has no animations" : " has no such animation (it has " + known + ")"));
}

Scene GltfAsset::instance(int animation, double time) const {
    return withFileContext(impl_->path, [&] { return impl_->instance(animation, time); });
}

Scene loadGltf(const std::string& path, const LoadOptions& opts) {
    return GltfAsset(path, opts).instance();
}

SceneEstimate estimateGltf(const std::string& path) {
    try {
        return gltf::precheck(gltf::readFile(path, /*jsonOnly=*/true));
    } catch (const Error& e) {
        throw e.withContext(path);
    } catch (const std::bad_alloc&) {
        throw Error(path + ": out of memory while reading its JSON");
    }
}

Camera defaultCamera(const Scene& scene) {
    Camera cam;
    cam.name = "default";
    cam.yfov = glm::radians(45.0f);
    const Bounds b = scene.bounds();
    if (b.empty()) return cam;
    const glm::vec3 centre = 0.5f * (b.min + b.max);
    const float radius = std::max(0.5f * glm::length(b.max - b.min), 1e-3f);
    // The bounding sphere fits the vertical field of view at distance r / sin(yfov/2).
    cam.position = centre + glm::vec3(0.0f, 0.0f, radius / std::sin(0.5f * cam.yfov));
    cam.forward = glm::vec3(0.0f, 0.0f, -1.0f);
    cam.up = glm::vec3(0.0f, 1.0f, 0.0f);
    return cam;
}

std::string describeScene(const Scene& scene) {
    std::ostringstream os;
    const Bounds b = scene.bounds();
    os << (scene.sourcePath.empty() ? "(generated)" : scene.sourcePath) << ": " << scene.triangles.size()
       << " triangles, " << scene.positions.size() << " vertices, " << scene.materials.size()
       << " materials, " << scene.textures.size() << " textures, " << scene.punctualLights.size()
       << " punctual lights, " << scene.cameras.size() << " cameras";
    if (!b.empty())
        os << "\n  bounds (" << b.min.x << ", " << b.min.y << ", " << b.min.z << ") - (" << b.max.x << ", "
           << b.max.y << ", " << b.max.z << ")";
    for (const auto& u : scene.unsupported) os << "\n  unsupported: " << u;
    return os.str();
}

std::string describeAnimations(const std::vector<Animation>& animations) {
    std::ostringstream os;
    for (std::size_t i = 0; i < animations.size(); ++i) {
        const Animation& a = animations[i];
        char duration[32];
        std::snprintf(duration, sizeof duration, "%.4g s", a.duration());
        os << (i ? "\n" : "") << "animation " << i << (a.name.empty() ? "" : " '" + a.name + "'") << ": "
           << duration << ", " << a.channels.size() << " channel" << (a.channels.size() == 1 ? "" : "s");
        for (const auto& c : a.channels)
            os << "\n  " << c.target << " (" << interpolationName(c.interpolation) << ", " << c.times.size()
               << " keys, " << c.times.front() << " to " << c.times.back() << " s)";
    }
    return os.str();
}

}  // namespace gdpt
