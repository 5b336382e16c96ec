// procedural.h — scenes built in code, for tests and the benchmark. They use the same
// conventions as loaded glTF scenes (world space, metres, radiance in W/(m^2 sr), front face
// = counter-clockwise) and the "pure Lambertian" material convention (metallic 0,
// specularFactor 0, roughness 1: albedo = baseColor, no specular layer) unless stated.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>

#include "scene/scene.h"

namespace gdpt {

// Appends quad a, b, c, d as triangles (a, b, c), (a, c, d) of material `mat`, with six vertices
// of its own and the face normal (b − a) × (c − a), the layout cbox.gltf uses; counter-clockwise
// seen from the side the normal points to.
void addQuad(Scene& s, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, std::uint32_t mat);

// The Cornell box in Bitterli's layout: Lambertian red, green and white walls, two white
// boxes and a ceiling light of radiance (17, 12, 4) emitting downwards; 36 triangles,
// materials white, red, green, light = 0..3; camera at (0, 1, 6.8) looking at (0, 1, 0)
// with a vertical field of view of 19.5 degrees. The same geometry, materials and camera as
// the glTF Cornell box with an independent reference image that some tests read from
// ../shared/scenes/cbox.
[[nodiscard]] Scene makeCornellBox();

// A closed unit sphere (icosphere, 20 * 4^subdivisions triangles, radius 1, centred at the
// origin) whose front faces point to the centre, flat-shaded, with Lambertian albedo
// `albedo` and uniform emitted radiance `emission`; camera at the centre looking -Z.
// In such a furnace every path sees radiance emission / (1 - albedo).
[[nodiscard]] Scene makeFurnaceSphere(float albedo, glm::vec3 emission, int subdivisions);
// The same furnace whose cap above y = 0.6 (about a fifth of the area) is a second material,
// identical to the first: two emitters of unequal power and the same exact image, for
// the rules that pick among emitters (render/device_scene/light_table.h).
[[nodiscard]] Scene makeTwoEmitterFurnace(float albedo, glm::vec3 emission, int subdivisions);

// One black emissive quad of radiance `radiance` at z = -1 facing a camera at the origin
// (looking -Z, yfov 45°); it is large enough to fill the view at any aspect ratio < 20.
[[nodiscard]] Scene makeEmissiveQuad(glm::vec3 radiance);

// A Cornell-box-like room (walls and ceiling light of makeCornellBox, no boxes) filled with
// randomly placed, slightly squashed diffuse icospheres so that the total is about
// `targetTriangles` (within 4 % for targets >= 1000); camera as in makeCornellBox. For
// the 10k/100k/1M-triangle benchmarks. Deterministic for a given (targetTriangles, seed).
[[nodiscard]] Scene makeTriangleScene(std::uint32_t targetTriangles, std::uint32_t seed);

}  // namespace gdpt
