// features.h — what a scene needs from the kernels. Computed on the host once per scene; the
// booleans become specialisation constants so that a scene never pays for a feature it
// lacks (no texture fetches without textures, no punctual-light code without punctual
// lights, ...). `gdpt info` prints this.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <string>
#include <utility>
#include <vector>

#include "scene/scene.h"

namespace gdpt {

struct SceneFeatures {
    std::uint32_t triangles = 0;
    std::uint32_t emissiveTriangles = 0;
    std::uint32_t punctualLights = 0;
    std::uint32_t textures = 0;
    bool hasTextures = false;  // some material samples a texture
    bool hasPunctual = false;
    bool hasLightTris = false;
    bool hasEnv = false;
    // Some emissive material's triangles bound all the others: a sky made of triangles (a dome,
    // sphere or box of emissive surface around the scene; glTF has no environment light).
    bool hasEmissiveEnclosure = false;
    bool hasGlossy = false;         // some vertex can be classified glossy (roughness <= threshold)
    bool hasSpecularLayer = false;  // some material has a non-Lambertian (metal/dielectric) lobe
    bool hasAlphaMask = false;
    bool hasShadingNormals = false;  // some triangle's vertex normals differ from its face normal
    float minRoughness = 1.0f;       // over materials with a specular lobe
    float maxRoughness = 0.0f;
};

// Whether triangle `tri` of `scene` needs its vertex normals: false without normals and when
// all three are parallel to the face normal with the same sign (within 1e-6 in the cosine),
// where the kernels' interpolated shading normal would be the geometric one anyway.
bool triangleHasShadingNormals(const Scene& scene, std::size_t tri);

// Area of triangle `tri` (float, as the kernels' light pdfs use it).
float triangleArea(const Scene& scene, std::size_t tri);
// Power of triangle `tri` as a light, area · luminance(Le) · π (×2 when double-sided;
// the largest Le component where the luminance is 0), or 0 when it is not a light: not
// emissive, no area, or no power. The light table's CDF is proportional to it.
double emitterPower(const Scene& scene, std::size_t tri, float area);
// Whether triangle `tri`'s material emits (a cheap test that emitterPower > 0 requires).
bool materialIsEmissive(const Scene& scene, std::size_t tri);

// Whether the triangles of one emissive material enclose the rest of `scene` as far as their
// bounding boxes tell: that material's box has a positive extent on every axis and contains
// the box of every other material's triangles (within 1e-4 of the scene's diagonal). A scene
// of that material alone (the white furnace's sphere) counts.
bool hasEmissiveEnclosure(const Scene& scene);

// shiftThreshold: roughness at or below which a vertex is "glossy" for gradient-domain
// shifts (Kettunen et al. 2015 reference default 0.001).
SceneFeatures analyzeScene(const Scene& scene, glm::vec3 envRadiance, float shiftThreshold = 0.001f);

// Human-readable lines for `gdpt info`.
std::vector<std::pair<std::string, std::string>> describeFeatures(const SceneFeatures& f);

}  // namespace gdpt
