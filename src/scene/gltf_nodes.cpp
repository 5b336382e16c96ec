// gltf_nodes.cpp — the glTF node graph (gltf_internal.h): each node's transform, the graph's
// checks, the scene's roots, and the cameras and punctual lights the nodes place.
#include <cmath>
#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "scene/gltf_internal.h"

namespace gdpt::gltf {
namespace {

void checkFinite(const std::vector<double>& v, const std::string& what) {
    for (double x : v)
        if (!std::isfinite(x)) throw Error(what + " is not finite");
}

}  // namespace

// Local transform of a node: `matrix` (column-major) or T * R * S (glTF 2.0 §3.5.3), where an
// animation's pose (if any) replaces the node's own translation, rotation or scale (animated
// nodes have no matrix: readAnimations refuses them).
glm::dmat4 localMatrix(const tinygltf::Node& node, const NodePose* pose) {
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

}  // namespace gdpt::gltf
