// gltf_test_writer.h — builds small glTF documents in tests and writes them as .gltf (+ .bin
// side file) or .glb, so loader tests need no checked-in fixtures and each test states its
// input next to its assertions.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <glm/glm.hpp>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "scene/gltf_loader.h"
#include "temp_dir.h"
#include "util/error.h"

namespace gdpt::test {

// The error message of loading `path`, or "" if it loads.
inline std::string loadError(const std::string& path) {
    try {
        (void)loadGltf(path);
        return "";
    } catch (const Error& e) {
        return e.what();
    }
}

constexpr int kFloat = 5126, kUInt = 5125, kUShort = 5123, kUByte = 5121;

// <gtest temp dir>/gdpt_scene_<suite>_<test>, one path component (temp_dir.h's testDirName).
inline std::filesystem::path testDirPath(const ::testing::TestInfo& info) {
    return std::filesystem::path(::testing::TempDir()) / ("gdpt_scene_" + testDirName(info));
}

// Removes each test's directory when the test ends (registered once per test program).
class TestDirCleaner : public ::testing::EmptyTestEventListener {
    void OnTestEnd(const ::testing::TestInfo& info) override {
        std::error_code ignored;
        std::filesystem::remove_all(testDirPath(info), ignored);
    }
};
inline const bool kTestDirCleanerRegistered = [] {
    ::testing::UnitTest::GetInstance()->listeners().Append(new TestDirCleaner);
    return true;
}();

// A fresh directory per test, removed when the test ends.
inline std::string testDir() {
    (void)kTestDirCleanerRegistered;  // an odr-use: registered before the first directory
    const std::filesystem::path dir = testDirPath(*::testing::UnitTest::GetInstance()->current_test_info());
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir.string();
}

class TestGltf {
public:
    nlohmann::json doc;
    std::vector<unsigned char> bin;
    // JSON text written as the document's top-level "extras" as it is (e.g. nesting deeper
    // than nlohmann::json can dump without recursion); empty = none.
    std::string rawExtras;

    TestGltf() {
        doc["asset"] = {{"version", "2.0"}};
        for (const char* k : {"accessors", "bufferViews", "meshes", "nodes", "materials"})
            doc[k] = nlohmann::json::array();
    }

