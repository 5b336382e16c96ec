// test_gltf_scale.cpp — scenes too large or too small for single-precision geometry are
// refused with the supported range, and an out-of-range vertex is reported as what it is.
#include <gtest/gtest.h>

#include <string>

#include "gltf_test_writer.h"
#include "scene/gltf_loader.h"
#include "util/error.h"

namespace gdpt {
namespace {

using test::TestGltf;

// oneTriangle (1 unit across) under a root node scaled by `k`.
TestGltf scaledTriangle(double k) {
    auto g = test::oneTriangle();
    g.doc["cameras"] =
        nlohmann::json::array({{{"type", "perspective"}, {"perspective", {{"yfov", 0.5}, {"znear", 0.1}}}}});
    const int cam = g.addNode({{"camera", 0}, {"translation", {0.3, 0.3, 3}}});
    const int root = g.addNode({{"name", "Root"}, {"scale", {k, k, k}}, {"children", {0, cam}}});
    g.setScene({root});
    return g;
}

// Class: scene scale. At 1e10 or 1e-12 the scene rendered black without a word: triangle
// normals and areas come from |e1 x e2|, whose square overflows or underflows single
// precision. Such scenes are refused with the supported range (a camera under the tiny scale
// is no longer reported as a "degenerate camera transform" instead).
TEST(GltfScale, ScenesOutsideTheSupportedSizeAreRefusedWithTheRange) {
    const std::string dir = test::testDir();
    for (const double k : {1e-12, 1e-10}) {
        const std::string path = scaledTriangle(k).writeGltf(dir, "tiny");
        const std::string msg = test::loadError(path);
        EXPECT_NE(msg.find(path + ": the scene is "), std::string::npos) << msg;
        EXPECT_NE(msg.find("units across; gdpt renders scenes from 4.7e-10 to 2.1e+09 units across"),
                  std::string::npos)
            << msg;
    }
    const std::string path = scaledTriangle(1e10).writeGltf(dir, "huge");
    const std::string msg = test::loadError(path);
    EXPECT_NE(msg.find(path + ": mesh 'Tri' primitive 0: vertex 1 is at (1e+10, 0, 0) after the node "
                              "transform, outside the coordinates gdpt "
                              "renders (|x|, |y|, |z| <= 2.1e+09"),
              std::string::npos)
        << msg;
}

// Guards the range's inside: 1e-9 and 1e9 units load.
TEST(GltfScale, ScenesInsideTheSupportedSizeLoad) {
    const std::string dir = test::testDir();
    for (const double k : {1e-9, 1e9}) {
        const Scene s = loadGltf(scaledTriangle(k).writeGltf(dir, "ok"));
        ASSERT_EQ(s.triangles.size(), 1u) << k;
        EXPECT_FLOAT_EQ(s.positions[1].x, static_cast<float>(k));
    }
}

// Class: misleading messages. A finite position of 1e38 was reported as "not finite"; the
// message now says where the vertex is and what range is supported, and only a transform that
// really overflows double precision is reported as an overflow.
TEST(GltfScale, OutOfRangePositionSaysWhatIsWrong) {
    const std::string dir = test::testDir();
    TestGltf g;
    const int mesh = g.addMesh({g.primitive({{0, 0, 0}, {1e38f, 0, 0}, {0, 1, 0}}, {0, 1, 2})}, "Far");
    g.setScene({g.addNode({{"mesh", mesh}})});
    std::string msg = test::loadError(g.writeGltf(dir, "far"));
    EXPECT_NE(
        msg.find("mesh 'Far' primitive 0: vertex 1 is at (1e+38, 0, 0) after the node transform, outside "
                 "the coordinates gdpt renders"),
        std::string::npos)
        << msg;
    EXPECT_EQ(msg.find("not finite"), std::string::npos) << msg;

    g.doc["nodes"][0]["scale"] = {1e300, 1, 1};
    msg = test::loadError(g.writeGltf(dir, "overflow"));
    EXPECT_NE(msg.find("mesh 'Far' primitive 0: vertex 1 overflows after the node transform"),
              std::string::npos)
        << msg;
}

}  // namespace
}  // namespace gdpt
