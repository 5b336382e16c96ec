// gltf_precheck.cpp — checks that need only the JSON text of a glTF file, made before
// tinygltf parses it, so that hostile input is refused before it costs stack or memory:
//   1. nesting depth, by a linear scan (tinygltf and nlohmann's dump recurse per level);
//   2. required extensions (glTF 2.0 §3.12);
//   3. bufferView strides (glTF 2.0 §5.11.4: 4..252, a multiple of 4, vertex attributes only);
//   4. every accessor's count, and its byte range against its bufferView and buffer (§3.6.2);
//   5. zero-filled accessors (no bufferView) against kZeroFilledAllowance;
//   6. the instanced scene's size (SceneEstimate) from the default scene's node hierarchy.
// The JSON is parsed once more by tinygltf afterwards; parsing it here keeps only the
// structural top-level members. Checks skip what they cannot interpret (wrong types, missing
// members), leaving those errors to tinygltf and the loader, so the messages stay the same.
#include <algorithm>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "scene/gltf_internal.h"

namespace gdpt::gltf {
namespace {

using nlohmann::json;

const std::set<std::string> kSupportedExtensions = {
    "KHR_materials_emissive_strength", "KHR_materials_specular", "KHR_materials_ior", "KHR_lights_punctual"};
// Geometry we cannot decode at all.
const std::set<std::string> kCompressionExtensions = {"KHR_draco_mesh_compression", "EXT_meshopt_compression",
                                                      "KHR_meshopt_compression"};

// Top-level members the checks read; the rest of the document is skipped while parsing, and
// so are the URIs of buffers and images (data URIs can be most of the file).
const std::set<std::string> kStructuralMembers = {"extensionsRequired",
                                                  "buffers",
                                                  "bufferViews",
                                                  "accessors",
                                                  "images",
                                                  "meshes",
                                                  "nodes",
                                                  "scenes",
                                                  "scene"};

// Saturating arithmetic: estimates of hostile files must not wrap around.
std::uint64_t satAdd(std::uint64_t a, std::uint64_t b) {
    std::uint64_t r = 0;
    return __builtin_add_overflow(a, b, &r) ? UINT64_MAX : r;
}
std::uint64_t satMul(std::uint64_t a, std::uint64_t b) {
    std::uint64_t r = 0;
    return __builtin_mul_overflow(a, b, &r) ? UINT64_MAX : r;
}

void checkJsonDepth(std::string_view text) {
    int depth = 0;
    bool inString = false;
    for (std::size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (inString) {
            if (c == '\\')
                ++i;  // an escaped character never ends the string
            else if (c == '"')
                inString = false;
        } else if (c == '"') {
            inString = true;
        } else if (c == '{' || c == '[') {
            if (++depth > kMaxJsonDepth)
                throw Error("JSON nests arrays and objects deeper than " + std::to_string(kMaxJsonDepth) +
                            " levels (at byte " + std::to_string(i) +
                            "); gdpt refuses such files (glTF itself needs about 10)");
        } else if ((c == '}' || c == ']') && depth > 0) {
            --depth;
        }
    }
}

// Member `key` of object `o`, or null.
const json* member(const json& o, const char* key) {
    if (!o.is_object()) return nullptr;
    const auto it = o.find(key);
    return it == o.end() ? nullptr : &*it;
}

// The array member `key` of `o`, or an empty array.
const json& arrayMember(const json& o, const char* key) {
    static const json kEmpty = json::array();
    const json* v = member(o, key);
    return v != nullptr && v->is_array() ? *v : kEmpty;
}

std::optional<std::uint64_t> unsignedMember(const json& o, const char* key) {
    const json* v = member(o, key);
    if (v == nullptr || !v->is_number_unsigned()) return std::nullopt;
    return v->get<std::uint64_t>();
}

// An index member (glTFid): a non-negative integer, or nothing.
std::optional<std::size_t> indexMember(const json& o, const char* key) {
    const auto v = unsignedMember(o, key);
    if (!v || *v > (1ull << 31)) return std::nullopt;
    return static_cast<std::size_t>(*v);
}

std::string nameOf(const json& o) {
    const json* v = member(o, "name");
    return v != nullptr && v->is_string() ? v->get<std::string>() : std::string();
}

int componentBytes(std::uint64_t componentType) {
    switch (componentType) {
        case 5120:  // BYTE
        case 5121:  // UNSIGNED_BYTE
            return 1;
        case 5122:  // SHORT
        case 5123:  // UNSIGNED_SHORT
            return 2;
        case 5125:  // UNSIGNED_INT
        case 5126:  // FLOAT
            return 4;
        default:
            return 0;
    }
}

// Bytes of one element of an accessor, or 0 if its type or componentType is not valid glTF.
// Matrix columns start on 4-byte boundaries (glTF 2.0 §3.6.2.4 "Data Alignment").
std::uint64_t elementBytes(const json& accessor) {
    const auto ct = unsignedMember(accessor, "componentType");
    const json* type = member(accessor, "type");
    if (!ct || type == nullptr || !type->is_string()) return 0;
    const std::uint64_t c = std::uint64_t(componentBytes(*ct));
    const std::string t = type->get<std::string>();
    if (t == "SCALAR") return c;
    if (t == "VEC2") return 2 * c;
    if (t == "VEC3") return 3 * c;
    if (t == "VEC4") return 4 * c;
    const std::uint64_t n = t == "MAT2" ? 2 : t == "MAT3" ? 3 : t == "MAT4" ? 4 : 0;
    return n * ((n * c + 3) / 4 * 4);
}

class Prechecker {
public:
    explicit Prechecker(const json& doc)
        : doc_(doc),
          buffers_(arrayMember(doc, "buffers")),
          views_(arrayMember(doc, "bufferViews")),
          accessors_(arrayMember(doc, "accessors")),
          meshes_(arrayMember(doc, "meshes")),
          nodes_(arrayMember(doc, "nodes")),
          labels_(accessors_.size()),
          zeroFilledCounted_(accessors_.size(), false) {
        for (const json& b : buffers_)
            if (const auto n = unsignedMember(b, "byteLength")) bufferBytes_ = satAdd(bufferBytes_, *n);
    }