    int addView(const void* data, std::size_t bytes, int stride = 0) {
        while (bin.size() % 4) bin.push_back(0);
        nlohmann::json v = {{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", bytes}};
        if (stride) v["byteStride"] = stride;
        const auto* p = static_cast<const unsigned char*>(data);
        bin.insert(bin.end(), p, p + bytes);
        doc["bufferViews"].push_back(v);
        return static_cast<int>(doc["bufferViews"].size() - 1);
    }
    int addAccessor(int view, int componentType, std::size_t count, const std::string& type,
                    std::size_t byteOffset = 0) {
        nlohmann::json a = {
            {"bufferView", view}, {"componentType", componentType}, {"count", count}, {"type", type}};
        if (byteOffset) a["byteOffset"] = byteOffset;
        doc["accessors"].push_back(a);
        return static_cast<int>(doc["accessors"].size() - 1);
    }
    int addVec3(const std::vector<glm::vec3>& v) {
        return addAccessor(addView(v.data(), v.size() * 12), kFloat, v.size(), "VEC3");
    }
    int addScalars(const std::vector<float>& v) {
        return addAccessor(addView(v.data(), v.size() * 4), kFloat, v.size(), "SCALAR");
    }
    int addVec4(const std::vector<glm::vec4>& v) {
        return addAccessor(addView(v.data(), v.size() * 16), kFloat, v.size(), "VEC4");
    }
    // An animation with one sampler per channel: (node, path, interpolation, key times,
    // output accessor); returns its index.
    struct ChannelSpec {
        int node;
        std::string path;
        std::string interpolation;
        std::vector<float> times;
        int output;
    };
    int addAnimation(const std::string& name, const std::vector<ChannelSpec>& channels) {
        nlohmann::json a = {{"channels", nlohmann::json::array()}, {"samplers", nlohmann::json::array()}};
        if (!name.empty()) a["name"] = name;
        for (const ChannelSpec& c : channels) {
            a["samplers"].push_back(
                {{"input", addScalars(c.times)}, {"output", c.output}, {"interpolation", c.interpolation}});
            a["channels"].push_back(
                {{"sampler", a["samplers"].size() - 1}, {"target", {{"node", c.node}, {"path", c.path}}}});
        }
        doc["animations"].push_back(a);
        return static_cast<int>(doc["animations"].size() - 1);
    }
    int addVec2(const std::vector<glm::vec2>& v) {
        return addAccessor(addView(v.data(), v.size() * 8), kFloat, v.size(), "VEC2");
    }
    int addIndices(const std::vector<std::uint32_t>& idx, int componentType = kUInt) {
        std::vector<unsigned char> raw;
        for (std::uint32_t i : idx) {
            const int size = componentType == kUInt ? 4 : componentType == kUShort ? 2 : 1;
            for (int b = 0; b < size; ++b) raw.push_back(static_cast<unsigned char>(i >> (8 * b)));
        }
        return addAccessor(addView(raw.data(), raw.size()), componentType, idx.size(), "SCALAR");
    }
    // A primitive JSON object; indices < 0 = non-indexed.
    nlohmann::json primitive(const std::vector<glm::vec3>& pos, const std::vector<std::uint32_t>& idx,
                             int mode = 4, const std::vector<glm::vec3>& nrm = {}, int material = -1) {
        nlohmann::json p = {{"attributes", {{"POSITION", addVec3(pos)}}}, {"mode", mode}};
        if (!nrm.empty()) p["attributes"]["NORMAL"] = addVec3(nrm);
        if (!idx.empty()) p["indices"] = addIndices(idx);
        if (material >= 0) p["material"] = material;
        return p;
    }
    int addMesh(const std::vector<nlohmann::json>& prims, const std::string& name = "") {
        nlohmann::json m = {{"primitives", prims}};
        if (!name.empty()) m["name"] = name;
        doc["meshes"].push_back(m);
        return static_cast<int>(doc["meshes"].size() - 1);
    }
    int addNode(const nlohmann::json& node) {
        doc["nodes"].push_back(node);
        return static_cast<int>(doc["nodes"].size() - 1);
    }
    void setScene(const std::vector<int>& roots) {
        doc["scenes"] = nlohmann::json::array({{{"nodes", roots}}});
        doc["scene"] = 0;
    }
    int addMaterial(const nlohmann::json& m) {
        doc["materials"].push_back(m);
        return static_cast<int>(doc["materials"].size() - 1);
    }

    // Writes dir/name.gltf and dir/name.bin; returns the .gltf path.
    std::string writeGltf(const std::string& dir, const std::string& name) {
        nlohmann::json d = doc;
        if (!bin.empty()) {
            d["buffers"] = nlohmann::json::array({{{"uri", name + ".bin"}, {"byteLength", bin.size()}}});
            writeBytes(dir + "/" + name + ".bin", bin);
        }
        const std::string text = withRawExtras(d.dump(1));
        writeBytes(dir + "/" + name + ".gltf", std::vector<unsigned char>(text.begin(), text.end()));
        return dir + "/" + name + ".gltf";
    }
    // Writes dir/name.glb (JSON chunk + BIN chunk, glTF 2.0 §4.4); returns its path.
    std::string writeGlb(const std::string& dir, const std::string& name) {
        nlohmann::json d = doc;
        std::vector<unsigned char> body = bin;
        while (body.size() % 4) body.push_back(0);
        if (!body.empty()) d["buffers"] = nlohmann::json::array({{{"byteLength", bin.size()}}});
        std::string json = withRawExtras(d.dump());
        while (json.size() % 4) json.push_back(' ');
        std::vector<unsigned char> out;
        auto u32 = [&](std::uint32_t v) {
            for (int b = 0; b < 4; ++b) out.push_back(static_cast<unsigned char>(v >> (8 * b)));
        };
        const std::size_t total = 12 + 8 + json.size() + (body.empty() ? 0 : 8 + body.size());
        out.insert(out.end(), {'g', 'l', 'T', 'F'});
        u32(2);
        u32(static_cast<std::uint32_t>(total));
        u32(static_cast<std::uint32_t>(json.size()));
        u32(0x4E4F534Au);  // "JSON"
        out.insert(out.end(), json.begin(), json.end());
        if (!body.empty()) {
            u32(static_cast<std::uint32_t>(body.size()));
            u32(0x004E4942u);  // "BIN\0"
            out.insert(out.end(), body.begin(), body.end());
        }
        writeBytes(dir + "/" + name + ".glb", out);
        return dir + "/" + name + ".glb";
    }

    std::string withRawExtras(std::string text) const {
        if (rawExtras.empty()) return text;
        const std::size_t close = text.rfind('}');
        return text.substr(0, close) + ",\"extras\":" + rawExtras + text.substr(close);
    }

    static void writeBytes(const std::string& path, const std::vector<unsigned char>& data) {
        std::ofstream f(path, std::ios::binary);
        f.write(reinterpret_cast<const char*>(data.data()), static_cast<std::streamsize>(data.size()));
    }
};

// One counter-clockwise triangle in the z = 0 plane facing +Z, with +Z normals.
inline std::vector<glm::vec3> unitTriangle() {
    return {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
}
inline std::vector<glm::vec3> plusZNormals() {
    return {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
}

// A minimal valid file: one node with one triangle mesh named "Tri".
inline TestGltf oneTriangle() {
    TestGltf g;
    const int mesh = g.addMesh({g.primitive(unitTriangle(), {0, 1, 2}, 4, plusZNormals())}, "Tri");
    g.setScene({g.addNode({{"name", "TriNode"}, {"mesh", mesh}})});
    return g;
}

}  // namespace gdpt::test
