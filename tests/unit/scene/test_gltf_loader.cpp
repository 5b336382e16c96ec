// test_gltf_loader.cpp — the glTF loader on valid input: the shared Cornell box, node
// transforms, .gltf/.glb equivalence, strips and fans, normals policy, materials, textures,
// lights, cameras, scene selection and unsupported-feature reporting. Expected values are
// worked out by hand in the comments, not computed with the code under test.
#include <gtest/gtest.h>
#include <stb/stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <glm/gtc/constants.hpp>

#include "gltf_test_writer.h"
#include "scene/gltf_loader.h"
#include "scene/procedural.h"
#include "shared_data.h"
#include "util/error.h"

namespace gdpt {
namespace {

using test::TestGltf;

void expectNear(glm::vec3 a, glm::vec3 b, float tol, const std::string& what = "") {
    EXPECT_NEAR(a.x, b.x, tol) << what;
    EXPECT_NEAR(a.y, b.y, tol) << what;
    EXPECT_NEAR(a.z, b.z, tol) << what;
}

bool hasUnsupported(const Scene& s, const std::string& needle) {
    return std::any_of(s.unsupported.begin(), s.unsupported.end(),
                       [&](const std::string& u) { return u.find(needle) != std::string::npos; });
}

glm::vec3 faceNormal(const Scene& s, std::size_t t) {
    const glm::uvec3 tri = s.triangles[t];
    return glm::normalize(
        glm::cross(s.positions[tri.y] - s.positions[tri.x], s.positions[tri.z] - s.positions[tri.x]));
}

// Field-by-field equality of two scenes (normals within `normalTol`).
void expectSameScene(const Scene& a, const Scene& b, float normalTol) {
    ASSERT_EQ(a.positions.size(), b.positions.size());
    ASSERT_EQ(a.triangles.size(), b.triangles.size());
    ASSERT_EQ(a.normals.size(), b.normals.size());
    ASSERT_EQ(a.uvs.size(), b.uvs.size());
    for (std::size_t i = 0; i < a.positions.size(); ++i) EXPECT_EQ(a.positions[i], b.positions[i]) << i;
    for (std::size_t i = 0; i < a.normals.size(); ++i) expectNear(a.normals[i], b.normals[i], normalTol);
    for (std::size_t i = 0; i < a.uvs.size(); ++i) EXPECT_EQ(a.uvs[i], b.uvs[i]);
    EXPECT_EQ(a.triangles, b.triangles);
    EXPECT_EQ(a.triangleMaterial, b.triangleMaterial);
    ASSERT_EQ(a.materials.size(), b.materials.size());
    for (std::size_t i = 0; i < a.materials.size(); ++i) {
        const auto &x = a.materials[i], &y = b.materials[i];
        EXPECT_EQ(x.baseColor, y.baseColor) << "material " << i;
        EXPECT_EQ(x.emissive, y.emissive) << "material " << i;
        EXPECT_EQ(x.metallic, y.metallic);
        EXPECT_EQ(x.roughness, y.roughness);
        EXPECT_EQ(x.specular, y.specular);
        EXPECT_EQ(x.specularColor, y.specularColor);
        EXPECT_EQ(x.ior, y.ior);
        EXPECT_EQ(x.flags, y.flags);
        EXPECT_EQ(x.baseColorTex, y.baseColorTex);
    }
    ASSERT_EQ(a.cameras.size(), b.cameras.size());
    for (std::size_t i = 0; i < a.cameras.size(); ++i) {
        EXPECT_EQ(a.cameras[i].position, b.cameras[i].position);
        EXPECT_EQ(a.cameras[i].forward, b.cameras[i].forward);
        EXPECT_EQ(a.cameras[i].up, b.cameras[i].up);
        EXPECT_EQ(a.cameras[i].yfov, b.cameras[i].yfov);
        EXPECT_EQ(a.cameras[i].aspectRatio, b.cameras[i].aspectRatio);
    }
}

// ---------------------------------------------------------------------------------------
// The shared Cornell box and our own scenes/
// ---------------------------------------------------------------------------------------

// ../shared/scenes/cbox/cbox.gltf: the Cornell box in Bitterli's layout, the scene of the
// independent reference image that tests/gpu/integrator/test_cbox_reference.cpp compares against (data
// outside the repository, so that gdpt's tests cannot have shaped it).
std::string sharedCbox() {
    return test::sharedDataPath("scenes/cbox/cbox.gltf");
}

TEST(GltfLoader, SharedCornellBox) {
    GDPT_REQUIRE_SHARED_DATA(sharedCbox());
    const Scene s = loadGltf(sharedCbox());
    // 5 walls x 2 + 2 boxes x 12 + light x 2.
    EXPECT_EQ(s.triangles.size(), 36u);
    EXPECT_EQ(s.triangleMaterial.size(), 36u);
    EXPECT_EQ(s.normals.size(), s.positions.size());
    EXPECT_TRUE(s.uvs.empty());
    const Bounds b = s.bounds();
    EXPECT_EQ(b.min, glm::vec3(-1, 0, -1));
    EXPECT_EQ(b.max, glm::vec3(1, 2, 1));
    ASSERT_EQ(s.materials.size(), 4u);
    // The light triangles are the last two and face down (-Y).
    const gpu::Material& light = s.materials[s.triangleMaterial[35]];
    expectNear(light.emissive, {17, 12, 4}, 1e-5f);
    EXPECT_TRUE(light.flags & gpu::kMatFlagEmissive);
    expectNear(faceNormal(s, 35), {0, -1, 0}, 1e-6f);
    // Diffuse walls: pure Lambertian (metallic 0, KHR_materials_specular factor 0).
    EXPECT_EQ(s.materials[0].metallic, 0.0f);
    EXPECT_EQ(s.materials[0].specular, 0.0f);
    EXPECT_EQ(s.materials[0].flags & gpu::kMatFlagEmissive, 0u);
    ASSERT_EQ(s.cameras.size(), 1u);
    expectNear(s.cameras[0].position, {0, 1, 6.8f}, 1e-6f);
    expectNear(s.cameras[0].forward, {0, 0, -1}, 1e-6f);
    expectNear(s.cameras[0].up, {0, 1, 0}, 1e-6f);
    EXPECT_NEAR(s.cameras[0].yfov, 19.5 * glm::pi<double>() / 180.0, 1e-6);
    EXPECT_TRUE(s.unsupported.empty()) << describeScene(s);
}

TEST(GltfLoader, SharedCornellBoxMatchesProcedural) {
    GDPT_REQUIRE_SHARED_DATA(sharedCbox());
    // Normals: the file's are normalised in double by its generator, ours in float.
    expectSameScene(loadGltf(sharedCbox()), makeCornellBox(), 2e-7f);
}

TEST(GltfLoader, OwnCornellBoxMatchesProcedural) {
    expectSameScene(loadGltf(std::string(GDPT_SOURCE_DIR) + "/scenes/cornell_box.gltf"), makeCornellBox(),
                    2e-7f);
}

TEST(GltfLoader, OwnGlossyAndFurnaceScenesLoadCleanly) {
    const Scene glossy = loadGltf(std::string(GDPT_SOURCE_DIR) + "/scenes/glossy_cornell.gltf");
    EXPECT_TRUE(glossy.unsupported.empty()) << describeScene(glossy);
    bool rough = false, mirror = false;
    for (const auto& m : glossy.materials) {
        rough = rough || (m.metallic == 1.0f && m.roughness == 0.3f);
        mirror = mirror || (m.metallic == 1.0f && m.roughness == 0.0f);
    }
    EXPECT_TRUE(rough && mirror);
    const Scene furnace = loadGltf(std::string(GDPT_SOURCE_DIR) + "/scenes/furnace.gltf");
    EXPECT_EQ(furnace.triangles.size(), 1280u);
    ASSERT_EQ(furnace.materials.size(), 1u);
    expectNear(furnace.materials[0].emissive, glm::vec3(0.5f), 0.0f);
    // Inward-facing: every face normal points towards the centre (the origin).
    for (std::size_t t = 0; t < furnace.triangles.size(); ++t)
        EXPECT_LT(glm::dot(faceNormal(furnace, t), furnace.positions[furnace.triangles[t].x]), 0.0f);
}

// ---------------------------------------------------------------------------------------
// Node transforms
// ---------------------------------------------------------------------------------------

TEST(GltfLoader, NestedTrsAndMatrixTransforms) {
    TestGltf g;
    // Triangle (0,0,0),(1,0,0),(0,1,0) with normal (1,1,0)/sqrt2 at every vertex.
    const float r = 1.0f / std::sqrt(2.0f);
    const int mesh =
        g.addMesh({g.primitive(test::unitTriangle(), {0, 1, 2}, 4, {{r, r, 0}, {r, r, 0}, {r, r, 0}})});
    // Child: matrix = translation (0,0,1) (column-major, translation in elements 12..14).
    const int child =
        g.addNode({{"mesh", mesh}, {"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 1, 1}}});
    // Parent: T (1,2,3) * R (90° about +Y: quaternion (0, sin45, 0, cos45)) * S (2,1,1).
    const int parent = g.addNode({{"children", {child}},
                                  {"translation", {1, 2, 3}},
                                  {"rotation", {0, r, 0, r}},
                                  {"scale", {2, 1, 1}}});
    g.setScene({parent});
    const Scene s = loadGltf(g.writeGltf(test::testDir(), "trs"));
    ASSERT_EQ(s.positions.size(), 3u);
    // p' = T R S (p + (0,0,1)); R maps (x,y,z) -> (z, y, -x).
    // (0,0,0) -> (0,0,1) -> S (0,0,1) -> R (1,0,0) -> T (2,2,3)
    // (1,0,0) -> (1,0,1) -> S (2,0,1) -> R (1,0,-2) -> T (2,2,1)
    // (0,1,0) -> (0,1,1) -> S (0,1,1) -> R (1,1,0) -> T (2,3,3)
    expectNear(s.positions[0], {2, 2, 3}, 1e-5f);
    expectNear(s.positions[1], {2, 2, 1}, 1e-5f);
    expectNear(s.positions[2], {2, 3, 3}, 1e-5f);
    // Normal: inverse-transpose of R S = R S^-1: (1,1,0) -> S^-1 (0.5,1,0) -> R (0,1,-0.5),
    // normalised: (0, 2, -1)/sqrt5. Not simply R S n, which would give (0,1,-2)/sqrt5.
    const glm::vec3 expected = glm::vec3(0, 2, -1) / std::sqrt(5.0f);
    for (const auto& n : s.normals) expectNear(n, expected, 1e-5f);
}

TEST(GltfLoader, NegativeScaleFlipsWinding) {
    for (const bool mirror : {false, true}) {
        auto g = test::oneTriangle();
        if (mirror) g.doc["nodes"][0]["scale"] = {-1, 1, 1};
        const Scene s = loadGltf(g.writeGltf(test::testDir(), mirror ? "mirror" : "plain"));
        ASSERT_EQ(s.triangles.size(), 1u);
        // Mirroring x leaves the +Z normal unchanged; the winding must follow it so the
        // counter-clockwise (front) side still faces +Z.
        expectNear(s.normals[0], {0, 0, 1}, 1e-6f);
        expectNear(faceNormal(s, 0), {0, 0, 1}, 1e-6f, mirror ? "mirrored" : "plain");
    }
}

TEST(GltfLoader, GltfAndGlbGiveIdenticalScenes) {
    TestGltf g;
    const int mat = g.addMaterial({{"pbrMetallicRoughness", {{"baseColorFactor", {0.2, 0.3, 0.4, 1}}}},
                                   {"emissiveFactor", {1, 0.5, 0}}});
    auto prim = g.primitive({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, {0, 1, 2, 0, 2, 3}, 4,
                            {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}}, mat);
    prim["attributes"]["TEXCOORD_0"] = g.addVec2({{0, 0}, {1, 0}, {1, 1}, {0, 1}});
    const int mesh = g.addMesh({prim, g.primitive(test::unitTriangle(), {}, 5)});
    g.setScene({g.addNode({{"mesh", mesh}, {"translation", {0.5, 0, 0}}})});
    const std::string dir = test::testDir();
    const Scene a = loadGltf(g.writeGltf(dir, "same"));
    const Scene b = loadGltf(g.writeGlb(dir, "same"));
    EXPECT_EQ(a.triangles.size(), 3u);
    EXPECT_EQ(a.uvs.size(), a.positions.size());
    expectSameScene(a, b, 0.0f);
}

// ---------------------------------------------------------------------------------------
// Topology and attributes
// ---------------------------------------------------------------------------------------

TEST(GltfLoader, StripsAndFansBecomeTriangles) {
    TestGltf g;
    // Strip over a row of quads: v0=(0,0) v1=(0,1) v2=(1,0) v3=(1,1) v4=(2,0).
    const std::vector<glm::vec3> strip = {{0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {1, 1, 0}, {2, 0, 0}};
    // Fan around the origin: centre then 5 rim points counter-clockwise.
    std::vector<glm::vec3> fan = {{0, 0, 0}};
    for (int i = 0; i < 5; ++i) fan.emplace_back(std::cos(0.3f * float(i)), std::sin(0.3f * float(i)), 0.0f);
    const int mesh = g.addMesh({g.primitive(strip, {0, 1, 2, 3, 4}, 5),  // indexed strip
                                g.primitive(fan, {}, 6)});               // non-indexed fan
    g.setScene({g.addNode({{"mesh", mesh}})});
    const Scene s = loadGltf(g.writeGltf(test::testDir(), "strip"));
    // Strip: n-2 = 3 triangles, §3.7.2.1: (0,1,2), (1,3,2), (2,3,4) — alternate ones reversed
    // so that all keep the same orientation. Fan: 4 triangles (1,2,0), (2,3,0), ...
    ASSERT_EQ(s.triangles.size(), 7u);
    EXPECT_EQ(s.triangles[0], glm::uvec3(0, 1, 2));
    EXPECT_EQ(s.triangles[1], glm::uvec3(1, 3, 2));
    EXPECT_EQ(s.triangles[2], glm::uvec3(2, 3, 4));
    EXPECT_EQ(s.triangles[3], glm::uvec3(6, 7, 5));
    EXPECT_EQ(s.triangles[6], glm::uvec3(9, 10, 5));
    // The strip here winds clockwise seen from +Z, the fan counter-clockwise: consistent.
    for (int t = 0; t < 3; ++t) expectNear(faceNormal(s, std::size_t(t)), {0, 0, -1}, 1e-6f);
    for (int t = 3; t < 7; ++t) expectNear(faceNormal(s, std::size_t(t)), {0, 0, 1}, 1e-6f);
}

TEST(GltfLoader, LinesArePointsAreReportedNotRendered) {
    TestGltf g;
    const int mesh =
        g.addMesh({g.primitive(test::unitTriangle(), {}, 1), g.primitive(test::unitTriangle(), {}, 0),
                   g.primitive(test::unitTriangle(), {}, 4)},
                  "Mixed");
    g.setScene({g.addNode({{"mesh", mesh}})});
    const Scene s = loadGltf(g.writeGltf(test::testDir(), "lines"));
    EXPECT_EQ(s.triangles.size(), 1u);
    EXPECT_TRUE(hasUnsupported(s, "mesh 'Mixed' primitive 0: mode 1 (LINES)"));
    EXPECT_TRUE(hasUnsupported(s, "mesh 'Mixed' primitive 1: mode 0 (POINTS)"));
}

TEST(GltfLoader, MissingNormalsBecomeFlatWhereOthersHaveThem) {
    TestGltf g;
    // A bent pair of triangles without normals sharing an edge, plus one triangle with normals.
    const std::vector<glm::vec3> bent = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, -1}};
    const int mesh = g.addMesh({g.primitive(bent, {0, 1, 2, 0, 2, 3}),
                                g.primitive(test::unitTriangle(), {0, 1, 2}, 4, test::plusZNormals())});
    g.setScene({g.addNode({{"mesh", mesh}})});
    const Scene s = loadGltf(g.writeGltf(test::testDir(), "flat"));
    ASSERT_EQ(s.normals.size(), s.positions.size());
    ASSERT_EQ(s.positions.size(), 6u + 3u);  // 2 unwelded triangles + 3 shared vertices
    // Flat normals: triangle 0 faces +Z; triangle 1 (0,2,3) has normal
    // (0,1,0) x (0,0,-1) = (-1,0,0); no averaging across the shared edge.
    for (int k = 0; k < 3; ++k) expectNear(s.normals[s.triangles[0][k]], {0, 0, 1}, 1e-6f);
    for (int k = 0; k < 3; ++k) expectNear(s.normals[s.triangles[1][k]], {-1, 0, 0}, 1e-6f);

    // Without normals anywhere, Scene::normals stays empty and vertices stay shared.
    TestGltf h;
    h.setScene({h.addNode({{"mesh", h.addMesh({h.primitive(bent, {0, 1, 2, 0, 2, 3})})}})});
    const Scene t = loadGltf(h.writeGltf(test::testDir(), "none"));
    EXPECT_TRUE(t.normals.empty());
    EXPECT_EQ(t.positions.size(), 4u);
}

TEST(GltfLoader, SparseAccessorAndStridedView) {
    TestGltf g;
    // Interleaved-style strided view: positions 12 bytes + 4 padding bytes each.
    std::vector<float> data = {0, 0, 0, -1, 9, 9, 9, -1, 0, 1, 0, -1};
    const int view = g.addView(data.data(), data.size() * 4, 16);
    const int acc = g.addAccessor(view, test::kFloat, 3, "VEC3");
    // Sparse: replace element 1 (9,9,9) by (1,0,0).
    const std::uint32_t sparseIdx[1] = {1};
    const float sparseVal[3] = {1, 0, 0};
    const int iv = g.addView(sparseIdx, 4), vv = g.addView(sparseVal, 12);
    g.doc["accessors"][static_cast<std::size_t>(acc)]["sparse"] = {
        {"count", 1},
        {"indices", {{"bufferView", iv}, {"componentType", test::kUInt}}},
        {"values", {{"bufferView", vv}}}};
    g.doc["meshes"].push_back({{"primitives", {{{"attributes", {{"POSITION", acc}}}}}}});
    g.setScene({g.addNode({{"mesh", 0}})});
    const Scene s = loadGltf(g.writeGltf(test::testDir(), "sparse"));
    ASSERT_EQ(s.positions.size(), 3u);
    EXPECT_EQ(s.positions[1], glm::vec3(1, 0, 0));
    EXPECT_EQ(s.positions[2], glm::vec3(0, 1, 0));
}

// ---------------------------------------------------------------------------------------
// Materials, textures, lights, cameras, scenes
// ---------------------------------------------------------------------------------------

TEST(GltfLoader, MaterialsAndDefaults) {
    TestGltf g;
    const int m = g.addMaterial(
        {{"name", "Glow"},
         {"pbrMetallicRoughness",
          {{"baseColorFactor", {0.5, 0.25, 1, 0.8}}, {"metallicFactor", 0.3}, {"roughnessFactor", 0.6}}},
         {"emissiveFactor", {1, 0.5, 0.25}},
         {"alphaMode", "MASK"},
         {"alphaCutoff", 0.3},
         {"doubleSided", true},
         {"extensions",
          {{"KHR_materials_emissive_strength", {{"emissiveStrength", 4}}},
           {"KHR_materials_specular", {{"specularFactor", 0.7}, {"specularColorFactor", {1, 0.5, 0.5}}}},
           {"KHR_materials_ior", {{"ior", 1.33}}}}}});
    const int mesh = g.addMesh({g.primitive(test::unitTriangle(), {}, 4, {}, m),
                                g.primitive(test::unitTriangle(), {})});  // no material
    g.setScene({g.addNode({{"mesh", mesh}})});
    const Scene s = loadGltf(g.writeGltf(test::testDir(), "mat"));
    ASSERT_EQ(s.materials.size(), 2u);
    const auto& a = s.materials[s.triangleMaterial[0]];
    EXPECT_EQ(a.baseColor, glm::vec4(0.5f, 0.25f, 1.0f, 0.8f));
    EXPECT_FLOAT_EQ(a.metallic, 0.3f);
    EXPECT_FLOAT_EQ(a.roughness, 0.6f);
    EXPECT_EQ(a.emissive, glm::vec3(4.0f, 2.0f, 1.0f));
    EXPECT_FLOAT_EQ(a.specular, 0.7f);
    EXPECT_EQ(a.specularColor, glm::vec3(1.0f, 0.5f, 0.5f));
    EXPECT_FLOAT_EQ(a.ior, 1.33f);
    EXPECT_FLOAT_EQ(a.alphaCutoff, 0.3f);
    EXPECT_EQ(a.flags, gpu::kMatFlagAlphaMask | gpu::kMatFlagDoubleSided | gpu::kMatFlagEmissive);
    // glTF default material (§5.19 defaults): white, metallic 1, roughness 1, no emission;
    // extension defaults specular 1, specularColor 1, ior 1.5.
    const auto& d = s.materials[s.triangleMaterial[1]];
    EXPECT_EQ(d.baseColor, glm::vec4(1.0f));
    EXPECT_EQ(d.metallic, 1.0f);
    EXPECT_EQ(d.roughness, 1.0f);
    EXPECT_EQ(d.emissive, glm::vec3(0.0f));
    EXPECT_EQ(d.specular, 1.0f);
    EXPECT_EQ(d.specularColor, glm::vec3(1.0f));
    EXPECT_EQ(d.ior, 1.5f);
    EXPECT_EQ(d.flags, 0u);
    EXPECT_EQ(d.baseColorTex, -1);
}

std::vector<unsigned char> encodePng(int w, int h, const std::vector<unsigned char>& rgba) {
    std::vector<unsigned char> out;
    stbi_write_png_to_func(
        [](void* ctx, void* data, int size) {
            auto* v = static_cast<std::vector<unsigned char>*>(ctx);
            v->insert(v->end(), static_cast<unsigned char*>(data), static_cast<unsigned char*>(data) + size);
        },
        &out, w, h, 4, rgba.data(), w * 4);
    return out;
}

TEST(GltfLoader, TexturesDecodedSrgbAndLinear) {
    TestGltf g;
    // 2x2 RGBA: top row (128,0,255,255) (255,255,255,128); bottom row black, grey 64.
    const auto png = encodePng(2, 2, {128, 0, 255, 255, 255, 255, 255, 128, 0, 0, 0, 255, 64, 64, 64, 255});
    const int view = g.addView(png.data(), png.size());
    g.doc["images"] = nlohmann::json::array({{{"bufferView", view}, {"mimeType", "image/png"}}});
    g.doc["samplers"] = nlohmann::json::array({{{"wrapS", 33071}}});  // CLAMP_TO_EDGE
    g.doc["textures"] = nlohmann::json::array({{{"source", 0}, {"sampler", 0}}});
    const int m =
        g.addMaterial({{"pbrMetallicRoughness",
                        {{"baseColorTexture", {{"index", 0}}}, {"metallicRoughnessTexture", {{"index", 0}}}}},
                       {"normalTexture", {{"index", 0}}}});
    const int mesh = g.addMesh({g.primitive(test::unitTriangle(), {}, 4, {}, m)});
    g.setScene({g.addNode({{"mesh", mesh}})});
    const Scene s = loadGltf(g.writeGlb(test::testDir(), "tex"));
    // One image used as sRGB colour and as linear data: two textures; normal map shares the
    // linear one.
    ASSERT_EQ(s.textures.size(), 2u);
    const auto& mat = s.materials[0];
    const Texture& srgb = s.textures[static_cast<std::size_t>(mat.baseColorTex)];
    const Texture& lin = s.textures[static_cast<std::size_t>(mat.metallicRoughnessTex)];
    EXPECT_EQ(mat.normalTex, mat.metallicRoughnessTex);
    ASSERT_EQ(srgb.width, 2);
    ASSERT_EQ(srgb.height, 2);
    // sRGB 128/255 = 0.50196 -> ((0.50196+0.055)/1.055)^2.4 = 0.21586 (IEC 61966-2-1).
    EXPECT_NEAR(srgb.texels[0].r, 0.21586f, 1e-4f);
    EXPECT_EQ(srgb.texels[0].b, 1.0f);
    EXPECT_NEAR(srgb.texels[1].a, 128.0f / 255.0f, 1e-6f);  // alpha stays linear
    EXPECT_NEAR(srgb.texels[3].r, 0.05127f, 1e-4f);         // sRGB 64 -> 0.05127, bottom row
    EXPECT_NEAR(lin.texels[0].r, 128.0f / 255.0f, 1e-6f);
    EXPECT_NEAR(lin.texels[3].g, 64.0f / 255.0f, 1e-6f);
    EXPECT_TRUE(hasUnsupported(s, "normal textures are ignored"));
    EXPECT_TRUE(hasUnsupported(s, "wrap modes other than REPEAT"));
}

TEST(GltfLoader, PunctualLightsFromNodes) {
    auto g = test::oneTriangle();
    g.doc["extensionsUsed"] = {"KHR_lights_punctual"};
    g.doc["extensions"]["KHR_lights_punctual"]["lights"] = {
        {{"type", "point"}, {"color", {1, 0.5, 0.25}}, {"intensity", 8}},
        {{"type", "spot"},
         {"intensity", 2},
         {"range", 10},
         {"spot", {{"innerConeAngle", 0.2}, {"outerConeAngle", 0.4}}}},
        {{"type", "directional"}, {"name", "Sun"}}};
    const float r = 1.0f / std::sqrt(2.0f);
    const int p =
        g.addNode({{"translation", {1, 2, 3}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
    // Spot rotated -90° about X: local -Z points to world -Y (straight down).
    const int sp = g.addNode({{"translation", {0, 5, 0}},
                              {"rotation", {-r, 0, 0, r}},
                              {"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}});
    const int sun = g.addNode({{"extensions", {{"KHR_lights_punctual", {{"light", 2}}}}}});
    g.setScene({0, p, sp, sun});
    const Scene s = loadGltf(g.writeGltf(test::testDir(), "lights"));
    ASSERT_EQ(s.punctualLights.size(), 2u);
    EXPECT_EQ(s.punctualLights[0].type, gpu::kPunctualPoint);
    expectNear(s.punctualLights[0].position, {1, 2, 3}, 1e-6f);
    expectNear(s.punctualLights[0].intensity, {8, 4, 2}, 1e-6f);
    EXPECT_EQ(s.punctualLights[1].type, gpu::kPunctualSpot);
    expectNear(s.punctualLights[1].direction, {0, -1, 0}, 1e-6f);
    EXPECT_NEAR(s.punctualLights[1].cosInner, std::cos(0.2f), 1e-6f);
    EXPECT_NEAR(s.punctualLights[1].cosOuter, std::cos(0.4f), 1e-6f);
    expectNear(s.punctualLights[1].intensity, {2, 2, 2}, 1e-6f);
    EXPECT_TRUE(hasUnsupported(s, "light 'Sun': directional lights"));
    EXPECT_TRUE(hasUnsupported(s, "range ignored"));
}

TEST(GltfLoader, CamerasInTraversalOrder) {
    auto g = test::oneTriangle();
    g.doc["cameras"] = {
        {{"name", "A"},
         {"type", "perspective"},
         {"perspective", {{"yfov", 0.5}, {"znear", 0.1}, {"aspectRatio", 1.5}}}},
        {{"name", "B"}, {"type", "perspective"}, {"perspective", {{"yfov", 0.7}, {"znear", 0.1}}}},
        {{"name", "O"},
         {"type", "orthographic"},
         {"orthographic", {{"xmag", 1}, {"ymag", 1}, {"znear", 0.1}, {"zfar", 10}}}}};
    const float r = 1.0f / std::sqrt(2.0f);
    // Camera B sits under a parent translated by (0,0,5), rotated +90° about Y: local -Z
    // becomes world -X, local +Y stays +Y.
    const int camB = g.addNode({{"camera", 1}, {"rotation", {0, r, 0, r}}});
    const int parent = g.addNode({{"translation", {0, 0, 5}}, {"children", {camB}}});
    const int camA = g.addNode({{"camera", 0}, {"translation", {1, 1, 1}}});
    const int camO = g.addNode({{"camera", 2}});
    g.setScene({0, parent, camA, camO});
    const Scene s = loadGltf(g.writeGltf(test::testDir(), "cams"));
    ASSERT_EQ(s.cameras.size(), 2u);
    EXPECT_EQ(s.cameras[0].name, "B");
    expectNear(s.cameras[0].position, {0, 0, 5}, 1e-6f);
    expectNear(s.cameras[0].forward, {-1, 0, 0}, 1e-6f);
    expectNear(s.cameras[0].up, {0, 1, 0}, 1e-6f);
    EXPECT_FLOAT_EQ(s.cameras[0].yfov, 0.7f);
    EXPECT_EQ(s.cameras[0].aspectRatio, 0.0f);
    EXPECT_EQ(s.cameras[1].name, "A");
    EXPECT_FLOAT_EQ(s.cameras[1].aspectRatio, 1.5f);
    EXPECT_TRUE(hasUnsupported(s, "camera 'O': orthographic"));
}

TEST(GltfLoader, SceneSelection) {
    auto g = test::oneTriangle();
    const int other = g.addNode({{"mesh", 0}, {"translation", {10, 0, 0}}});
    g.doc["scenes"] = {{{"nodes", {0}}}, {{"nodes", {other}}}};
    g.doc["scene"] = 1;
    const Scene s = loadGltf(g.writeGltf(test::testDir(), "sel"));
    ASSERT_EQ(s.triangles.size(), 1u);
    EXPECT_EQ(s.positions[0].x, 10.0f);
    // No scenes at all: every root node is rendered.
    g.doc.erase("scenes");
    g.doc.erase("scene");
    EXPECT_EQ(loadGltf(g.writeGltf(test::testDir(), "noscene")).triangles.size(), 2u);
}

TEST(GltfLoader, UnsupportedFeaturesAreReported) {
    auto g = test::oneTriangle();
    g.doc["extensionsUsed"] = {"KHR_materials_transmission", "KHR_materials_clearcoat",
                               "KHR_texture_transform"};
    g.doc["images"] = nlohmann::json::array();
    g.addMaterial({{"alphaMode", "BLEND"},
                   {"extensions", {{"KHR_materials_sheen", nlohmann::json::object()}}},
                   {"occlusionTexture", {{"index", 0}}}});
    g.doc["meshes"][0]["primitives"][0]["material"] = 0;
    g.doc["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"] = 0;
    g.doc["meshes"][0]["primitives"][0]["targets"] = {{{"POSITION", 0}}};
    g.doc["skins"] = {{{"joints", {0}}}};
    const Scene s = loadGltf(g.writeGltf(test::testDir(), "unsup"));
    EXPECT_EQ(s.triangles.size(), 1u);  // still rendered
    for (const char* needle :
         {"extension KHR_materials_transmission", "extension KHR_materials_clearcoat",
          "extension KHR_texture_transform", "alphaMode BLEND", "material extension KHR_materials_sheen",
          "occlusionTexture", "COLOR_0", "morph targets", "skins"})
        EXPECT_TRUE(hasUnsupported(s, needle)) << needle << "\n" << describeScene(s);
}

TEST(GltfLoader, DefaultCameraFramesBounds) {
    Scene s;
    s.positions = {{-1, -1, -1}, {1, 1, 1}};
    const Camera c = defaultCamera(s);
    // Bounding sphere radius sqrt3 must fit yfov 45°: distance sqrt3 / sin(22.5°) = 4.526.
    expectNear(c.position, {0, 0, std::sqrt(3.0f) / std::sin(glm::radians(22.5f))}, 1e-4f);
    expectNear(c.forward, {0, 0, -1}, 0.0f);
    EXPECT_FLOAT_EQ(c.yfov, glm::radians(45.0f));
}

}  // namespace
}  // namespace gdpt
