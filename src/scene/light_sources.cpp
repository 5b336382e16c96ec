// light_sources.cpp — see light_sources.h.
#include "scene/light_sources.h"

namespace gdpt {
namespace {

bool positive(glm::vec3 v) {
    return v.x > 0.0f || v.y > 0.0f || v.z > 0.0f;
}

bool hasEmissiveTriangle(const Scene& scene) {
    for (std::size_t t = 0; t < scene.triangles.size(); ++t) {
        const std::uint32_t mi = scene.triangleMaterial[t];
        if (mi >= scene.materials.size()) continue;
        const gpu::Material& m = scene.materials[mi];
        if (!(m.flags & gpu::kMatFlagEmissive) || !positive(m.emissive)) continue;
        const glm::uvec3 tri = scene.triangles[t];
        const glm::vec3 p0 = scene.positions[tri.x];
        const glm::vec3 cross = glm::cross(scene.positions[tri.y] - p0, scene.positions[tri.z] - p0);
        if (glm::dot(cross, cross) > 0.0f) return true;
    }
    return false;
}

}  // namespace

bool hasLightSource(const Scene& scene, glm::vec3 envRadiance) {
    if (positive(envRadiance)) return true;
    for (const gpu::PunctualLight& light : scene.punctualLights)
        if (positive(light.intensity)) return true;
    return hasEmissiveTriangle(scene);
}

std::optional<std::string> blackImageWarning(const Scene& scene, glm::vec3 envRadiance, bool envOption) {
    if (hasLightSource(scene, envRadiance)) return std::nullopt;
    const std::string name = scene.sourcePath.empty() ? "(generated scene)" : scene.sourcePath;
    return name + ": no light source (no emissive surface, no punctual light" +
           (envOption ? ", no --env" : "") + "): the image will be black" +
           (envOption ? "; try --env 1,1,1" : "");
}

}  // namespace gdpt