    SceneEstimate run() {
        checkStrides();
        labelAccessors();
        for (std::size_t i = 0; i < accessors_.size(); ++i) checkAccessor(i);
        return estimate();
    }

private:
    // The label of accessor i in messages: its first use, e.g. "mesh 'Floor' primitive 2:
    // accessor 7 (POSITION)", else "accessor 7".
    const std::string& label(std::size_t i) {
        if (labels_[i].empty()) labels_[i] = "accessor " + std::to_string(i);
        return labels_[i];
    }

    void checkStrides() const {
        for (std::size_t i = 0; i < views_.size(); ++i) {
            const json* stride = member(views_[i], "byteStride");
            if (stride == nullptr) continue;
            const bool valid = stride->is_number_unsigned() && stride->get<std::uint64_t>() >= 4 &&
                               stride->get<std::uint64_t>() <= 252 && stride->get<std::uint64_t>() % 4 == 0;
            if (!valid)
                throw Error(elementName("bufferView", static_cast<int>(i), nameOf(views_[i])) +
                            ": byteStride " + stride->dump() +
                            " is not a multiple of 4 in [4, 252] (glTF 2.0 §5.11.4 bufferView.byteStride)");
        }
    }

    std::uint64_t strideOf(std::size_t view) const {
        return unsignedMember(views_[view], "byteStride").value_or(0);
    }

    // Refuses a byteStride on a bufferView holding `what` (not vertex attributes): "Buffer views
    // with other types of data MUST NOT define byteStride" (glTF 2.0 §5.11.4).
    void forbidStride(std::size_t view, const std::string& what) const {
        if (view >= views_.size() || strideOf(view) == 0) return;
        throw Error(elementName("bufferView", static_cast<int>(view), nameOf(views_[view])) + " holds " +
                    what + " but defines byteStride " + std::to_string(strideOf(view)) +
                    ", which only vertex attributes may (glTF 2.0 §5.11.4)");
    }

    void labelAccessors() {
        for (std::size_t m = 0; m < meshes_.size(); ++m) {
            const json& prims = arrayMember(meshes_[m], "primitives");
            for (std::size_t p = 0; p < prims.size(); ++p) {
                const std::string prim = elementName("mesh", static_cast<int>(m), nameOf(meshes_[m])) +
                                         " primitive " + std::to_string(p);
                auto use = [&](std::size_t a, const std::string& role) {
                    if (a < labels_.size() && labels_[a].empty())
                        labels_[a] = prim + ": accessor " + std::to_string(a) + " (" + role + ")";
                };
                if (const auto idx = indexMember(prims[p], "indices")) {
                    use(*idx, "indices");
                    if (*idx < accessors_.size())
                        if (const auto view = indexMember(accessors_[*idx], "bufferView"))
                            forbidStride(*view, "the indices of " + prim);
                }
                if (const json* attributes = member(prims[p], "attributes");
                    attributes && attributes->is_object())
                    for (const auto& [name, value] : attributes->items())
                        if (value.is_number_unsigned()) use(value.get<std::size_t>(), name);
            }
        }
        for (const json& image : arrayMember(doc_, "images"))
            if (const auto view = indexMember(image, "bufferView")) forbidStride(*view, "an image");
    }

