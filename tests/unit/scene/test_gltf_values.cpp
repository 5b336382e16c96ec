// test_gltf_values.cpp — material and light factors the renderer cannot use are refused with a
// message naming the element, the factor and its glTF range, instead of rendering negative or
// NaN pixels without a word.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "gltf_test_writer.h"
#include "scene/gltf_loader.h"
#include "util/error.h"

namespace gdpt {
namespace {

using test::TestGltf;

// oneTriangle with material `m` on its primitive.
TestGltf withMaterial(const nlohmann::json& m) {
    auto g = test::oneTriangle();
    g.addMaterial(m);
    g.doc["meshes"][0]["primitives"][0]["material"] = 0;
    return g;
}

// Class: negative or NaN material factors (a negative emissiveFactor gave negative pixels).
// Every factor outside its range in the glTF 2.0 schema or its extension's is refused naming
// the material, the factor and the range. (JSON has no NaN or infinity, and tinygltf's parser
// refuses 1e999; the checks refuse them too.)
TEST(GltfValues, FactorsOutsideTheirRangeAreRefusedNamingTheMaterial) {
    const std::string dir = test::testDir();
    struct Case {
        nlohmann::json material;
        std::string expected;
    };
    const nlohmann::json pbr = {{"baseColorFactor", {1, 1, 1, 1}}};
    const std::vector<Case> cases = {
        {{{"emissiveFactor", {-1, 0, 0}}}, "emissiveFactor component 0 is -1, outside [0, 1]"},
        {{{"emissiveFactor", {0, 2, 0}}}, "emissiveFactor component 1 is 2, outside [0, 1]"},
        {{{"pbrMetallicRoughness", {{"baseColorFactor", {0.5, -0.25, 0, 1}}}}},
         "baseColorFactor component 1 is -0.25, outside [0, 1]"},
        {{{"pbrMetallicRoughness", {{"baseColorFactor", {0.5, 0.5, 0.5, 1.5}}}}},
         "baseColorFactor component 3 is 1.5, outside [0, 1]"},
        {{{"pbrMetallicRoughness", {{"metallicFactor", -0.1}}}}, "metallicFactor is -0.1, outside [0, 1]"},
        {{{"pbrMetallicRoughness", {{"roughnessFactor", 2}}}}, "roughnessFactor is 2, outside [0, 1]"},
        {{{"emissiveFactor", {1, 1, 1}},
          {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", -3}}}}}},
         "emissiveStrength -3 is not a finite value >= 0"},
        {{{"emissiveFactor", {1, 1, 1}},
          {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 1e39}}}}}},
         "emissiveFactor x emissiveStrength 1e+39 overflows single precision"},
        {{{"extensions", {{"KHR_materials_specular", {{"specularFactor", 1.5}}}}}},
         "specularFactor is 1.5, outside [0, 1]"},
        {{{"extensions", {{"KHR_materials_specular", {{"specularColorFactor", {1, -1, 1}}}}}}},
         "specularColorFactor component 1 is -1, outside [0, inf)"},
        {{{"extensions", {{"KHR_materials_ior", {{"ior", 0.5}}}}}},
         "ior 0.5 is neither 0 nor a finite value >= 1"},
        {{{"alphaMode", "MASK"}, {"alphaCutoff", -1}}, "alphaCutoff is -1, outside [0, inf)"},
    };
    for (const Case& c : cases) {
        nlohmann::json m = c.material;
        m["name"] = "Bad";
        auto g = withMaterial(m);
        const std::string path = g.writeGltf(dir, "mat");
        const std::string msg = test::loadError(path);
        EXPECT_NE(msg.find(path + ": material 'Bad': " + c.expected), std::string::npos)
            << c.material.dump() << " -> '" << msg << "'";
    }
}

// Guards the ranges' ends: factors at their bounds, emission above 1 through
// KHR_materials_emissive_strength, specularColorFactor above 1 and ior 0 all load.
TEST(GltfValues, FactorsAtTheirBoundsLoad) {
    auto g = withMaterial(
        {{"pbrMetallicRoughness",
          {{"baseColorFactor", {0, 1, 0, 1}}, {"metallicFactor", 1}, {"roughnessFactor", 0}}},
         {"emissiveFactor", {1, 0, 0}},
         {"extensions",
          {{"KHR_materials_emissive_strength", {{"emissiveStrength", 100}}},
           {"KHR_materials_specular", {{"specularFactor", 0}, {"specularColorFactor", {2, 2, 2}}}},
           {"KHR_materials_ior", {{"ior", 0}}}}}});
    const Scene s = loadGltf(g.writeGltf(test::testDir(), "bounds"));
    ASSERT_EQ(s.materials.size(), 1u);
    EXPECT_EQ(s.materials[0].emissive, glm::vec3(100, 0, 0));
    EXPECT_EQ(s.materials[0].specularColor, glm::vec3(2));
}

// The same class for KHR_lights_punctual: a negative color or intensity would emit negative
// radiance.
TEST(GltfValues, NegativeLightColorOrIntensityIsRefusedNamingTheLight) {
    const std::string dir = test::testDir();
    const std::vector<std::pair<nlohmann::json, std::string>> cases = {
        {{{"type", "point"}, {"name", "Bulb"}, {"color", {1, -0.5, 1}}},
         "light 'Bulb': color component 1 is -0.5, outside [0, 1]"},
        {{{"type", "point"}, {"name", "Bulb"}, {"intensity", -5}},
         "light 'Bulb': intensity -5 is not a finite value >= 0"},
    };
    for (const auto& [light, expected] : cases) {
        auto g = test::oneTriangle();
        g.doc["extensions"]["KHR_lights_punctual"]["lights"] = {light};
        g.doc["extensionsUsed"] = {"KHR_lights_punctual"};
        g.doc["scenes"][0]["nodes"].push_back(
            g.addNode({{"name", "Lamp"}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}}));
        const std::string msg = test::loadError(g.writeGltf(dir, "light"));
        EXPECT_NE(msg.find("node 'Lamp': " + expected), std::string::npos) << msg;
    }
}

}  // namespace
}  // namespace gdpt
