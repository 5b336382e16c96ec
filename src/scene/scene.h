// scene.h — the flattened CPU scene every later stage consumes: world-space triangles with
// per-vertex attributes, materials, textures (already linear), lights and one camera.
// Produced by the glTF loader (gltf_loader.h) or by the procedural generators; consumed by
// the BVH builder and the GPU upload. No Vulkan here.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "gdpt_shared.h"

namespace gdpt {

struct Camera {
    glm::vec3 position{0.0f, 0.0f, 1.0f};  // world space
    glm::vec3 forward{0.0f, 0.0f, -1.0f};  // unit view direction (camera local -Z)
    glm::vec3 up{0.0f, 1.0f, 0.0f};        // unit, orthogonal to forward (camera local +Y)
    float yfov = 0.6f;                     // vertical field of view, radians
    float aspectRatio = 0.0f;              // from glTF if given (0 = unknown)
    std::string name;
};

// A decoded texture: linear RGBA float texels, row 0 = top of the image (glTF uv (0,0)).
struct Texture {
    int width = 0;
    int height = 0;
    std::vector<glm::vec4> texels;  // width*height linear RGBA
    std::string name;
};

// Axis-aligned box, world space.
struct Bounds {
    glm::vec3 min{1e30f};
    glm::vec3 max{-1e30f};
    void extend(const glm::vec3& p) {
        min = glm::min(min, p);
        max = glm::max(max, p);
    }
    [[nodiscard]] bool empty() const { return min.x > max.x; }
};

struct Scene {
    // Per-vertex attributes, world space. normals may be empty (use geometric normals);
    // uvs may be empty (all zero).
    std::vector<glm::vec3> positions;
    std::vector<glm::vec3> normals;
    std::vector<glm::vec2> uvs;
    // Triangles: three vertex indices each, and the material of each triangle.
    std::vector<glm::uvec3> triangles;
    std::vector<std::uint32_t> triangleMaterial;

    std::vector<gpu::Material> materials;
    std::vector<Texture> textures;
    std::vector<gpu::PunctualLight> punctualLights;

    std::vector<Camera> cameras;  // in glTF scene traversal order; may be empty

    // Features found in the file that gdpt does not support (printed as one warning).
    std::vector<std::string> unsupported;

    std::string sourcePath;  // file it was loaded from ("" for generated scenes)

    [[nodiscard]] Bounds bounds() const {
        Bounds b;
        for (const auto& p : positions) b.extend(p);
        return b;
    }
};

}  // namespace gdpt