    // Checks that `count` elements of `elementSize` bytes, `stride` apart from `offset` in
    // bufferView `view`, lie inside the view, and the view inside its buffer (as declared;
    // tinygltf checks the declared byteLength against the data it loads).
    void checkRange(std::size_t view, std::uint64_t offset, std::uint64_t count, std::uint64_t elementSize,
                    std::uint64_t stride, const std::string& what) const {
        if (view >= views_.size())
            throw Error(what + ": bufferView " + std::to_string(view) + " out of range (file has " +
                        std::to_string(views_.size()) + " bufferViews)");
        const json& bv = views_[view];
        const auto length = unsignedMember(bv, "byteLength");
        const auto buffer = indexMember(bv, "buffer");
        if (!length || !buffer) return;  // tinygltf reports the malformed bufferView
        if (*buffer >= buffers_.size())
            throw Error(what + ": bufferView " + std::to_string(view) + ": buffer " +
                        std::to_string(*buffer) + " out of range (file has " +
                        std::to_string(buffers_.size()) + " buffers)");
        const std::uint64_t viewStart = unsignedMember(bv, "byteOffset").value_or(0);
        const std::uint64_t viewEnd = satAdd(viewStart, *length);
        const auto bufferLength = unsignedMember(buffers_[*buffer], "byteLength");
        if (bufferLength && viewEnd > *bufferLength)
            throw Error(what + ": bufferView " + std::to_string(view) + " spans bytes [" +
                        std::to_string(viewStart) + ", " + std::to_string(viewEnd) + ") but buffer " +
                        std::to_string(*buffer) + " has only " + std::to_string(*bufferLength) +
                        " bytes (missing or short buffer)");
        if (count == 0) return;
        if (stride < elementSize)
            throw Error(what + ": bufferView " + std::to_string(view) + " byteStride " +
                        std::to_string(stride) + " is smaller than the element size " +
                        std::to_string(elementSize));
        // offset + stride * (count - 1) + elementSize <= byteLength (glTF 2.0 §3.6.2.4).
        const std::uint64_t end = satAdd(satAdd(offset, satMul(stride, count - 1)), elementSize);
        if (end > *length)
            throw Error(what + " needs bytes [" + std::to_string(offset) + ", " + std::to_string(end) +
                        ") of bufferView " + std::to_string(view) + ", which has only " +
                        std::to_string(*length) + " bytes");
    }

    void checkAccessor(std::size_t i) {
        const json& a = accessors_[i];
        const auto count = unsignedMember(a, "count");
        if (!count) return;  // tinygltf reports a missing or negative count
        if (*count > kMaxAccessorCount)
            throw Error(label(i) + " has count " + std::to_string(*count) + ", more than the limit " +
                        std::to_string(kMaxAccessorCount));
        const std::uint64_t size = elementBytes(a);
        if (size == 0) return;  // the loader reports the type
        if (const auto view = indexMember(a, "bufferView")) {
            const std::uint64_t stride =
                *view < views_.size() && strideOf(*view) != 0 ? strideOf(*view) : size;
            checkRange(*view, unsignedMember(a, "byteOffset").value_or(0), *count, size, stride, label(i));
        }
        const json* sparse = member(a, "sparse");
        if (sparse == nullptr) return;
        const auto n = unsignedMember(*sparse, "count");
        const json* indices = member(*sparse, "indices");
        const json* values = member(*sparse, "values");
        if (!n || indices == nullptr || values == nullptr) return;
        if (*n > *count)
            throw Error(label(i) + " sparse count " + std::to_string(*n) + " is out of [0, " +
                        std::to_string(*count) + "]");
        const auto indexView = indexMember(*indices, "bufferView");
        const auto valueView = indexMember(*values, "bufferView");
        const std::uint64_t indexSize =
            std::uint64_t(componentBytes(unsignedMember(*indices, "componentType").value_or(0)));
        if (indexView && indexSize != 0) {
            forbidStride(*indexView, "the sparse indices of " + label(i));
            checkRange(*indexView, unsignedMember(*indices, "byteOffset").value_or(0), *n, indexSize,
                       indexSize, label(i) + " sparse indices");
        }
        if (valueView) {
            forbidStride(*valueView, "the sparse values of " + label(i));
            checkRange(*valueView, unsignedMember(*values, "byteOffset").value_or(0), *n, size, size,
                       label(i) + " sparse values");
        }
    }

