// test_procedural.cpp — the procedural scenes are what they claim: the furnace sphere is a
// closed surface seen from inside by its front faces (brute-force ray casts from the centre,
// including rays straight through vertices and edge midpoints, the cases where a leaky mesh
// or an edge-exclusive test would miss), the emissive quad fills the view, and the benchmark
// scene hits its triangle target deterministically.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <glm/gtc/constants.hpp>
#include <map>
#include <optional>
#include <utility>

#include "scene/procedural.h"

namespace gdpt {
namespace {

struct Hit {
    float t;
    std::size_t triangle;
};

// Möller–Trumbore in double precision with edges included (barycentrics >= -1e-12), so a
// ray through a shared edge or vertex counts as a hit on the adjacent triangles.
std::optional<Hit> closestHit(const Scene& s, glm::dvec3 o, glm::dvec3 d) {
    std::optional<Hit> best;
    for (std::size_t i = 0; i < s.triangles.size(); ++i) {
        const glm::uvec3 tri = s.triangles[i];
        const glm::dvec3 p0(s.positions[tri.x]), p1(s.positions[tri.y]), p2(s.positions[tri.z]);
        const glm::dvec3 e1 = p1 - p0, e2 = p2 - p0, pv = glm::cross(d, e2);
        const double det = glm::dot(e1, pv);
        if (std::abs(det) < 1e-18) continue;
        const glm::dvec3 tv = o - p0;
        const double u = glm::dot(tv, pv) / det;
        const glm::dvec3 qv = glm::cross(tv, e1);
        const double v = glm::dot(d, qv) / det;
        const double t = glm::dot(e2, qv) / det;
        if (u < -1e-12 || v < -1e-12 || u + v > 1.0 + 1e-12 || t <= 1e-9) continue;
        if (!best || t < best->t) best = Hit{static_cast<float>(t), i};
    }
    return best;
}

glm::dvec3 geometricNormal(const Scene& s, std::size_t t) {
    const glm::uvec3 tri = s.triangles[t];
    return glm::cross(glm::dvec3(s.positions[tri.y] - s.positions[tri.x]),
                      glm::dvec3(s.positions[tri.z] - s.positions[tri.x]));
}

// Uniform directions on the sphere from a fixed-seed LCG (deterministic on every platform).
std::vector<glm::dvec3> randomDirections(int n, std::uint32_t seed) {
    std::vector<glm::dvec3> dirs;
    auto next = [&] { return (seed = seed * 1664525u + 1013904223u) / 4294967296.0; };
    for (int i = 0; i < n; ++i) {
        const double z = 1.0 - 2.0 * next(), phi = 2.0 * glm::pi<double>() * next();
        const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
        dirs.emplace_back(r * std::cos(phi), r * std::sin(phi), z);
    }
    return dirs;
}

TEST(Procedural, FurnaceSphereIsClosedAndSeenFromInsideByFrontFaces) {
    const Scene s = makeFurnaceSphere(0.5f, glm::vec3(0.5f), 2);
    ASSERT_EQ(s.triangles.size(), 320u);  // 20 * 4^2
    ASSERT_EQ(s.materials.size(), 1u);
    EXPECT_EQ(s.materials[0].baseColor, glm::vec4(0.5f, 0.5f, 0.5f, 1.0f));
    EXPECT_EQ(s.materials[0].emissive, glm::vec3(0.5f));
    EXPECT_EQ(s.materials[0].specular, 0.0f);
    EXPECT_EQ(s.materials[0].metallic, 0.0f);
    EXPECT_TRUE(s.materials[0].flags & gpu::kMatFlagEmissive);
    ASSERT_EQ(s.cameras.size(), 1u);
    EXPECT_EQ(s.cameras[0].position, glm::vec3(0.0f));

    // Closed, consistently oriented 2-manifold: every directed edge appears exactly once and
    // its reverse exactly once.
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
    for (const auto& t : s.triangles)
        for (int k = 0; k < 3; ++k) edges[{t[k], t[(k + 1) % 3]}]++;
    for (const auto& [e, n] : edges) {
        EXPECT_EQ(n, 1);
        EXPECT_EQ(edges.count({e.second, e.first}), 1u) << "open edge " << e.first << "-" << e.second;
    }

    std::vector<glm::dvec3> dirs = randomDirections(2000, 7u);
    for (const auto& t : s.triangles) {
        dirs.push_back(glm::dvec3(s.positions[t.x]));                                 // vertex
        dirs.push_back(glm::dvec3(s.positions[t.x]) + glm::dvec3(s.positions[t.y]));  // edge
    }
    for (const auto& d : dirs) {
        const auto hit = closestHit(s, glm::dvec3(0.0), glm::normalize(d));
        ASSERT_TRUE(hit.has_value()) << "ray escaped: " << d.x << " " << d.y << " " << d.z;
        // Front face: the ray arrives against the counter-clockwise normal.
        EXPECT_LT(glm::dot(geometricNormal(s, hit->triangle), d), 0.0);
        EXPECT_GT(hit->t, 0.9f);  // inscribed icosphere level 2: all points within [0.95,1]
        EXPECT_LE(hit->t, 1.0f + 1e-6f);
    }
    // Flat-shaded: no vertex normals, so that shading and geometric normals agree and the
    // furnace identity holds exactly.
    EXPECT_TRUE(s.normals.empty());
}

TEST(Procedural, EmissiveQuadFillsTheView) {
    const Scene s = makeEmissiveQuad({1.0f, 2.0f, 3.0f});
    ASSERT_EQ(s.cameras.size(), 1u);
    const Camera& c = s.cameras[0];
    const glm::vec3 right = glm::cross(c.forward, c.up);
    const double tanHalf = std::tan(0.5 * c.yfov), aspect = 4.0;  // a wide 4:1 image
    for (int j = 0; j <= 8; ++j)
        for (int i = 0; i <= 8; ++i) {
            const double x = (i / 4.0 - 1.0) * tanHalf * aspect, y = (j / 4.0 - 1.0) * tanHalf;
            const glm::dvec3 d = glm::dvec3(c.forward) + x * glm::dvec3(right) + y * glm::dvec3(c.up);
            const auto hit = closestHit(s, glm::dvec3(c.position), d);
            ASSERT_TRUE(hit.has_value()) << i << "," << j;
            EXPECT_LT(glm::dot(geometricNormal(s, hit->triangle), d), 0.0);  // front face
        }
    EXPECT_EQ(s.materials[0].emissive, glm::vec3(1.0f, 2.0f, 3.0f));
    EXPECT_EQ(s.materials[0].baseColor, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
}

TEST(Procedural, CornellBoxShape) {
    const Scene s = makeCornellBox();
    EXPECT_EQ(s.triangles.size(), 36u);
    EXPECT_EQ(s.materials.size(), 4u);
    EXPECT_EQ(s.materials[3].emissive, glm::vec3(17.0f, 12.0f, 4.0f));
    // Every wall faces the inside of the box: rays from the box centre hit front faces.
    for (const auto& d : randomDirections(500, 3u)) {
        const auto hit = closestHit(s, glm::dvec3(0.0, 1.0, 0.0), d);
        if (!hit) {
            EXPECT_GT(d.z, 0.0);  // only the open front (+Z) side lets rays out
            continue;
        }
        EXPECT_LT(glm::dot(geometricNormal(s, hit->triangle), d), 0.0);
    }
}

TEST(Procedural, TriangleSceneHitsTargetDeterministically) {
    for (const std::uint32_t target : {10000u, 100000u}) {
        const Scene a = makeTriangleScene(target, 1u);
        const double rel = std::abs(double(a.triangles.size()) - target) / target;
        EXPECT_LT(rel, 0.04) << target << " -> " << a.triangles.size();
        EXPECT_EQ(a.normals.size(), a.positions.size());
        EXPECT_EQ(a.triangleMaterial.size(), a.triangles.size());
        const Bounds b = a.bounds();
        EXPECT_GE(b.min.x, -1.0f);
        EXPECT_LE(b.max.y, 2.0f);
        for (std::uint32_t m : a.triangleMaterial) ASSERT_LT(m, a.materials.size());
        for (const auto& t : a.triangles)
            ASSERT_TRUE(t.x < a.positions.size() && t.y < a.positions.size() && t.z < a.positions.size());
        ASSERT_EQ(a.cameras.size(), 1u);
        EXPECT_EQ(a.cameras[0].position, glm::vec3(0.0f, 1.0f, 6.8f));
        // Same seed, same scene; another seed, another placement.
        const Scene again = makeTriangleScene(target, 1u);
        EXPECT_EQ(a.positions, again.positions);
        EXPECT_NE(a.positions, makeTriangleScene(target, 2u).positions);
    }
}

}  // namespace
}  // namespace gdpt
