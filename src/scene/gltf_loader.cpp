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
