// gltf_geometry.cpp — checked accessor reads and the conversion of mesh primitives into
// world-space triangles of the flattened Scene.
//
// Every read is bounds-checked against its bufferView and buffer in 64-bit arithmetic, so
// no file can make the loader read outside the data tinygltf loaded (glTF 2.0 §3.6
// "Buffers and Buffer Views", §3.6.2 "Accessors").
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <numeric>

#include "scene/gltf_internal.h"
#include "util/huge_pages.h"

namespace gdpt::gltf {
namespace {

const char* typeName(int type) {
    switch (type) {
        case TINYGLTF_TYPE_SCALAR:
            return "SCALAR";
        case TINYGLTF_TYPE_VEC2:
            return "VEC2";
        case TINYGLTF_TYPE_VEC3:
            return "VEC3";
        case TINYGLTF_TYPE_VEC4:
            return "VEC4";
        case TINYGLTF_TYPE_MAT2:
            return "MAT2";
        case TINYGLTF_TYPE_MAT3:
            return "MAT3";
        case TINYGLTF_TYPE_MAT4:
            return "MAT4";
        default:
            return "unknown";
    }
}

const char* componentTypeName(int componentType) {
    switch (componentType) {
        case TINYGLTF_COMPONENT_TYPE_BYTE:
            return "BYTE";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
            return "UNSIGNED_BYTE";
        case TINYGLTF_COMPONENT_TYPE_SHORT:
            return "SHORT";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
            return "UNSIGNED_SHORT";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
            return "UNSIGNED_INT";
        case TINYGLTF_COMPONENT_TYPE_FLOAT:
            return "FLOAT";
        default:
            return "unknown";
    }
}

int componentSize(int componentType) {
    switch (componentType) {
        case TINYGLTF_COMPONENT_TYPE_BYTE:
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
            return 1;
        case TINYGLTF_COMPONENT_TYPE_SHORT:
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
            return 2;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
        case TINYGLTF_COMPONENT_TYPE_FLOAT:
            return 4;
        default:
            return 0;
    }
}

int componentCount(int type) {
    switch (type) {
        case TINYGLTF_TYPE_SCALAR:
            return 1;
        case TINYGLTF_TYPE_VEC2:
            return 2;
        case TINYGLTF_TYPE_VEC3:
            return 3;
        case TINYGLTF_TYPE_VEC4:
            return 4;
        default:
            return 0;  // matrices are never vertex attributes we read
    }
}

std::string accessorLabel(int accessor, const char* role) {
    return "accessor " + std::to_string(accessor) + " (" + role + ")";
}

// Reads one component as double; `normalized` maps integers to [0,1] or [-1,1] as in
// glTF 2.0 §3.11 (table "normalized integer to float": c/255, max(c/127,-1), ...).
double readComponent(const unsigned char* p, int componentType, bool normalized) {
    switch (componentType) {
        case TINYGLTF_COMPONENT_TYPE_FLOAT: {
            float v;
            std::memcpy(&v, p, 4);
            return v;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
            std::uint32_t v;
            std::memcpy(&v, p, 4);
            return v;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
            std::uint16_t v;
            std::memcpy(&v, p, 2);
            return normalized ? v / 65535.0 : v;
        }
        case TINYGLTF_COMPONENT_TYPE_SHORT: {
            std::int16_t v;
            std::memcpy(&v, p, 2);
            return normalized ? std::max(v / 32767.0, -1.0) : v;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
            return normalized ? *p / 255.0 : *p;
        case TINYGLTF_COMPONENT_TYPE_BYTE: {
            const auto v = static_cast<std::int8_t>(*p);
            return normalized ? std::max(v / 127.0, -1.0) : v;
        }
        default:
            return 0.0;
    }
}

// Returns a pointer to `count` elements of `elemSize` bytes, `stride` apart, starting at
// `byteOffset` inside bufferView `view`, after checking that all of them lie inside the
// view and the view inside its buffer.
const unsigned char* checkedRange(const tinygltf::Model& model, int view, std::uint64_t byteOffset,
                                  std::uint64_t count, std::uint64_t elemSize, std::uint64_t stride,
                                  const std::string& label) {
    if (view < 0 || static_cast<std::size_t>(view) >= model.bufferViews.size())
        throw Error(label + ": bufferView " + std::to_string(view) + " out of range (file has " +
                    std::to_string(model.bufferViews.size()) + " bufferViews)");
    const tinygltf::BufferView& bv = model.bufferViews[static_cast<std::size_t>(view)];
    const std::string bvLabel = label + ": bufferView " + std::to_string(view);
    if (bv.buffer < 0 || static_cast<std::size_t>(bv.buffer) >= model.buffers.size())
        throw Error(bvLabel + ": buffer " + std::to_string(bv.buffer) + " out of range (file has " +
                    std::to_string(model.buffers.size()) + " buffers)");
    const std::uint64_t bufferSize = model.buffers[static_cast<std::size_t>(bv.buffer)].data.size();
    const std::uint64_t viewEnd = std::uint64_t(bv.byteOffset) + std::uint64_t(bv.byteLength);
    if (viewEnd > bufferSize || viewEnd < bv.byteOffset)
        throw Error(bvLabel + " spans bytes [" + std::to_string(bv.byteOffset) + ", " +
                    std::to_string(viewEnd) + ") but buffer " + std::to_string(bv.buffer) + " has only " +
                    std::to_string(bufferSize) + " bytes (missing or short buffer)");
    if (count == 0) return nullptr;
    if (byteOffset > bv.byteLength || stride > (1ull << 32) || elemSize > stride)
        throw Error(label + ": byteOffset " + std::to_string(byteOffset) + " / stride " +
                    std::to_string(stride) + " do not fit bufferView " + std::to_string(view) + " of " +
                    std::to_string(bv.byteLength) + " bytes");
    // count <= kMaxAccessorCount and stride <= 2^32, so this cannot overflow 64 bits.
    const std::uint64_t needEnd = byteOffset + (count - 1) * stride + elemSize;
    if (needEnd > bv.byteLength)
        throw Error(label + " needs bytes [" + std::to_string(byteOffset) + ", " + std::to_string(needEnd) +
                    ") of bufferView " + std::to_string(view) + ", which has only " +
                    std::to_string(bv.byteLength) + " bytes");
    return model.buffers[static_cast<std::size_t>(bv.buffer)].data.data() + bv.byteOffset + byteOffset;
}

// Accessor `index` after every check against its bufferView, buffer and sparse storage:
// what readElements reads, with nothing allocated yet (precheckJson has checked the same on
// the JSON; these checks keep the readers safe on their own).
struct CheckedAccessor {
    std::string label;
    std::size_t count = 0;
    int components = 0;
    int componentType = 0;
    bool normalized = false;
    std::uint64_t stride = 0;
    const unsigned char* data = nullptr;  // first element; null: zeros (no bufferView) or count 0
    // Sparse substitution (§3.6.2.3): `sparseCount` indices of `sparseIndexType`, then as
    // many values.
    std::uint64_t sparseCount = 0;
    int sparseIndexType = 0;
    const unsigned char* sparseIndices = nullptr;
    const unsigned char* sparseValues = nullptr;
};

// Checks accessor `index`: its type against `expectedType`, its componentType against
// `allowedComponentTypes`, its count, and the byte ranges of its data and sparse storage.
CheckedAccessor checkAccessor(const tinygltf::Model& model, int index, const char* role, int expectedType,
                              std::initializer_list<int> allowedComponentTypes) {
    CheckedAccessor out;
    out.label = accessorLabel(index, role);
    const std::string& label = out.label;
    if (index < 0 || static_cast<std::size_t>(index) >= model.accessors.size())
        throw Error(label + " out of range (file has " + std::to_string(model.accessors.size()) +
                    " accessors)");
    const tinygltf::Accessor& acc = model.accessors[static_cast<std::size_t>(index)];
    if (acc.type != expectedType)
        throw Error(label + " has type " + typeName(acc.type) + ", expected " + typeName(expectedType));
    if (std::find(allowedComponentTypes.begin(), allowedComponentTypes.end(), acc.componentType) ==
        allowedComponentTypes.end()) {
        std::string allowed;
        for (int ct : allowedComponentTypes)
            allowed += std::string(allowed.empty() ? "" : " or ") + componentTypeName(ct);
        throw Error(label + " has componentType " + std::to_string(acc.componentType) + " (" +
                    componentTypeName(acc.componentType) + "), expected " + allowed);
    }
    if (acc.count > kMaxAccessorCount)
        throw Error(label + " has count " + std::to_string(acc.count) + ", more than the limit " +
                    std::to_string(kMaxAccessorCount));
    out.count = acc.count;
    out.components = componentCount(acc.type);
    out.componentType = acc.componentType;
    out.normalized = acc.normalized;
    const std::uint64_t elemSize =
        std::uint64_t(out.components) * std::uint64_t(componentSize(acc.componentType));
    out.stride = elemSize;

    if (acc.bufferView >= 0) {
        const auto& bv = model.bufferViews.size() > static_cast<std::size_t>(acc.bufferView)
                             ? model.bufferViews[static_cast<std::size_t>(acc.bufferView)]
                             : tinygltf::BufferView{};
        if (bv.byteStride != 0) out.stride = bv.byteStride;
        if (out.stride < elemSize)
            throw Error(label + ": bufferView " + std::to_string(acc.bufferView) + " byteStride " +
                        std::to_string(out.stride) + " is smaller than the element size " +
                        std::to_string(elemSize));
        out.data =
            checkedRange(model, acc.bufferView, acc.byteOffset, acc.count, elemSize, out.stride, label);
    }

    if (acc.sparse.isSparse) {
        const auto& sp = acc.sparse;
        const std::string spLabel = label + " sparse";
        const int idxType = sp.indices.componentType;
        if (idxType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
            idxType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
            idxType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
            throw Error(spLabel + " indices have componentType " + std::to_string(idxType) +
                        ", expected an unsigned integer type");
        if (sp.count < 0 || static_cast<std::uint64_t>(sp.count) > acc.count)
            throw Error(spLabel + " count " + std::to_string(sp.count) + " is out of [0, " +
                        std::to_string(acc.count) + "]");
        out.sparseCount = static_cast<std::uint64_t>(sp.count);
        out.sparseIndexType = idxType;
        const std::uint64_t idxSize = std::uint64_t(componentSize(idxType));
        out.sparseIndices =
            checkedRange(model, sp.indices.bufferView, std::uint64_t(std::max(sp.indices.byteOffset, 0)),
                         out.sparseCount, idxSize, idxSize, spLabel + " indices");
        out.sparseValues =
            checkedRange(model, sp.values.bufferView, std::uint64_t(std::max(sp.values.byteOffset, 0)),
                         out.sparseCount, elemSize, elemSize, spLabel + " values");
    }
    return out;
}

// Calls set(element, component, value) for the accessor's data (nothing for zeros), then
// for its sparse substitutions, which overwrite elements.
template <typename Set>
void readElements(const CheckedAccessor& a, Set&& set) {
    const std::uint64_t componentBytes = std::uint64_t(componentSize(a.componentType));
    if (a.data != nullptr)
        for (std::size_t i = 0; i < a.count; ++i)
            for (int c = 0; c < a.components; ++c)
                set(i, c,
                    readComponent(a.data + i * a.stride + std::uint64_t(c) * componentBytes, a.componentType,
                                  a.normalized));
    const std::uint64_t idxSize = std::uint64_t(componentSize(a.sparseIndexType));
    const std::uint64_t elemSize = std::uint64_t(a.components) * componentBytes;
    for (std::uint64_t k = 0; k < a.sparseCount; ++k) {
        const auto target = static_cast<std::uint64_t>(
            readComponent(a.sparseIndices + k * idxSize, a.sparseIndexType, false));
        if (target >= a.count)
            throw Error(a.label + " sparse index " + std::to_string(target) + " is out of range of " +
                        std::to_string(a.count) + " elements");
        for (int c = 0; c < a.components; ++c)
            set(static_cast<std::size_t>(target), c,
                readComponent(a.sparseValues + k * elemSize + std::uint64_t(c) * componentBytes,
                              a.componentType, a.normalized));
    }
}

const char* modeName(int mode) {
    switch (mode) {
        case TINYGLTF_MODE_POINTS:
            return "POINTS";
        case TINYGLTF_MODE_LINE:
            return "LINES";
        case TINYGLTF_MODE_LINE_LOOP:
            return "LINE_LOOP";
        case TINYGLTF_MODE_LINE_STRIP:
            return "LINE_STRIP";
        default:
            return "unknown";
    }
}

// Triangle list from an index list and topology, as glTF 2.0 §3.7.2.1 defines it:
// strips p_i = {v_i, v_{i+(1+i%2)}, v_{i+(2-i%2)}}, fans p_i = {v_{i+1}, v_{i+2}, v_0}.
// Triangles that repeat a vertex index have zero area (the usual strip-restart idiom) and
// are dropped.
std::vector<glm::uvec3> assembleTriangles(const std::vector<std::uint32_t>& idx, int mode) {
    std::vector<glm::uvec3> tris;
    const std::size_t n = idx.size();
    reserveHuge(tris, mode == TINYGLTF_MODE_TRIANGLES ? n / 3 : (n >= 2 ? n - 2 : 0));
    if (mode == TINYGLTF_MODE_TRIANGLES) {
        if (n % 3 != 0)
            throw Error("TRIANGLES primitive has " + std::to_string(n) +
                        " vertex indices, not a multiple of 3");
        for (std::size_t i = 0; i + 2 < n; i += 3) tris.emplace_back(idx[i], idx[i + 1], idx[i + 2]);
    } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
        for (std::size_t i = 0; i + 2 < n; ++i)
            tris.emplace_back(idx[i], idx[i + 1 + i % 2], idx[i + 2 - i % 2]);
    } else {  // TRIANGLE_FAN
        for (std::size_t i = 0; i + 2 < n; ++i) tris.emplace_back(idx[i + 1], idx[i + 2], idx[0]);
    }
    tris.erase(std::remove_if(tris.begin(), tris.end(),
                              [](const glm::uvec3& t) { return t.x == t.y || t.y == t.z || t.x == t.z; }),
               tris.end());
    return tris;
}

bool allFinite(const glm::dvec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// Notes vertex attributes that gdpt does not use (glTF 2.0 §3.7.2.1 attribute names).
void noteIgnoredAttributes(Context& ctx, const tinygltf::Primitive& prim) {
    for (const auto& [name, accessor] : prim.attributes) {
        (void)accessor;
        if (name == "POSITION" || name == "NORMAL" || name == "TEXCOORD_0") continue;
        if (name.rfind("TEXCOORD_", 0) == 0)
            ctx.unsupported("vertex attribute " + name + " (only TEXCOORD_0 is used)");
        else if (name.rfind("COLOR_", 0) == 0)
            ctx.unsupported("vertex colours (" + name + ")");
        else if (name.rfind("JOINTS_", 0) == 0 || name.rfind("WEIGHTS_", 0) == 0)
            ctx.unsupported("skinning attributes (" + name + "); rendered unskinned");
        else if (name == "TANGENT")
            ctx.unsupported("TANGENT attributes (normal mapping is not supported)");
        else
            ctx.unsupported("vertex attribute " + name);
    }
}

}  // namespace

std::vector<glm::vec3> readVec3(const tinygltf::Model& model, int accessor, const char* role) {
    const CheckedAccessor a =
        checkAccessor(model, accessor, role, TINYGLTF_TYPE_VEC3, {TINYGLTF_COMPONENT_TYPE_FLOAT});
    std::vector<glm::vec3> out =
        hugeVector<glm::vec3>(a.count);  // zeros where the accessor has no bufferView
    readElements(a, [&](std::size_t i, int c, double v) { out[i][c] = static_cast<float>(v); });
    for (std::size_t i = 0; i < out.size(); ++i)
        if (!std::isfinite(out[i].x) || !std::isfinite(out[i].y) || !std::isfinite(out[i].z))
            throw Error(a.label + " element " + std::to_string(i) + " is not finite");
    return out;
}

std::vector<glm::vec2> readTexcoords(const tinygltf::Model& model, int accessor, const char* role) {
    // §3.7.2.1: TEXCOORD_n is float, or normalized unsigned byte/short.
    const CheckedAccessor a =
        checkAccessor(model, accessor, role, TINYGLTF_TYPE_VEC2,
                      {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                       TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT});
    std::vector<glm::vec2> out = hugeVector<glm::vec2>(a.count);
    readElements(a, [&](std::size_t i, int c, double v) { out[i][c] = static_cast<float>(v); });
    for (std::size_t i = 0; i < out.size(); ++i)
        if (!std::isfinite(out[i].x) || !std::isfinite(out[i].y))
            throw Error(a.label + " element " + std::to_string(i) + " is not finite");
    return out;
}

std::vector<glm::dvec4> readKeyValues(const tinygltf::Model& model, int accessor, const char* role, int type,
                                      bool normalizedIntegers) {
    const std::initializer_list<int> floatOnly = {TINYGLTF_COMPONENT_TYPE_FLOAT};
    const std::initializer_list<int> withIntegers = {
        TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
        TINYGLTF_COMPONENT_TYPE_SHORT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT};
    const CheckedAccessor a =
        checkAccessor(model, accessor, role, type, normalizedIntegers ? withIntegers : floatOnly);
    if (a.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT && !a.normalized)
        throw Error(a.label +
                    " has integer components that are not normalized (glTF 2.0 §3.11 allows "
                    "only normalized integers for rotations)");
    std::vector<glm::dvec4> out(a.count, glm::dvec4(0.0));
    readElements(a, [&](std::size_t i, int c, double v) { out[i][c] = v; });
    return out;
}

std::vector<std::uint32_t> readIndices(const tinygltf::Model& model, int accessor) {
    const CheckedAccessor a =
        checkAccessor(model, accessor, "indices", TINYGLTF_TYPE_SCALAR,
                      {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                       TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT});
    if (a.normalized) throw Error(a.label + " must not be normalized");
    std::vector<std::uint32_t> out = hugeVector<std::uint32_t>(a.count);
    readElements(a, [&](std::size_t i, int, double v) { out[i] = static_cast<std::uint32_t>(v); });
    return out;
}

void addMeshInstance(Context& ctx, const MeshInstance& inst, bool sceneHasNormals, bool sceneHasUvs) {
    const tinygltf::Model& model = ctx.model;
    Scene& scene = ctx.scene;
    const tinygltf::Mesh& mesh = model.meshes[static_cast<std::size_t>(inst.mesh)];
    const std::string meshLabel = elementName("mesh", inst.mesh, mesh.name);

    // Normals transform with the inverse transpose; a mirroring transform (negative
    // determinant) reverses the winding, so we swap two indices to keep front faces
    // counter-clockwise in world space (§3.7.3 "the determinant ... is negative").
    const glm::dmat3 linear(inst.world);
    const double det = glm::determinant(linear);
    if (!std::isfinite(det) || std::abs(det) < 1e-300) {
        ctx.unsupported("node " + std::to_string(inst.node) +
                        " has a singular transform; its mesh is skipped");
        return;
    }
    const glm::dmat3 normalMatrix = glm::transpose(glm::inverse(linear));
    const bool flip = det < 0.0;

    for (std::size_t pi = 0; pi < mesh.primitives.size(); ++pi) {
        const tinygltf::Primitive& prim = mesh.primitives[pi];
        const std::string primLabel = meshLabel + " primitive " + std::to_string(pi);
        try {
            const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
            if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
                mode != TINYGLTF_MODE_TRIANGLE_FAN) {
                ctx.unsupported(primLabel + ": mode " + std::to_string(mode) + " (" + modeName(mode) +
                                "); only triangles are rendered");
                continue;
            }
            if (!prim.targets.empty()) ctx.unsupported("morph targets (" + meshLabel + ")");
            noteIgnoredAttributes(ctx, prim);

            const auto posIt = prim.attributes.find("POSITION");
            if (posIt == prim.attributes.end()) throw Error("has no POSITION attribute");
            const std::vector<glm::vec3> pos = readVec3(model, posIt->second, "POSITION");
            std::vector<glm::vec3> nrm;
            if (auto it = prim.attributes.find("NORMAL"); it != prim.attributes.end()) {
                nrm = readVec3(model, it->second, "NORMAL");
                if (nrm.size() != pos.size())
                    throw Error(accessorLabel(it->second, "NORMAL") + " has count " +
                                std::to_string(nrm.size()) + ", POSITION has " + std::to_string(pos.size()));
            }
            std::vector<glm::vec2> uv;
            if (auto it = prim.attributes.find("TEXCOORD_0"); it != prim.attributes.end()) {
                uv = readTexcoords(model, it->second, "TEXCOORD_0");
                if (uv.size() != pos.size())
                    throw Error(accessorLabel(it->second, "TEXCOORD_0") + " has count " +
                                std::to_string(uv.size()) + ", POSITION has " + std::to_string(pos.size()));
            }

            std::vector<std::uint32_t> idx;
            if (prim.indices >= 0) {
                idx = readIndices(model, prim.indices);
                for (std::size_t i = 0; i < idx.size(); ++i)
                    if (idx[i] >= pos.size())
                        throw Error(accessorLabel(prim.indices, "indices") + " element " + std::to_string(i) +
                                    " is " + std::to_string(idx[i]) + ", out of range of the " +
                                    std::to_string(pos.size()) + " vertices");
            } else {
                idx.resize(pos.size());
                std::iota(idx.begin(), idx.end(), 0u);
            }
            std::vector<glm::uvec3> tris = assembleTriangles(idx, mode);
            const std::uint32_t material = materialIndex(ctx, prim.material);

            // World-space vertices of this primitive, within the coordinates gdpt renders
            // (kMaxSceneExtent).
            std::vector<glm::vec3> wPos = hugeVector<glm::vec3>(pos.size());
            for (std::size_t i = 0; i < pos.size(); ++i) {
                const glm::dvec3 p = glm::dvec3(inst.world * glm::dvec4(glm::dvec3(pos[i]), 1.0));
                if (!allFinite(p))
                    throw Error("vertex " + std::to_string(i) + " overflows after the node transform");
                if (glm::any(glm::greaterThan(glm::abs(p), glm::dvec3(kMaxSceneExtent)))) {
                    char limit[64];
                    std::snprintf(limit, sizeof limit, "|x|, |y|, |z| <= %.2g", kMaxSceneExtent);
                    throw Error("vertex " + std::to_string(i) + " is at (" + formatNumber(p.x) + ", " +
                                formatNumber(p.y) + ", " + formatNumber(p.z) +
                                ") after the node transform, outside the coordinates gdpt renders (" + limit +
                                "; single-precision triangle normals and areas); scale the scene down");
                }
                wPos[i] = glm::vec3(p);
            }
            if (flip)
                for (auto& t : tris) std::swap(t.y, t.z);

            const bool flat = sceneHasNormals && nrm.empty();
            const std::size_t newVerts = flat ? tris.size() * 3 : pos.size();
            if (scene.positions.size() + newVerts > kMaxSceneVertices)
                throw Error("the scene exceeds " + std::to_string(kMaxSceneVertices) + " vertices");
            const auto base = static_cast<std::uint32_t>(scene.positions.size());

            if (flat) {
                // Flat normals: three own vertices per triangle carrying the face normal.
                for (std::size_t t = 0; t < tris.size(); ++t) {
                    const glm::uvec3 tri = tris[t];
                    const glm::vec3 p0 = wPos[tri.x], p1 = wPos[tri.y], p2 = wPos[tri.z];
                    glm::vec3 n = glm::cross(p1 - p0, p2 - p0);
                    const float len = glm::length(n);
                    n = len > 0.0f && std::isfinite(len) ? n / len : glm::vec3(0, 0, 1);
                    for (std::uint32_t k = 0; k < 3; ++k) {
                        scene.positions.push_back(wPos[tri[static_cast<int>(k)]]);
                        scene.normals.push_back(n);
                        if (sceneHasUvs)
                            scene.uvs.push_back(uv.empty() ? glm::vec2(0.0f) : uv[tri[static_cast<int>(k)]]);
                    }
                    const auto b = base + static_cast<std::uint32_t>(3 * t);
                    scene.triangles.emplace_back(b, b + 1, b + 2);
                    scene.triangleMaterial.push_back(material);
                }
                continue;
            }
            for (std::size_t i = 0; i < pos.size(); ++i) {
                scene.positions.push_back(wPos[i]);
                if (sceneHasNormals) {
                    glm::dvec3 n = normalMatrix * glm::dvec3(nrm[i]);
                    const double len = glm::length(n);
                    // Zero-length file normals cannot be renormalised; use +Y rather than NaN.
                    n = len > 0.0 && std::isfinite(len) ? n / len : glm::dvec3(0, 1, 0);
                    scene.normals.push_back(glm::vec3(n));
                }
                if (sceneHasUvs) scene.uvs.push_back(uv.empty() ? glm::vec2(0.0f) : uv[i]);
            }
            for (const auto& t : tris) {
                scene.triangles.push_back(t + glm::uvec3(base));
                scene.triangleMaterial.push_back(material);
            }
        } catch (const Error& e) {
            throw e.withContext(primLabel);
        }
    }
}

}  // namespace gdpt::gltf
