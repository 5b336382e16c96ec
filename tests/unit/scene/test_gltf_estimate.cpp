// test_gltf_estimate.cpp — the scene size known before loading (estimateGltf,
// LoadOptions::checkEstimate) and progress while loading large scenes. Class guarded: a
// 29.4M-triangle scene was refused by the device's texel limit only after 125 s and 7 GB, with
// no output meanwhile; the estimate lets a caller refuse it from the JSON alone.
#include <gtest/gtest.h>

#include <string>

#include "gltf_test_writer.h"
#include "scene/gltf_loader.h"
#include "util/error.h"

namespace gdpt {
namespace {

using test::TestGltf;

// Vertices 0..n-1 on a fan around the origin (no three collinear), z = 0.
std::vector<glm::vec3> fanVertices(int n) {
    std::vector<glm::vec3> v;
    for (int i = 0; i < n; ++i)
        v.emplace_back(std::cos(0.7f * float(i)) * float(1 + i), std::sin(0.7f * float(i)) * float(1 + i),
                       0.0f);
    return v;
}

// Mesh A: a TRIANGLES primitive (4 vertices, 6 indices: 2 triangles), a strip (5 vertices: 3
// triangles) and LINES (not read); mesh B: a non-indexed fan (5 vertices: 3 triangles). Node 0
// (A) has children 1 (A) and 2 (B); node 3 (B) is in no scene. Instanced: 2 x (2 + 3) + 3 = 13
// triangles and 2 x (4 + 5) + 5 = 23 vertices.
TestGltf instancedScene() {
    TestGltf g;
    const int a = g.addMesh({g.primitive(fanVertices(4), {0, 1, 2, 0, 2, 3}, 4),
                             g.primitive(fanVertices(5), {}, 5), g.primitive(fanVertices(2), {}, 1)},
                            "A");
    const int b = g.addMesh({g.primitive(fanVertices(5), {}, 6)}, "B");
    const int n1 = g.addNode({{"mesh", a}, {"translation", {10, 0, 0}}});
    const int n2 = g.addNode({{"mesh", b}, {"translation", {0, 10, 0}}});
    const int n0 = g.addNode({{"mesh", a}, {"children", {n1, n2}}});
    g.addNode({{"mesh", b}});
    g.setScene({n0});
    return g;
}

TEST(GltfEstimate, CountsInstancedTrianglesFromTheJsonAlone) {
    const std::string dir = test::testDir();
    auto g = instancedScene();
    const std::string gltf = g.writeGltf(dir, "scene");
    const std::string glb = g.writeGlb(dir, "scene");
    const Scene loaded = loadGltf(gltf);
    EXPECT_EQ(loaded.triangles.size(), 13u);
    EXPECT_EQ(loaded.positions.size(), 23u);

    // Without the buffers (the .bin deleted, the .glb's BIN chunk cut off) the estimate is the
    // same: it reads only the JSON.
    std::filesystem::remove(dir + "/scene.bin");
    std::filesystem::resize_file(glb, std::filesystem::file_size(glb) - 64);
    for (const std::string& path : {gltf, glb}) {
        const SceneEstimate e = estimateGltf(path);
        EXPECT_EQ(e.triangles, 13u) << path;
        EXPECT_EQ(e.vertices, 23u) << path;
        EXPECT_GE(e.bytes, 13u * 16u + 23u * 12u) << path;
        EXPECT_THROW((void)loadGltf(path), Error) << path;
    }
}

// A primitive without normals in a scene with normals gets three vertices per triangle (flat
// normals); the estimate counts them as the loader makes them.
TEST(GltfEstimate, CountsFlatShadedVertices) {
    TestGltf g;
    const int smooth = g.addMesh({g.primitive(test::unitTriangle(), {0, 1, 2}, 4, test::plusZNormals())});
    const int flat = g.addMesh({g.primitive(fanVertices(5), {0, 1, 2, 0, 2, 3, 0, 3, 4})});
    g.setScene({g.addNode({{"mesh", smooth}}), g.addNode({{"mesh", flat}})});
    const std::string path = g.writeGltf(test::testDir(), "flat");
    const SceneEstimate e = estimateGltf(path);
    const Scene s = loadGltf(path);
    EXPECT_EQ(e.triangles, 4u);
    EXPECT_EQ(e.vertices, 3u + 9u);
    EXPECT_EQ(s.positions.size(), e.vertices);
}

// The caller's check sees the estimate before any buffer is read: with the .bin missing, its
// refusal (prefixed with the file) comes instead of the missing-file error.
TEST(GltfEstimate, CheckEstimateRefusesBeforeBuffersAreRead) {
    const std::string dir = test::testDir();
    auto g = instancedScene();
    const std::string path = g.writeGltf(dir, "scene");
    std::filesystem::remove(dir + "/scene.bin");
    LoadOptions opts;
    std::uint64_t seen = 0;
    opts.checkEstimate = [&](const SceneEstimate& e) {
        seen = e.triangles;
        if (e.triangles > 10) throw Error("more than 10 triangles");
    };
    try {
        (void)loadGltf(path, opts);
        FAIL() << "loaded";
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()), path + ": more than 10 triangles");
    }
    EXPECT_EQ(seen, 13u);
}

// The memory budget is compared with the estimate before loading.
TEST(GltfEstimate, MemoryBudgetRefusesFromTheEstimate) {
    auto g = instancedScene();
    const std::string path = g.writeGltf(test::testDir(), "scene");
    LoadOptions opts;
    opts.memoryBudget = estimateGltf(path).bytes - 1;
    EXPECT_THROW((void)loadGltf(path, opts), Error);
    opts.memoryBudget += 1;
    EXPECT_EQ(loadGltf(path, opts).triangles.size(), 13u);
}

// Progress on stderr while loading a scene of at least progressTriangles triangles, and none
// when quiet.
TEST(GltfEstimate, ProgressIsShownForLargeScenesUnlessQuiet) {
    auto g = instancedScene();
    const std::string path = g.writeGltf(test::testDir(), "scene");
    LoadOptions opts;
    opts.progressTriangles = 13;
    ::testing::internal::CaptureStderr();
    (void)loadGltf(path, opts);
    const std::string shown = ::testing::internal::GetCapturedStderr();
    EXPECT_NE(shown.find("loading " + path), std::string::npos) << shown;
    EXPECT_NE(shown.find("13 triangles"), std::string::npos) << shown;

    opts.quiet = true;
    ::testing::internal::CaptureStderr();
    (void)loadGltf(path, opts);
    EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");

    opts.quiet = false;
    opts.progressTriangles = 14;
    ::testing::internal::CaptureStderr();
    (void)loadGltf(path, opts);
    EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
}

}  // namespace
}  // namespace gdpt
