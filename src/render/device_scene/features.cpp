#include "render/device_scene/features.h"

#include <algorithm>
#include <cmath>

namespace gdpt {

bool triangleHasShadingNormals(const Scene& scene, std::size_t tri) {
    if (scene.normals.empty()) return false;
    const glm::uvec3 t = scene.triangles[tri];
    const glm::vec3 face =
        glm::cross(scene.positions[t.y] - scene.positions[t.x], scene.positions[t.z] - scene.positions[t.x]);
    const float faceLength = glm::length(face);
    if (!(faceLength > 0.0f) || !std::isfinite(faceLength))
        return true;  // degenerate: leave it to the kernels
    float lo = 1.0f, hi = -1.0f;
    for (int k = 0; k < 3; ++k) {
        const glm::vec3 n = scene.normals[t[k]];
        const float len = glm::length(n);
        if (!(len > 0.0f) || !std::isfinite(len)) return true;
        const float c = glm::dot(n, face) / (len * faceLength);
        lo = std::min(lo, c);
        hi = std::max(hi, c);
    }
    constexpr float kFlat = 1.0f - 1e-6f;
    return !(lo >= kFlat || hi <= -kFlat);
}

float triangleArea(const Scene& scene, std::size_t tri) {
    const glm::uvec3 t = scene.triangles[tri];
    const glm::vec3 p0 = scene.positions[t.x], p1 = scene.positions[t.y], p2 = scene.positions[t.z];
    return 0.5f * glm::length(glm::cross(p1 - p0, p2 - p0));
}

bool materialIsEmissive(const Scene& scene, std::size_t tri) {
    const std::uint32_t mi = scene.triangleMaterial[tri];
    return mi < scene.materials.size() && (scene.materials[mi].flags & gpu::kMatFlagEmissive) != 0;
}

double emitterPower(const Scene& scene, std::size_t tri, float area) {
    constexpr float kPi = 3.14159265358979f;  // float products, as the light table was always built
    const std::uint32_t mi = scene.triangleMaterial[tri];
    if (mi >= scene.materials.size()) return 0.0;
    const gpu::Material& m = scene.materials[mi];
    if (!(m.flags & gpu::kMatFlagEmissive) || !(area > 0.0f)) return 0.0;
    const glm::vec3 le = m.emissive;
    const float luminance = 0.2126f * le.x + 0.7152f * le.y + 0.0722f * le.z;
    double p = area * luminance * kPi;
    if (m.flags & gpu::kMatFlagDoubleSided) p *= 2.0;
    if (!(p > 0.0)) p = area * kPi * std::max({le.x, le.y, le.z});
    return p > 0.0 ? p : 0.0;
}

bool hasEmissiveEnclosure(const Scene& scene) {
    std::vector<Bounds> bounds(scene.materials.size());
    for (std::size_t t = 0; t < scene.triangles.size(); ++t) {
        const std::uint32_t m = scene.triangleMaterial[t];
        if (m >= bounds.size()) continue;
        for (int k = 0; k < 3; ++k) bounds[m].extend(scene.positions[scene.triangles[t][k]]);
    }
    Bounds all;  // the union of the materials' boxes
    for (const Bounds& b : bounds)
        if (!b.empty()) {
            all.extend(b.min);
            all.extend(b.max);
        }
    if (all.empty()) return false;
    const float tolerance = 1e-4f * glm::length(all.max - all.min);
    for (std::size_t e = 0; e < bounds.size(); ++e) {
        const Bounds& sky = bounds[e];
        if (sky.empty() || !(scene.materials[e].flags & gpu::kMatFlagEmissive)) continue;
        const glm::vec3 extent = sky.max - sky.min;
        if (!(std::min({extent.x, extent.y, extent.z}) > tolerance)) continue;
        bool encloses = true;
        for (std::size_t m = 0; m < bounds.size() && encloses; ++m) {
            if (m == e || bounds[m].empty()) continue;
            encloses = glm::all(glm::lessThanEqual(sky.min, bounds[m].min + tolerance)) &&
                       glm::all(glm::greaterThanEqual(sky.max, bounds[m].max - tolerance));
        }
        if (encloses) return true;
    }
    return false;
}

SceneFeatures analyzeScene(const Scene& scene, glm::vec3 envRadiance, float shiftThreshold) {
    SceneFeatures f;
    f.triangles = static_cast<std::uint32_t>(scene.triangles.size());
    f.punctualLights = static_cast<std::uint32_t>(scene.punctualLights.size());
    f.textures = static_cast<std::uint32_t>(scene.textures.size());
    f.hasPunctual = f.punctualLights > 0;
    f.hasEnv = envRadiance.x > 0.0f || envRadiance.y > 0.0f || envRadiance.z > 0.0f;

    std::vector<bool> used(scene.materials.size(), false);
    for (std::size_t t = 0; t < scene.triangles.size(); ++t) {
        const std::uint32_t m = scene.triangleMaterial[t];
        if (m < used.size()) used[m] = true;
        if (m < scene.materials.size() && (scene.materials[m].flags & gpu::kMatFlagEmissive))
            ++f.emissiveTriangles;
    }
    f.hasLightTris = f.emissiveTriangles > 0;
    f.hasEmissiveEnclosure = f.hasLightTris && hasEmissiveEnclosure(scene);
    for (std::size_t t = 0; t < scene.triangles.size() && !f.hasShadingNormals; ++t)
        f.hasShadingNormals = triangleHasShadingNormals(scene, t);
    for (std::size_t i = 0; i < scene.materials.size(); ++i) {
        if (!used[i]) continue;
        const gpu::Material& m = scene.materials[i];
        const bool textured = m.baseColorTex >= 0 || m.metallicRoughnessTex >= 0 || m.emissiveTex >= 0;
        f.hasTextures = f.hasTextures || textured;
        f.hasAlphaMask = f.hasAlphaMask || (m.flags & gpu::kMatFlagAlphaMask);
        const bool specularLobe = m.metallic > 0.0f || m.specular > 0.0f;
        if (specularLobe) {
            f.hasSpecularLayer = true;
            // A roughness texture can only lower the factor, so it may reach 0.
            const float lo = m.metallicRoughnessTex >= 0 ? 0.0f : m.roughness;
            f.minRoughness = std::min(f.minRoughness, lo);
            f.maxRoughness = std::max(f.maxRoughness, m.roughness);
        }
    }
    // Below roughness 0.01 (GGX alpha < kDeltaAlpha = 1e-4) the lobe is a Dirac mirror,
    // which is "glossy" for the shift mappings whatever the threshold.
    f.hasGlossy = f.hasSpecularLayer && f.minRoughness <= std::max(shiftThreshold, 0.01f);
    if (!f.hasSpecularLayer) f.minRoughness = f.maxRoughness = 1.0f;
    return f;
}

std::vector<std::pair<std::string, std::string>> describeFeatures(const SceneFeatures& f) {
    auto yn = [](bool b) { return std::string(b ? "yes" : "no"); };
    return {
        {"triangles", std::to_string(f.triangles)},
        {"emissive triangles", std::to_string(f.emissiveTriangles)},
        {"punctual lights", std::to_string(f.punctualLights)},
        {"textures", std::to_string(f.textures)},
        {"textures sampled", yn(f.hasTextures)},
        {"alpha mask", yn(f.hasAlphaMask)},
        {"shading normals", yn(f.hasShadingNormals)},
        {"specular layer", yn(f.hasSpecularLayer)},
        {"roughness range", std::to_string(f.minRoughness) + " .. " + std::to_string(f.maxRoughness)},
        {"glossy/specular vertices", yn(f.hasGlossy)},
        {"environment", yn(f.hasEnv)},
        {"emissive sky (enclosure)", yn(f.hasEmissiveEnclosure)},
        {"transmission", "no (not supported)"},
    };
}

}  // namespace gdpt
