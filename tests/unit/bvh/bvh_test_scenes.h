// bvh_test_scenes.h — seeded procedural meshes and rays for the BVH tests.
#pragma once

#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
#include <map>
#include <random>
#include <utility>
#include <vector>

namespace gdpt::test {

struct Mesh {
    std::vector<glm::vec3> positions;
    std::vector<glm::uvec3> triangles;

    uint32_t addVertex(glm::vec3 p) {
        positions.push_back(p);
        return static_cast<uint32_t>(positions.size() - 1);
    }
    void addTriangle(glm::vec3 a, glm::vec3 b, glm::vec3 c) {
        triangles.emplace_back(addVertex(a), addVertex(b), addVertex(c));
    }
};

inline glm::vec3 uniformInBox(std::mt19937& rng, glm::vec3 lo, glm::vec3 hi) {
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    return lo + glm::vec3(u(rng), u(rng), u(rng)) * (hi - lo);
}

inline glm::vec3 uniformOnSphere(std::mt19937& rng) {
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    float z = 1.0f - 2.0f * u(rng);
    float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    float phi = 6.2831853f * u(rng);
    return glm::vec3(r * std::cos(phi), r * std::sin(phi), z);
}

// Random triangle soup in [-1, 1]^3 with edges up to `size`.
inline Mesh randomSoup(uint32_t count, float size, uint32_t seed) {
    std::mt19937 rng(seed);
    Mesh m;
    for (uint32_t i = 0; i < count; ++i) {
        glm::vec3 c = uniformInBox(rng, glm::vec3(-1.0f), glm::vec3(1.0f));
        m.addTriangle(c + size * uniformInBox(rng, glm::vec3(-1.0f), glm::vec3(1.0f)),
                      c + size * uniformInBox(rng, glm::vec3(-1.0f), glm::vec3(1.0f)),
                      c + size * uniformInBox(rng, glm::vec3(-1.0f), glm::vec3(1.0f)));
    }
    return m;
}

// Height-field terrain over [-1, 1]^2 (y up), n x n quads with shared vertices.
inline Mesh terrain(uint32_t n, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> jitter(-0.02f, 0.02f);
    Mesh m;
    for (uint32_t j = 0; j <= n; ++j) {
        for (uint32_t i = 0; i <= n; ++i) {
            float x = -1.0f + 2.0f * float(i) / float(n);
            float z = -1.0f + 2.0f * float(j) / float(n);
            float y = 0.2f * std::sin(3.0f * x) * std::cos(2.0f * z) + jitter(rng);
            m.addVertex(glm::vec3(x, y, z));
        }
    }
    for (uint32_t j = 0; j < n; ++j) {
        for (uint32_t i = 0; i < n; ++i) {
            uint32_t a = j * (n + 1) + i;
            m.triangles.emplace_back(a, a + 1, a + n + 2);
            m.triangles.emplace_back(a, a + n + 2, a + n + 1);
        }
    }
    return m;
}

// Closed mesh: icosahedron subdivided `levels` times and projected on the unit sphere.
// Vertices are shared between faces, so edges are exactly shared.
inline Mesh icosphere(uint32_t levels) {
    const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
    Mesh m;
    const float v[12][3] = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                            {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
    for (const auto& p : v) {
        m.addVertex(glm::normalize(glm::vec3(p[0], p[1], p[2])));
    }
    m.triangles = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                   {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                   {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
    for (uint32_t l = 0; l < levels; ++l) {
        std::map<std::pair<uint32_t, uint32_t>, uint32_t> midpoints;
        auto mid = [&](uint32_t a, uint32_t b) {
            auto key = std::make_pair(std::min(a, b), std::max(a, b));
            auto it = midpoints.find(key);
            if (it != midpoints.end()) {
                return it->second;
            }
            uint32_t idx = m.addVertex(glm::normalize(m.positions[a] + m.positions[b]));
            midpoints.emplace(key, idx);
            return idx;
        };
        std::vector<glm::uvec3> next;
        for (const glm::uvec3& f : m.triangles) {
            uint32_t ab = mid(f.x, f.y);
            uint32_t bc = mid(f.y, f.z);
            uint32_t ca = mid(f.z, f.x);
            next.insert(next.end(), {{f.x, ab, ca}, {f.y, bc, ab}, {f.z, ca, bc}, {ab, bc, ca}});
        }
        m.triangles = std::move(next);
    }
    return m;
}

}  // namespace gdpt::test
