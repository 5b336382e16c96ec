// procedural.cpp — Cornell box, furnace sphere, emissive quad and the benchmark scene.
//
// cbox.gltf below names the glTF Cornell box (Bitterli's layout) whose independent
// reference image the reference tests read from ../shared/scenes/cbox; makeCornellBox()
// reproduces its geometry, materials and camera.
#include "scene/procedural.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

namespace gdpt {
namespace {

// Pure Lambertian material: albedo = baseColor, no specular lobe (metallic 0, specular 0).
gpu::Material lambertian(glm::vec3 albedo, glm::vec3 emission = glm::vec3(0.0f)) {
    gpu::Material m{};
    m.baseColor = glm::vec4(albedo, 1.0f);
    m.emissive = emission;
    m.metallic = 0.0f;
    m.specularColor = glm::vec3(1.0f);
    m.roughness = 1.0f;
    m.specular = 0.0f;
    m.ior = 1.5f;
    m.alphaCutoff = 0.5f;
    m.flags = glm::any(glm::greaterThan(emission, glm::vec3(0.0f))) ? gpu::kMatFlagEmissive : 0u;
    m.baseColorTex = m.metallicRoughnessTex = m.emissiveTex = m.normalTex = -1;
    return m;
}

// A box given by its 8 corners in cbox.gltf's corner order; faces as in that file.
void addBox(Scene& s, const glm::vec3 (&c)[8], std::uint32_t mat) {
    static constexpr int kFaces[6][4] = {{0, 1, 2, 3}, {4, 5, 6, 7}, {7, 6, 2, 1},
                                         {4, 0, 3, 5}, {5, 3, 2, 6}, {4, 7, 1, 0}};
    for (const auto& f : kFaces) addQuad(s, c[f[0]], c[f[1]], c[f[2]], c[f[3]], mat);
}

// The room of cbox.gltf (floor, ceiling, back, left, right walls) and its ceiling light.
// Materials must already hold white (0), red (1), green (2) and light (3).
void addRoomAndLight(Scene& s, bool withBoxes) {
    addQuad(s, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, {-1, 0, -1}, 0);    // floor
    addQuad(s, {-1, 2, -1}, {1, 2, -1}, {1, 2, 1}, {-1, 2, 1}, 0);    // ceiling
    addQuad(s, {-1, 0, -1}, {1, 0, -1}, {1, 2, -1}, {-1, 2, -1}, 0);  // back
    addQuad(s, {-1, 0, 1}, {-1, 0, -1}, {-1, 2, -1}, {-1, 2, 1}, 1);  // left (red)
    addQuad(s, {1, 0, -1}, {1, 0, 1}, {1, 2, 1}, {1, 2, -1}, 2);      // right (green)
    if (withBoxes) {
        // Corner coordinates copied from cbox.bin (float32 values printed to 9 digits).
        const glm::vec3 shortBox[8] = {
            {0.704602957f, 0.0f, 0.170820087f},          {0.704602957f, 0.600000024f, 0.170820087f},
            {0.529179931f, 0.600000024f, 0.744602919f},  {0.529179931f, 0.0f, 0.744602919f},
            {0.130820081f, 0.0f, -0.00460293842f},       {-0.044602938f, 0.0f, 0.569179893f},
            {-0.044602938f, 0.600000024f, 0.569179893f}, {0.130820081f, 0.600000024f, -0.00460293842f}};
        const glm::vec3 tallBox[8] = {
            {-0.135820091f, 0.0f, -0.664602935f},        {-0.135820091f, 1.20000005f, -0.664602935f},
            {0.039602939f, 1.20000005f, -0.0908200815f}, {0.039602939f, 0.0f, -0.0908200815f},
            {-0.709602952f, 0.0f, -0.489179909f},        {-0.534179926f, 0.0f, 0.0846029371f},
            {-0.534179926f, 1.20000005f, 0.0846029371f}, {-0.709602952f, 1.20000005f, -0.489179909f}};
        addBox(s, shortBox, 0);
        addBox(s, tallBox, 0);
    }
    addQuad(s, {-0.235f, 1.98f, -0.22f}, {0.235f, 1.98f, -0.22f}, {0.235f, 1.98f, 0.16f},
            {-0.235f, 1.98f, 0.16f}, 3);  // light, facing down
}

void addCornellMaterials(Scene& s) {
    s.materials.push_back(lambertian({0.725f, 0.71f, 0.68f}));                    // white
    s.materials.push_back(lambertian({0.63f, 0.065f, 0.05f}));                    // red
    s.materials.push_back(lambertian({0.14f, 0.45f, 0.091f}));                    // green
    s.materials.push_back(lambertian({0.0f, 0.0f, 0.0f}, {17.0f, 12.0f, 4.0f}));  // light
}

Camera cornellCamera() {
    Camera cam;
    cam.name = "camera";
    cam.position = {0.0f, 1.0f, 6.8f};
    cam.forward = {0.0f, 0.0f, -1.0f};
    cam.up = {0.0f, 1.0f, 0.0f};
    cam.yfov = 0.34033920413889424f;  // 19.5°, as in cbox.gltf
    cam.aspectRatio = 1.0f;
    return cam;
}

// Unit icosphere: vertices on the unit sphere, triangles counter-clockwise seen from
// outside. Shared vertices (edge midpoints are cached) make the mesh closed.
void icosphere(int subdivisions, std::vector<glm::vec3>& verts, std::vector<glm::uvec3>& tris) {
    const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
    verts = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
             {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
    for (auto& v : verts) v = glm::normalize(v);
    tris = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
            {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
            {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
    for (int level = 0; level < subdivisions; ++level) {
        std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> midpoint;
        auto mid = [&](std::uint32_t a, std::uint32_t b) {
            const auto key = std::minmax(a, b);
            auto it = midpoint.find(key);
            if (it != midpoint.end()) return it->second;
            verts.push_back(glm::normalize(verts[a] + verts[b]));
            const auto idx = static_cast<std::uint32_t>(verts.size() - 1);
            midpoint.emplace(key, idx);
            return idx;
        };
        std::vector<glm::uvec3> next;
        next.reserve(tris.size() * 4);
        for (const auto& tr : tris) {
            const std::uint32_t a = mid(tr.x, tr.y), b = mid(tr.y, tr.z), c = mid(tr.z, tr.x);
            next.insert(next.end(), {{tr.x, a, c}, {tr.y, b, a}, {tr.z, c, b}, {a, b, c}});
        }
        tris = std::move(next);
    }
}

// SplitMix64: a tiny, portable generator (std:: distributions differ between libraries).
struct SplitMix {
    std::uint64_t state;
    std::uint64_t next() {
        std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    float uniform() { return static_cast<float>(next() >> 40) * 0x1.0p-24f; }  // [0,1)
    float range(float lo, float hi) { return lo + (hi - lo) * uniform(); }
};

}  // namespace

void addQuad(Scene& s, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, std::uint32_t mat) {
    const glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
    const auto base = static_cast<std::uint32_t>(s.positions.size());
    for (const glm::vec3& p : {a, b, c, a, c, d}) {
        s.positions.push_back(p);
        s.normals.push_back(n);
    }
    s.triangles.emplace_back(base, base + 1, base + 2);
    s.triangles.emplace_back(base + 3, base + 4, base + 5);
    s.triangleMaterial.insert(s.triangleMaterial.end(), 2, mat);
}

Scene makeCornellBox() {
    Scene s;
    addCornellMaterials(s);
    addRoomAndLight(s, true);
    s.cameras.push_back(cornellCamera());
    return s;
}

Scene makeFurnaceSphere(float albedo, glm::vec3 emission, int subdivisions) {
    Scene s;
    s.materials.push_back(lambertian(glm::vec3(albedo), emission));
    std::vector<glm::vec3> verts;
    std::vector<glm::uvec3> tris;
    icosphere(std::clamp(subdivisions, 0, 8), verts, tris);
    s.positions = verts;
    // Flat shading: no vertex normals. Interpolated normals would break the furnace identity
    // (a cosine lobe about a shading normal loses what falls below the geometric surface:
    // 0.15 % per bounce at 2 subdivisions, which a 100-bounce furnace shows as 20 %).
    // Reverse the winding so that the front face (counter-clockwise) is seen from inside.
    for (const auto& t : tris) s.triangles.emplace_back(t.x, t.z, t.y);
    s.triangleMaterial.assign(s.triangles.size(), 0u);
    Camera cam;
    cam.name = "centre";
    cam.position = glm::vec3(0.0f);
    cam.yfov = glm::radians(45.0f);
    s.cameras.push_back(cam);
    return s;
}

Scene makeTwoEmitterFurnace(float albedo, glm::vec3 emission, int subdivisions) {
    Scene s = makeFurnaceSphere(albedo, emission, subdivisions);
    s.materials.push_back(s.materials[0]);
    for (std::size_t t = 0; t < s.triangles.size(); ++t) {
        const glm::uvec3 v = s.triangles[t];
        if ((s.positions[v.x].y + s.positions[v.y].y + s.positions[v.z].y) / 3.0f > 0.6f)
            s.triangleMaterial[t] = 1;
    }
    return s;
}

Scene makeEmissiveQuad(glm::vec3 radiance) {
    Scene s;
    s.materials.push_back(lambertian(glm::vec3(0.0f), radiance));
    addQuad(s, {-20, -20, -1}, {20, -20, -1}, {20, 20, -1}, {-20, 20, -1}, 0);  // faces +Z
    Camera cam;
    cam.name = "quad";
    cam.position = glm::vec3(0.0f);
    cam.yfov = glm::radians(45.0f);
    s.cameras.push_back(cam);
    return s;
}

Scene makeTriangleScene(std::uint32_t targetTriangles, std::uint32_t seed) {
    Scene s;
    addCornellMaterials(s);
    SplitMix rng{0x5EED0000ull ^ (std::uint64_t(seed) << 20) ^ targetTriangles};
    // A few diffuse colours for the spheres (materials 4..7).
    for (int i = 0; i < 4; ++i)
        s.materials.push_back(
            lambertian({rng.range(0.2f, 0.8f), rng.range(0.2f, 0.8f), rng.range(0.2f, 0.8f)}));
    addRoomAndLight(s, false);

    // Pick the finest sphere level that still gives >= 16 spheres, so the total lands within
    // half a sphere (<= 1/32) of the target.
    const std::uint64_t room = s.triangles.size();
    const std::uint64_t remaining = targetTriangles > room ? targetTriangles - room : 0;
    int level = 0;
    while (level < 7 && 20ull * (1ull << (2 * (level + 1))) * 16 <= remaining) ++level;
    const std::uint64_t perSphere = 20ull << (2 * level);
    const std::uint64_t count = (remaining + perSphere / 2) / perSphere;

    std::vector<glm::vec3> unitVerts;
    std::vector<glm::uvec3> unitTris;
    icosphere(level, unitVerts, unitTris);
    // Radius so that the spheres fill roughly a fifth of the room's 8 m^3 volume.
    const float radius =
        count > 0 ? std::min(0.3f, std::cbrt(0.2f * 8.0f / (4.18879f * float(count)))) : 0.0f;
    for (std::uint64_t k = 0; k < count; ++k) {
        const glm::vec3 centre(rng.range(-1.0f + radius, 1.0f - radius), rng.range(radius, 1.9f - radius),
                               rng.range(-1.0f + radius, 1.0f - radius));
        // Squash each sphere into an ellipsoid ("blob"); normals use the inverse scale.
        const glm::vec3 scale =
            radius * glm::vec3(rng.range(0.7f, 1.2f), rng.range(0.7f, 1.2f), rng.range(0.7f, 1.2f));
        const auto mat = static_cast<std::uint32_t>(4 + (rng.next() % 4));
        const auto base = static_cast<std::uint32_t>(s.positions.size());
        for (const auto& v : unitVerts) {
            s.positions.push_back(centre + v * scale);
            s.normals.push_back(glm::normalize(v / scale));
        }
        for (const auto& t : unitTris) {
            s.triangles.push_back(t + glm::uvec3(base));
            s.triangleMaterial.push_back(mat);
        }
    }
    s.cameras.push_back(cornellCamera());
    return s;
}

}  // namespace gdpt