    // Count of accessor `a` (0 if it is missing or malformed; the loader reports that).
    std::uint64_t countOf(std::optional<std::size_t> a) const {
        return a && *a < accessors_.size() ? unsignedMember(accessors_[*a], "count").value_or(0) : 0;
    }

    // Accessor `a` is read by the loader: if it has no bufferView its zeros are created, which
    // is allowed up to the file's buffer bytes plus kZeroFilledAllowance.
    void noteRead(std::optional<std::size_t> a) {
        if (!a || *a >= accessors_.size() || zeroFilledCounted_[*a]) return;
        const json& acc = accessors_[*a];
        if (member(acc, "bufferView") != nullptr) return;
        zeroFilledCounted_[*a] = true;
        zeroFilledBytes_ = satAdd(zeroFilledBytes_, satMul(countOf(a), elementBytes(acc)));
        const std::uint64_t allowed = satAdd(bufferBytes_, kZeroFilledAllowance);
        if (zeroFilledBytes_ > allowed)
            throw Error(label(*a) + " has no bufferView: its " + std::to_string(countOf(a)) +
                        " elements would be zeros that the file does not hold; gdpt creates at most " +
                        std::to_string(allowed) + " bytes of such data (the file's " +
                        std::to_string(bufferBytes_) + " buffer bytes plus " +
                        std::to_string(kZeroFilledAllowance) + ")");
    }

    // Instances of each mesh in the default scene (the roots the loader renders: the scene's
    // nodes, or every root node without scenes), each node counted once.
    std::vector<std::uint64_t> meshInstances() const {
        std::vector<std::size_t> roots;
        const json& scenes = arrayMember(doc_, "scenes");
        if (!scenes.empty()) {
            const std::size_t s = indexMember(doc_, "scene").value_or(0);
            if (s < scenes.size())
                for (const json& r : arrayMember(scenes[s], "nodes"))
                    if (r.is_number_unsigned()) roots.push_back(r.get<std::size_t>());
        } else {
            std::vector<bool> child(nodes_.size(), false);
            for (const json& n : nodes_)
                for (const json& c : arrayMember(n, "children"))
                    if (c.is_number_unsigned() && c.get<std::size_t>() < child.size())
                        child[c.get<std::size_t>()] = true;
            for (std::size_t i = 0; i < nodes_.size(); ++i)
                if (!child[i]) roots.push_back(i);
        }
        std::vector<std::uint64_t> instances(meshes_.size(), 0);
        std::vector<bool> seen(nodes_.size(), false);
        std::vector<std::size_t> stack(roots.begin(), roots.end());
        while (!stack.empty()) {
            const std::size_t n = stack.back();
            stack.pop_back();
            if (n >= nodes_.size() || seen[n]) continue;
            seen[n] = true;
            if (const auto mesh = indexMember(nodes_[n], "mesh"); mesh && *mesh < meshes_.size())
                ++instances[*mesh];
            for (const json& c : arrayMember(nodes_[n], "children"))
                if (c.is_number_unsigned()) stack.push_back(c.get<std::size_t>());
        }
        return instances;
    }

