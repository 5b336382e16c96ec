// test_scene_set.cpp — the benchmark scene set in scenes/ (written by scenes/make_scenes.py):
// every file loads cleanly, and each scene has the property it is in the set for: the small
// light has the default light's power, the textured scene carries its 256x256 texture, and
// the indirect-gap scene never shows its light to a camera ray, the open scene is dozens of
// small boxes under a sky whose power dwarfs its small lamp's.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "scene/gltf_loader.h"

namespace gdpt {
namespace {

std::string scenePath(const std::string& name) {
    return std::string(GDPT_SOURCE_DIR) + "/scenes/" + name;
}

bool isEmissive(const Scene& s, std::size_t tri) {
    const glm::vec3 e = s.materials[s.triangleMaterial[tri]].emissive;
    return e.x > 0.0f || e.y > 0.0f || e.z > 0.0f;
}

std::size_t emissiveTriangles(const Scene& s) {
    std::size_t n = 0;
    for (std::size_t t = 0; t < s.triangles.size(); ++t) n += isEmissive(s, t) ? 1 : 0;
    return n;
}

// Sum over emissive triangles of area x radiance (W/sr per unit projected area: the power
// is pi times this for a Lambertian emitter, the same factor for every scene).
glm::dvec3 emittedPower(const Scene& s) {
    glm::dvec3 sum(0.0);
    for (std::size_t t = 0; t < s.triangles.size(); ++t) {
        if (!isEmissive(s, t)) continue;
        const glm::uvec3 tri = s.triangles[t];
        const glm::dvec3 a(s.positions[tri.x]), b(s.positions[tri.y]), c(s.positions[tri.z]);
        const double area = 0.5 * glm::length(glm::cross(b - a, c - a));
        sum += area * glm::dvec3(s.materials[s.triangleMaterial[t]].emissive);
    }
    return sum;
}

// Möller–Trumbore; returns the ray parameter of a hit with either face, if any.
std::optional<double> intersect(const glm::dvec3& o, const glm::dvec3& d, const glm::dvec3& a,
                                const glm::dvec3& b, const glm::dvec3& c) {
    const glm::dvec3 e1 = b - a, e2 = c - a;
    const glm::dvec3 p = glm::cross(d, e2);
    const double det = glm::dot(e1, p);
    if (std::abs(det) < 1e-14) return std::nullopt;
    const double inv = 1.0 / det;
    const glm::dvec3 s = o - a;
    const double u = glm::dot(s, p) * inv;
    if (u < 0.0 || u > 1.0) return std::nullopt;
    const glm::dvec3 q = glm::cross(s, e1);
    const double v = glm::dot(d, q) * inv;
    if (v < 0.0 || u + v > 1.0) return std::nullopt;
    const double t = glm::dot(e2, q) * inv;
    if (t <= 1e-9) return std::nullopt;
    return t;
}

// Index of the nearest triangle hit by the ray, or -1.
long long closestHit(const Scene& s, const glm::dvec3& o, const glm::dvec3& d) {
    double best = std::numeric_limits<double>::infinity();
    long long hit = -1;
    for (std::size_t t = 0; t < s.triangles.size(); ++t) {
        const glm::uvec3 tri = s.triangles[t];
        const auto h = intersect(o, d, glm::dvec3(s.positions[tri.x]), glm::dvec3(s.positions[tri.y]),
                                 glm::dvec3(s.positions[tri.z]));
        if (h && *h < best) {
            best = *h;
            hit = static_cast<long long>(t);
        }
    }
    return hit;
}

Scene loadClean(const std::string& name) {
    Scene s = loadGltf(scenePath(name));
    EXPECT_TRUE(s.unsupported.empty()) << name << ": " << describeScene(s);
    return s;
}

struct Expected {
    const char* file;
    std::size_t minTriangles, maxTriangles;
    std::size_t minEmissive, maxEmissive;
};

// Every scene of the set, with sane triangle and emissive-triangle ranges.
constexpr Expected kSet[] = {
    {"cornell_box.gltf", 36, 36, 2, 2},       {"glossy_cornell.gltf", 1000, 2000, 2, 2},
    {"furnace.gltf", 1280, 1280, 1280, 1280}, {"small_light.gltf", 36, 36, 2, 2},
    {"indirect_gap.gltf", 40, 200, 2, 2},     {"textured.gltf", 36, 36, 2, 2},
    {"moving_box.gltf", 36, 36, 2, 2},        {"camera_move.gltf", 36, 36, 2, 2},
    {"open_scene.gltf", 500, 1000, 322, 322},
};

TEST(SceneSet, EveryFileIsListedAndLoadsCleanly) {
    std::vector<std::string> files;
    for (const auto& entry : std::filesystem::directory_iterator(scenePath(""))) {
        const std::string ext = entry.path().extension().string();
        if (ext == ".gltf" || ext == ".glb") files.push_back(entry.path().filename().string());
    }
    std::sort(files.begin(), files.end());
    ASSERT_FALSE(files.empty());
    for (const std::string& f : files) {
        SCOPED_TRACE(f);
        const auto* e =
            std::find_if(std::begin(kSet), std::end(kSet), [&](const Expected& x) { return f == x.file; });
        ASSERT_NE(e, std::end(kSet)) << "scene not covered by this test";
        Scene s;
        ASSERT_NO_THROW(s = loadClean(f));
        EXPECT_GE(s.triangles.size(), e->minTriangles);
        EXPECT_LE(s.triangles.size(), e->maxTriangles);
        const std::size_t em = emissiveTriangles(s);
        EXPECT_GE(em, e->minEmissive);
        EXPECT_LE(em, e->maxEmissive);
        EXPECT_EQ(s.triangleMaterial.size(), s.triangles.size());
        ASSERT_EQ(s.cameras.size(), 1u);
        EXPECT_FLOAT_EQ(s.cameras[0].aspectRatio, 1.0f);
        EXPECT_TRUE(s.punctualLights.empty());
        // No file of the set may grow big: the set lives in the repository.
        EXPECT_LT(std::filesystem::file_size(scenePath(f)), 400u * 1024u);
    }
    for (const Expected& e : kSet)
        EXPECT_NE(std::find(files.begin(), files.end(), e.file), files.end()) << e.file << " missing";
}

TEST(SceneSet, SmallLightHasTheDefaultPowerOnATwentiethOfTheArea) {
    const Scene small = loadClean("small_light.gltf");
    const Scene cbox = loadClean("cornell_box.gltf");
    const glm::dvec3 ps = emittedPower(small), pc = emittedPower(cbox);
    // The default light: 0.47 m x 0.38 m of radiance (17, 12, 4).
    EXPECT_NEAR(pc.x, 0.47 * 0.38 * 17.0, 1e-4);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(ps[c] / pc[c], 1.0, 0.01) << "channel " << c;
    // About 5 % of the area, so 20 times the radiance.
    auto lightRadiance = [](const Scene& s) {
        for (std::size_t t = 0; t < s.triangles.size(); ++t)
            if (isEmissive(s, t)) return glm::dvec3(s.materials[s.triangleMaterial[t]].emissive);
        return glm::dvec3(0.0);
    };
    EXPECT_NEAR(lightRadiance(small).x / lightRadiance(cbox).x, 20.0, 0.2);
}

TEST(SceneSet, TexturedSceneSamplesItsDetailTexture) {
    const Scene s = loadClean("textured.gltf");
    ASSERT_EQ(s.textures.size(), 1u);
    EXPECT_EQ(s.textures[0].width, 256);
    EXPECT_EQ(s.textures[0].height, 256);
    ASSERT_EQ(s.textures[0].texels.size(), 256u * 256u);
    // The texture is high-contrast detail, not a flat colour: light and dark texels.
    float lo = 1.0f, hi = 0.0f;
    for (const glm::vec4& t : s.textures[0].texels) {
        lo = std::min(lo, t.g);
        hi = std::max(hi, t.g);
    }
    EXPECT_LT(lo, 0.05f);
    EXPECT_GT(hi, 0.5f);
    // Floor and back wall (4 triangles) sample it through TEXCOORD_0; the uvs span more than
    // a texel per pixel's worth and cross 0, so REPEAT wrapping is exercised.
    std::size_t textured = 0;
    for (std::size_t t = 0; t < s.triangles.size(); ++t)
        if (s.materials[s.triangleMaterial[t]].baseColorTex == 0) ++textured;
    EXPECT_EQ(textured, 4u);
    ASSERT_EQ(s.uvs.size(), s.positions.size());
    const auto [umin, umax] =
        std::minmax_element(s.uvs.begin(), s.uvs.end(), [](glm::vec2 a, glm::vec2 b) { return a.x < b.x; });
    EXPECT_LT(umin->x, 0.0f);
    EXPECT_GT(umax->x, 0.0f);
}

TEST(SceneSet, IndirectGapCameraNeverSeesTheLight) {
    const Scene s = loadClean("indirect_gap.gltf");
    ASSERT_EQ(s.cameras.size(), 1u);
    const Camera& cam = s.cameras[0];
    const glm::dvec3 o(cam.position), fwd(glm::normalize(glm::dvec3(cam.forward)));
    const glm::dvec3 up(glm::normalize(glm::dvec3(cam.up)));
    const glm::dvec3 right = glm::normalize(glm::cross(fwd, up));
    const double tanHalf = std::tan(0.5 * static_cast<double>(cam.yfov));
    const double aspect = cam.aspectRatio > 0.0f ? static_cast<double>(cam.aspectRatio) : 1.0;
    // 256 x 256 pixels, 3 x 3 rays each (corners, edge midpoints and centre), plus a
    // margin of half a pixel beyond the frame for any pixel filter.
    constexpr int kRes = 256, kSub = 3;
    std::size_t hits = 0, missed = 0, emissiveHits = 0;
    for (int py = 0; py < kRes * kSub + 2; ++py) {
        for (int px = 0; px < kRes * kSub + 2; ++px) {
            const double sx = (static_cast<double>(px) - 1.0) / (kRes * kSub - 1);
            const double sy = (static_cast<double>(py) - 1.0) / (kRes * kSub - 1);
            const double ndcX = (2.0 * sx - 1.0) * (1.0 + 1.0 / kRes);
            const double ndcY = (1.0 - 2.0 * sy) * (1.0 + 1.0 / kRes);
            const glm::dvec3 d = glm::normalize(fwd + ndcX * tanHalf * aspect * right + ndcY * tanHalf * up);
            const long long t = closestHit(s, o, d);
            if (t < 0) {
                ++missed;
                continue;
            }
            ++hits;
            if (isEmissive(s, static_cast<std::size_t>(t))) ++emissiveHits;
        }
    }
    EXPECT_EQ(emissiveHits, 0u);
    // Sanity of the ray setup: most rays hit the room (the open front shows some background).
    EXPECT_GT(hits, 4 * missed);
    // And the light exists and is bright enough to matter.
    EXPECT_EQ(emissiveTriangles(s), 2u);
    EXPECT_GT(emittedPower(s).x, 10.0);
}

// The open scene: a floor, 48 boxes of 12 triangles, a lamp of 2 triangles and a sky dome of
// 320; the lamp is tiny (0.09 m², under 1e-4 of the floor) but over 1000x the sky's radiance,
// and the sky holds almost all the emitted power (light selection by power rarely picks the
// lamp: the hard case for next-event estimation); the camera sees boxes, floor and sky.
TEST(SceneSet, OpenSceneHasManySmallBoxesUnderASkyAndASmallLamp) {
    const Scene s = loadClean("open_scene.gltf");
    EXPECT_EQ(s.triangles.size(), 2u + 48u * 12u + 2u + 320u);
    double lampArea = 0.0, lampRadiance = 0.0, skyRadiance = 0.0;
    glm::dvec3 lampPower(0.0), skyPower(0.0);
    for (std::size_t t = 0; t < s.triangles.size(); ++t) {
        if (!isEmissive(s, t)) continue;
        const glm::uvec3 tri = s.triangles[t];
        const glm::dvec3 a(s.positions[tri.x]), b(s.positions[tri.y]), c(s.positions[tri.z]);
        const double area = 0.5 * glm::length(glm::cross(b - a, c - a));
        const glm::dvec3 e(s.materials[s.triangleMaterial[t]].emissive);
        if (glm::length(a) < 10.0) {
            lampArea += area;
            lampRadiance = e.x;
            lampPower += area * e;
        } else {
            skyRadiance = e.x;
            skyPower += area * e;
        }
    }
    EXPECT_NEAR(lampArea, 0.09, 1e-4);
    EXPECT_GT(lampRadiance, 1000.0 * skyRadiance);
    EXPECT_GT(skyPower.x, 100.0 * lampPower.x);
    const Camera& cam = s.cameras[0];
    const glm::dvec3 o(cam.position), fwd(glm::normalize(glm::dvec3(cam.forward)));
    const glm::dvec3 up(glm::normalize(glm::dvec3(cam.up))), right = glm::normalize(glm::cross(fwd, up));
    const double tanHalf = std::tan(0.5 * static_cast<double>(cam.yfov));
    std::size_t sky = 0, floor = 0, boxes = 0, lamp = 0;
    for (int py = 0; py < 48; ++py)
        for (int px = 0; px < 48; ++px) {
            const double ndcX = (px + 0.5) / 24.0 - 1.0, ndcY = 1.0 - (py + 0.5) / 24.0;
            const glm::dvec3 d = glm::normalize(fwd + ndcX * tanHalf * right + ndcY * tanHalf * up);
            const long long t = closestHit(s, o, d);
            ASSERT_GE(t, 0) << "the sky dome encloses the scene";
            const auto i = static_cast<std::size_t>(t);
            if (i < 2)
                ++floor;
            else if (i < 2 + 48 * 12)
                ++boxes;
            else if (i < 2 + 48 * 12 + 2)
                ++lamp;
            else
                ++sky;
        }
    EXPECT_EQ(lamp, 0u);
    EXPECT_GT(sky, 48u);
    EXPECT_GT(boxes, 48u * 48u / 20u);
    EXPECT_GT(floor, 48u * 48u / 4u);
}

// The animated scenes start from the Cornell box: moving_box's short box at time 0 has the
// box's corners (up to float rounding of its centre's transform) and has moved by 3 s;
// camera_move's camera at time 0 is the box's camera and ends where the file says.
TEST(SceneSet, AnimatedScenesStartFromTheCornellBox) {
    const Scene cbox = loadClean("cornell_box.gltf");
    const GltfAsset moving(scenePath("moving_box.gltf"));
    ASSERT_EQ(moving.animations().size(), 1u);
    EXPECT_DOUBLE_EQ(moving.animations()[0].duration(), 3.0);
    const Scene start = moving.instance(0, 0.0), end = moving.instance(0, 3.0);
    const auto bounds = [](const Scene& s, std::size_t firstTriangle, std::size_t count) {
        Bounds b;
        for (std::size_t t = firstTriangle; t < firstTriangle + count; ++t)
            for (int k = 0; k < 3; ++k) b.extend(s.positions[s.triangles[t][k]]);
        return b;
    };
    // cornell_box lists the short box after the walls (5 quads = 10 triangles), moving_box last.
    const Bounds box = bounds(cbox, 10, 12), moved0 = bounds(start, 24, 12), moved3 = bounds(end, 24, 12);
    for (int a = 0; a < 3; ++a) {
        EXPECT_NEAR(moved0.min[a], box.min[a], 1e-6f);
        EXPECT_NEAR(moved0.max[a], box.max[a], 1e-6f);
    }
    EXPECT_LT(moved3.max.x, box.max.x - 0.1f);  // slid towards -x
    const GltfAsset camera(scenePath("camera_move.gltf"));
    ASSERT_EQ(camera.animations().size(), 1u);
    const Camera c0 = camera.instance(0, 0.0).cameras.at(0), c2 = camera.instance(0, 2.0).cameras.at(0);
    EXPECT_EQ(c0.position, cbox.cameras[0].position);
    EXPECT_EQ(c0.forward, cbox.cameras[0].forward);
    EXPECT_NEAR(c2.position.x, 0.45f, 1e-6f);
    EXPECT_NEAR(c2.position.z, 5.6f, 1e-6f);
    EXPECT_LT(c2.forward.x, -0.05f);  // turned left
}

}  // namespace
}  // namespace gdpt
