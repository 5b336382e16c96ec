// radiance_range.cpp — see radiance_range.h.
#include "scene/radiance_range.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "util/error.h"

namespace gdpt {
namespace {

bool representable(glm::vec3 v) {
    for (int c = 0; c < 3; ++c)
        if (!(v[c] >= 0.0f && v[c] <= kMaxRadiance)) return false;  // NaN fails too
    return true;
}

std::string text(glm::vec3 v) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "(%g, %g, %g)", double(v.x), double(v.y), double(v.z));
    return buf;
}

std::string range(const char* unit) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "the representable range [0, %g] %s per channel", double(kMaxRadiance),
                  unit);
    return buf;
}

// The largest value per channel of texture `index` (1 without a texture).
glm::vec3 textureMax(const Scene& scene, int index) {
    if (index < 0 || static_cast<std::size_t>(index) >= scene.textures.size()) return glm::vec3(1.0f);
    glm::vec3 m(0.0f);
    for (const glm::vec4& t : scene.textures[static_cast<std::size_t>(index)].texels)
        for (int c = 0; c < 3; ++c) m[c] = std::isnan(t[c]) ? t[c] : std::max(m[c], t[c]);
    return m;
}

}  // namespace

void checkRadianceRange(const Scene& scene, glm::vec3 envRadiance) {
    const std::string file = scene.sourcePath.empty() ? "(generated scene)" : scene.sourcePath;
    const char* why = ": gdpt accumulates radiance and its square in float32; scale the emission down";
    if (!representable(envRadiance))
        throw Error("environment radiance (--env) " + text(envRadiance) + " W/(m^2 sr) is outside " +
                    range("W/(m^2 sr)") + why);
    std::vector<char> used(scene.materials.size(), 0);
    for (std::uint32_t m : scene.triangleMaterial)
        if (m < used.size()) used[m] = 1;
    for (std::size_t m = 0; m < scene.materials.size(); ++m) {
        if (!used[m]) continue;
        const gpu::Material& mat = scene.materials[m];
        const glm::vec3 emission = mat.emissive * textureMax(scene, mat.emissiveTex);
        if (!representable(mat.emissive) || !representable(emission))
            throw Error(file + ": material " + std::to_string(m) + ": emission " +
                        text(representable(mat.emissive) ? emission : mat.emissive) +
                        " W/(m^2 sr) (emissiveFactor x emissiveStrength" +
                        (mat.emissiveTex >= 0 ? " x emissiveTexture" : "") + ") is outside " +
                        range("W/(m^2 sr)") + why);
    }
    for (std::size_t l = 0; l < scene.punctualLights.size(); ++l)
        if (!representable(scene.punctualLights[l].intensity))
            throw Error(file + ": punctual light " + std::to_string(l) + ": intensity " +
                        text(scene.punctualLights[l].intensity) + " W/sr (color x intensity) is outside " +
                        range("W/sr") + why);
}

}  // namespace gdpt
