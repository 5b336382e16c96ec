// scene_builders.h — small scenes built in code for the GPU tests: a Lambertian (optionally
// emissive) material, an axis-aligned quad facing +z or -z, a camera looking down -z.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <string>

#include "gdpt_shared.h"
#include "scene/gltf_loader.h"
#include "scene/procedural.h"
#include "scene/scene.h"

namespace gdpt::test {

inline gpu::Material lambert(glm::vec3 albedo, glm::vec3 emission = glm::vec3(0.0f)) {
    gpu::Material m{};
    m.baseColor = glm::vec4(albedo, 1.0f);
    m.emissive = emission;
    m.roughness = 1.0f;
    m.ior = 1.5f;
    m.alphaCutoff = 0.5f;
    m.specularColor = glm::vec3(1.0f);
    if (emission.x > 0 || emission.y > 0 || emission.z > 0) m.flags |= gpu::kMatFlagEmissive;
    m.baseColorTex = m.metallicRoughnessTex = m.emissiveTex = m.normalTex = -1;
    return m;
}

// Quad in the plane z = zPlane, half-size h, front face towards +z (or -z).
inline void addQuadZ(Scene& s, float zPlane, float h, std::uint32_t mat, bool facePlusZ = true) {
    const auto base = static_cast<std::uint32_t>(s.positions.size());
    s.positions.insert(s.positions.end(),
                       {{-h, -h, zPlane}, {h, -h, zPlane}, {h, h, zPlane}, {-h, h, zPlane}});
    if (facePlusZ) {
        s.triangles.emplace_back(base, base + 1, base + 2);
        s.triangles.emplace_back(base, base + 2, base + 3);
    } else {
        s.triangles.emplace_back(base, base + 2, base + 1);
        s.triangles.emplace_back(base, base + 3, base + 2);
    }
    s.triangleMaterial.insert(s.triangleMaterial.end(), {mat, mat});
}

inline Camera lookDown(float height, float yfovDeg) {
    Camera c;
    c.position = glm::vec3(0.0f, 0.0f, height);
    c.forward = glm::vec3(0.0f, 0.0f, -1.0f);
    c.up = glm::vec3(0.0f, 1.0f, 0.0f);
    c.yfov = glm::radians(yfovDeg);
    return c;
}

// Appends quad a, b, c, d (emitting along (b − a) × (c − a)) with a new emissive material of
// radiance `radiance`; returns the material.
inline std::uint32_t addEmitterQuad(Scene& s, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d,
                                    glm::vec3 radiance) {
    s.materials.push_back(lambert(glm::vec3(0.0f), radiance));
    const auto material = static_cast<std::uint32_t>(s.materials.size() - 1);
    addQuad(s, a, b, c, d, material);
    return material;
}

// The Cornell box (makeCornellBox, its light material 3) with a 1 m² quad of radiance 50
// behind its back wall (z = −1.5), emitting towards the wall, which hides it from everything
// inside: 96 % of the scene's emitted power lights nothing the camera sees. Its material is
// `hidden`.
inline Scene cornellBoxWithHiddenEmitter(std::uint32_t& hidden) {
    Scene s = makeCornellBox();
    hidden = addEmitterQuad(s, {-0.5f, 0.5f, -1.5f}, {0.5f, 0.5f, -1.5f}, {0.5f, 1.5f, -1.5f},
                            {-0.5f, 1.5f, -1.5f}, glm::vec3(50.0f));
    return s;
}

// scenes/glossy_cornell.gltf (rough metal box, mirror sphere, area light) with a point light
// beside the area light: the G-PT and MLT tests' glossy scene with both kinds of light.
inline Scene glossyCornellWithPointLight() {
    Scene scene = loadGltf(std::string(GDPT_SOURCE_DIR) + "/scenes/glossy_cornell.gltf");
    gpu::PunctualLight light{};
    light.position = glm::vec3(0.3f, 1.5f, 0.2f);
    light.type = gpu::kPunctualPoint;
    light.intensity = glm::vec3(2.0f, 1.5f, 1.0f);
    scene.punctualLights.push_back(light);
    return scene;
}

}  // namespace gdpt::test
