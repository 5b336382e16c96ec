// glTF animations through the loader (GltfAsset): a posed scene equals, bit for bit, the
// static file with the same pose written into its nodes; the hierarchy, cameras and punctual
// lights follow their animated ancestors; every malformed animation is refused naming the
// animation, channel and sampler; morph-target weights are noted, not applied.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <limits>

#include "gltf_test_writer.h"
#include "scene/gltf_loader.h"

namespace gdpt::test {
namespace {

std::string assetError(const std::string& path) {
    try {
        (void)GltfAsset(path);
        return "";
    } catch (const Error& e) {
        return e.what();
    }
}

// A triangle under a parent node; the parent's translation is animated LINEAR from 0 to
// (2, 0, 0) over 1 s and its rotation STEP to a quarter turn about Z at 1 s; a camera child.
TestGltf animatedFile(nlohmann::json parentStatic = nlohmann::json::object()) {
    TestGltf g;
    const int mesh = g.addMesh({g.primitive(unitTriangle(), {0, 1, 2}, 4, plusZNormals())}, "Tri");
    g.doc["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 0.5}, {"znear", 0.1}}}}};
    const int child = g.addNode({{"name", "Child"}, {"mesh", mesh}, {"translation", {0.0, 1.0, 0.0}}});
    const int cam = g.addNode({{"name", "Cam"}, {"camera", 0}, {"translation", {0.0, 0.0, 5.0}}});
    nlohmann::json parent = {{"name", "Parent"}, {"children", {child, cam}}};
    parent.update(parentStatic);
    const int p = g.addNode(parent);
    g.setScene({p});
    return g;
}

void addMove(TestGltf& g, int node) {
    const int t = g.addVec3({{0, 0, 0}, {2, 0, 0}});
    const float s = std::sqrt(0.5f);
    const int r = g.addVec4({{0, 0, 0, 1}, {0, 0, s, s}});
    g.addAnimation("Move", {{node, "translation", "LINEAR", {0.0f, 1.0f}, t},
                            {node, "rotation", "STEP", {0.0f, 1.0f}, r}});
}

bool sameBits(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(glm::vec3)) == 0;
}

TEST(GltfAnimation, PoseEqualsTheStaticFileOfThatPose) {
    const std::string dir = testDir();
    TestGltf animated = animatedFile();
    addMove(animated, 2);
    const GltfAsset asset(animated.writeGltf(dir, "animated"));
    ASSERT_EQ(asset.animations().size(), 1u);
    EXPECT_EQ(asset.animations()[0].name, "Move");
    EXPECT_DOUBLE_EQ(asset.animations()[0].duration(), 1.0);

    // At 0.5 s: translation (1, 0, 0), rotation still the identity (STEP).
    const Scene posed = asset.instance(0, 0.5);
    const Scene still = loadGltf(animatedFile({{"translation", {1.0, 0.0, 0.0}}}).writeGltf(dir, "still"));
    EXPECT_TRUE(sameBits(posed.positions, still.positions));
    EXPECT_TRUE(sameBits(posed.normals, still.normals));
    ASSERT_EQ(posed.cameras.size(), 1u);
    EXPECT_EQ(posed.cameras[0].position, still.cameras[0].position);
    EXPECT_EQ(posed.positions[0], glm::vec3(1, 1, 0));  // child's (0, 1, 0) + parent's (1, 0, 0)

    // At 1 s (and after): translation (2, 0, 0) and the quarter turn about Z.
    const float s = std::sqrt(0.5f);
    const Scene end = asset.instance(0, 1.0);
    const Scene stillEnd =
        loadGltf(animatedFile({{"translation", {2.0, 0.0, 0.0}}, {"rotation", {0.0, 0.0, s, s}}})
                     .writeGltf(dir, "end"));
    EXPECT_TRUE(sameBits(end.positions, stillEnd.positions));
    EXPECT_TRUE(sameBits(asset.instance(0, 9.0).positions, stillEnd.positions));
    // The child's (0, 1, 0) turned a quarter about Z is (-1, 0, 0); plus (2, 0, 0).
    EXPECT_NEAR(end.positions[0].x, 1.0f, 1e-6f);
    EXPECT_NEAR(end.positions[0].y, 0.0f, 1e-6f);
    // The camera child turns with it: it still looks down -Z, its up is now -X.
    EXPECT_NEAR(end.cameras[0].up.x, -1.0f, 1e-6f);
    EXPECT_NEAR(end.cameras[0].position.x, 2.0f, 1e-6f);
}

TEST(GltfAnimation, RestPoseIsTheStaticScene) {
    const std::string dir = testDir();
    TestGltf animated = animatedFile({{"translation", {0.0, 0.0, 0.0}}});
    addMove(animated, 2);
    const std::string path = animated.writeGltf(dir, "animated");
    const Scene rest = GltfAsset(path).instance();
    EXPECT_TRUE(sameBits(rest.positions, loadGltf(path).positions));
    EXPECT_EQ(rest.positions[0], glm::vec3(0, 1, 0));
    EXPECT_TRUE(rest.unsupported.empty()) << rest.unsupported.front();
}

TEST(GltfAnimation, PunctualLightsFollowTheirNode) {
    const std::string dir = testDir();
    TestGltf g = oneTriangle();
    g.doc["extensionsUsed"] = {"KHR_lights_punctual"};
    g.doc["extensions"]["KHR_lights_punctual"]["lights"] = {{{"type", "point"}, {"intensity", 3.0}}};
    const int light = g.addNode({{"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
    g.setScene({0, light});
    g.addAnimation("", {{light, "translation", "LINEAR", {0.0f, 2.0f}, g.addVec3({{0, 0, 0}, {0, 4, 0}})}});
    const GltfAsset asset(g.writeGltf(dir, "light"));
    ASSERT_EQ(asset.instance(0, 1.5).punctualLights.size(), 1u);
    EXPECT_EQ(asset.instance(0, 1.5).punctualLights[0].position, glm::vec3(0, 3, 0));
}

TEST(GltfAnimation, AnimationsAreFoundByNameOrIndexAndListed) {
    const std::string dir = testDir();
    TestGltf g = animatedFile();
    addMove(g, 2);
    g.addAnimation("Scale",
                   {{0,
                     "scale",
                     "CUBICSPLINE",
                     {0.0f, 3.0f},
                     g.addVec3({{0, 0, 0}, {1, 1, 1}, {0, 0, 0}, {0, 0, 0}, {2, 2, 2}, {0, 0, 0}})}});
    const GltfAsset asset(g.writeGltf(dir, "two"));
    EXPECT_EQ(asset.findAnimation("Move"), 0);
    EXPECT_EQ(asset.findAnimation("Scale"), 1);
    EXPECT_EQ(asset.findAnimation("1"), 1);
    try {
        (void)asset.findAnimation("Walk");
        ADD_FAILURE() << "no error";
    } catch (const UsageError& e) {
        EXPECT_NE(std::string(e.what()).find("has no such animation (it has 0 'Move', 1 'Scale')"),
                  std::string::npos)
            << e.what();
    }
    EXPECT_THROW((void)asset.findAnimation("2"), UsageError);
    const std::string listing = describeAnimations(asset.animations());
    EXPECT_NE(listing.find("animation 0 'Move': 1 s, 2 channels"), std::string::npos) << listing;
    EXPECT_NE(listing.find("node 'Parent' rotation (STEP, 2 keys, 0 to 1 s)"), std::string::npos) << listing;
    EXPECT_NE(listing.find("animation 1 'Scale': 3 s, 1 channel\n  node 'Child' scale (CUBICSPLINE"),
              std::string::npos)
        << listing;
}

TEST(GltfAnimation, MorphWeightsAreNotedNotApplied) {
    const std::string dir = testDir();
    TestGltf g = oneTriangle();
    g.addAnimation("Blend", {{0, "weights", "LINEAR", {0.0f, 1.0f}, g.addScalars({0.0f, 1.0f})}});
    const GltfAsset asset(g.writeGltf(dir, "weights"));
    const Scene s = asset.instance(0, 0.5);
    ASSERT_EQ(s.unsupported.size(), 1u);
    EXPECT_NE(s.unsupported[0].find("morph target weight animation"), std::string::npos);
    EXPECT_TRUE(asset.animations()[0].channels.empty());
}

// Each malformed animation: the file and the message fragment its error must contain.
TEST(GltfAnimation, MalformedAnimationsAreRefusedWithTheirPlace) {
    const std::string dir = testDir();
    const float nan = std::numeric_limits<float>::quiet_NaN();
    struct Case {
        const char* name;
        std::function<void(TestGltf&)> make;
        const char* message;
    };
    const std::vector<Case> cases = {
        {"repeated_time",
         [](TestGltf& g) {
             g.addAnimation("Move", {{0,
                                      "translation",
                                      "LINEAR",
                                      {0.0f, 1.0f, 1.0f},
                                      g.addVec3({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}})}});
         },
         "animation 'Move' channel 0: sampler 0: key times are not strictly increasing: key 2 at 1 s follows "
         "1 s"},
        {"nan_key",
         [nan](TestGltf& g) {
             g.addAnimation(
                 "", {{0, "translation", "LINEAR", {0.0f, 1.0f}, g.addVec3({{0, 0, 0}, {nan, 0, 0}})}});
         },
         "animation 0 channel 0: sampler 0: output value 1 has the component nan"},
        {"nan_time",
         [nan](TestGltf& g) {
             g.addAnimation("",
                            {{0, "translation", "LINEAR", {0.0f, nan}, g.addVec3({{0, 0, 0}, {1, 0, 0}})}});
         },
         "key time 1 is nan"},
        {"count_mismatch",
         [](TestGltf& g) {
             g.addAnimation("",
                            {{0, "scale", "LINEAR", {0.0f, 1.0f, 2.0f}, g.addVec3({{1, 1, 1}, {2, 2, 2}})}});
         },
         "the sampler has 3 key times but 2 output values"},
        {"cubic_count",
         [](TestGltf& g) {
             g.addAnimation("",
                            {{0, "scale", "CUBICSPLINE", {0.0f, 1.0f}, g.addVec3({{1, 1, 1}, {2, 2, 2}})}});
         },
         "CUBICSPLINE needs 3 per key"},
        {"bad_interpolation",
         [](TestGltf& g) {
             g.addAnimation("", {{0, "scale", "BEZIER", {0.0f, 1.0f}, g.addVec3({{1, 1, 1}, {2, 2, 2}})}});
         },
         "interpolation 'BEZIER' is not LINEAR, STEP or CUBICSPLINE"},
        {"rotation_vec3",
         [](TestGltf& g) {
             g.addAnimation("", {{0, "rotation", "LINEAR", {0.0f, 1.0f}, g.addVec3({{0, 0, 0}, {1, 0, 0}})}});
         },
         "(output) has type VEC3, expected VEC4"},
        {"zero_quaternion",
         [](TestGltf& g) {
             g.addAnimation(
                 "", {{0, "rotation", "LINEAR", {0.0f, 1.0f}, g.addVec4({{0, 0, 0, 1}, {0, 0, 0, 0}})}});
         },
         "rotation key 1 is a zero quaternion"},
        {"duplicate_target",
         [](TestGltf& g) {
             const int out = g.addVec3({{0, 0, 0}, {1, 0, 0}});
             g.addAnimation("", {{0, "translation", "LINEAR", {0.0f, 1.0f}, out},
                                 {0, "translation", "STEP", {0.0f, 1.0f}, out}});
         },
         "channel 1: targets node 0 translation, which an earlier channel of the animation targets already"},
        {"matrix_node",
         [](TestGltf& g) {
             g.doc["nodes"][0]["matrix"] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
             g.addAnimation("",
                            {{0, "translation", "LINEAR", {0.0f, 1.0f}, g.addVec3({{0, 0, 0}, {1, 0, 0}})}});
         },
         "node 'TriNode' is animated but has a matrix"},
        {"negative_time",
         [](TestGltf& g) {
             g.addAnimation("",
                            {{0, "translation", "LINEAR", {-1.0f, 1.0f}, g.addVec3({{0, 0, 0}, {1, 0, 0}})}});
         },
         "key time 0 is -1, before 0"},
    };
    for (const Case& c : cases) {
        TestGltf g = oneTriangle();
        c.make(g);
        const std::string path = g.writeGltf(dir, c.name);
        const std::string error = assetError(path);
        EXPECT_NE(error.find(c.message), std::string::npos) << c.name << ": " << error;
        EXPECT_EQ(error.rfind(path, 0), 0u) << c.name << ": the message names the file: " << error;
        // A plain load refuses it too: the file is broken whether or not it is animated.
        EXPECT_NE(loadError(path).find(c.message), std::string::npos) << c.name;
    }
}

}  // namespace
}  // namespace gdpt::test