    // What the loader builds from the instanced meshes (gltf_geometry.cpp addMeshInstance):
    // per vertex a position, a normal if any primitive has normals, a uv if any has
    // TEXCOORD_0; per triangle three indices and a material. A primitive without normals in a
    // scene with normals gets three own vertices per triangle (flat normals). While a
    // primitive is converted, its accessors' data and world-space copies exist as well.
    SceneEstimate estimate() {
        const std::vector<std::uint64_t> instances = meshInstances();
        bool normals = false, uvs = false;
        for (std::size_t m = 0; m < meshes_.size(); ++m)
            for (const json& prim : arrayMember(meshes_[m], "primitives"))
                if (const json* attributes = member(prim, "attributes"); attributes && instances[m] > 0) {
                    normals = normals || member(*attributes, "NORMAL") != nullptr;
                    uvs = uvs || member(*attributes, "TEXCOORD_0") != nullptr;
                }
        const std::uint64_t vertexBytes = 12 + (normals ? 12 : 0) + (uvs ? 8 : 0);
        constexpr std::uint64_t kTriangleBytes = 12 + 4;
        SceneEstimate out;
        std::uint64_t scene = 0, transient = 0;
        for (std::size_t m = 0; m < meshes_.size(); ++m) {
            if (instances[m] == 0) continue;
            for (const json& prim : arrayMember(meshes_[m], "primitives")) {
                const std::uint64_t mode = unsignedMember(prim, "mode").value_or(4);
                if (mode != 4 && mode != 5 && mode != 6) continue;  // not triangles: not read
                const json* attributes = member(prim, "attributes");
                if (attributes == nullptr) continue;
                const auto position = indexMember(*attributes, "POSITION");
                const auto normal = indexMember(*attributes, "NORMAL");
                const auto uv = indexMember(*attributes, "TEXCOORD_0");
                const auto indices = indexMember(prim, "indices");
                for (const auto& a : {position, normal, uv, indices}) noteRead(a);
                const std::uint64_t v = countOf(position);
                const std::uint64_t n = indices ? countOf(indices) : v;
                const std::uint64_t t = mode == 4 ? n / 3 : (n >= 3 ? n - 2 : 0);
                const std::uint64_t verts = normals && !normal ? satMul(3, t) : v;
                out.triangles = satAdd(out.triangles, satMul(instances[m], t));
                out.vertices = satAdd(out.vertices, satMul(instances[m], verts));
                scene = satAdd(scene, satMul(instances[m],
                                             satAdd(satMul(verts, vertexBytes), satMul(t, kTriangleBytes))));
                // Positions read and transformed, normals, uvs, indices, and the triangle list
                // (assembled and copied once).
                const std::uint64_t primitive = satAdd(satMul(v, 24 + (normal ? 12 : 0) + (uv ? 8 : 0)),
                                                       satAdd(satMul(n, 4), satMul(t, 24)));
                transient = std::max(transient, primitive);
            }
        }
        out.bytes = satAdd(scene, transient);
        return out;
    }

    const json& doc_;
    const json& buffers_;
    const json& views_;
    const json& accessors_;
    const json& meshes_;
    const json& nodes_;
    std::vector<std::string> labels_;
    std::vector<bool> zeroFilledCounted_;
    std::uint64_t bufferBytes_ = 0;
    std::uint64_t zeroFilledBytes_ = 0;
};

// Why a file whose extensionsRequired is `required` cannot be loaded (glTF 2.0 §3.12: a
// loader must not load a file that requires an extension it does not support), or nothing.
std::optional<std::string> requiredExtensionsError(const json& doc) {
    std::vector<std::string> missing;
    bool compression = false;
    for (const json& name : arrayMember(doc, "extensionsRequired")) {
        if (!name.is_string()) continue;
        const std::string ext = name.get<std::string>();
        if (supportedExtension(ext) || std::find(missing.begin(), missing.end(), ext) != missing.end())
            continue;
        missing.push_back(ext);
        compression = compression || kCompressionExtensions.count(ext) > 0;
    }
    if (missing.empty()) return std::nullopt;
    std::string list;
    for (const std::string& ext : missing) list += (list.empty() ? "" : ", ") + ext;
    std::string message = (missing.size() == 1 ? "required extension " : "required extensions ") + list +
                          (missing.size() == 1 ? " is" : " are") + " not supported by gdpt";
    if (compression) message += " (compressed geometry: decompress the file first)";
    return message;
}

}  // namespace

bool supportedExtension(const std::string& name) {
    return kSupportedExtensions.count(name) > 0;
}

std::optional<SceneEstimate> precheckJson(std::string_view text) {
    // First, before any parser: nlohmann's parser is iterative, but tinygltf's conversion of
    // the document recurses once per level.
    checkJsonDepth(text);
    const json::parser_callback_t structural = [](int depth, json::parse_event_t event, json& parsed) {
        if (event != json::parse_event_t::key) return true;
        if (depth == 1) return kStructuralMembers.count(parsed) > 0;
        return !(depth == 3 && parsed == "uri");  // members of buffers[i] and images[i]
    };
    const json doc = json::parse(text.begin(), text.end(), structural, /*allow_exceptions=*/false);
    if (doc.is_discarded() || !doc.is_object()) return std::nullopt;
    // Before the accessors: a compressed mesh's accessors have no bufferView, and the
    // message must name the extension rather than them.
    if (const auto message = requiredExtensionsError(doc)) throw Error(*message);
    return Prechecker(doc).run();
}

}  // namespace gdpt::gltf
