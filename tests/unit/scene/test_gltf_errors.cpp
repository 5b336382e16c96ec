// test_gltf_errors.cpp — every malformed input gives gdpt::Error naming the file and the
// element; no input crashes the loader. Each case starts from a valid file
// (oneTriangle) and breaks exactly one thing, so a loader that ignored the defect would load
// successfully and fail the test.
#include <gtest/gtest.h>
#include <stb/stb_image_write.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>

#include "gltf_test_writer.h"
#include "scene/gltf_loader.h"
#include "util/error.h"

namespace gdpt {
namespace {

using test::TestGltf;

// Loads `path`, requires a gdpt::Error, and checks the message holds every substring.
void expectError(const std::string& path, const std::vector<std::string>& substrings) {
    try {
        (void)loadGltf(path);
        FAIL() << "no error for " << path;
    } catch (const Error& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find(path), std::string::npos) << msg;
        for (const auto& s : substrings)
            EXPECT_NE(msg.find(s), std::string::npos) << "'" << s << "' not in: " << msg;
    }
}

TEST(GltfErrors, ValidBaseFileLoads) {
    // The base of every case below must load, otherwise the cases prove nothing.
    auto g = test::oneTriangle();
    EXPECT_EQ(loadGltf(g.writeGltf(test::testDir(), "ok")).triangles.size(), 1u);
}

TEST(GltfErrors, MissingFile) {
    expectError(test::testDir() + "/does_not_exist.gltf", {"cannot open"});
}

TEST(GltfErrors, DirectoryInsteadOfFile) {
    expectError(test::testDir(), {"not a regular file"});
}

TEST(GltfErrors, BadJson) {
    const std::string path = test::testDir() + "/bad.gltf";
    TestGltf::writeBytes(path, {'{', '"', 'a', 's', 's', 'e', 't', '"', ':', ' ', '{'});
    expectError(path, {"parse error"});
}

TEST(GltfErrors, EmptyFile) {
    const std::string path = test::testDir() + "/empty.gltf";
    TestGltf::writeBytes(path, {});
    expectError(path, {"not a glTF 2.0 file", "the file is empty"});
    TestGltf::writeBytes(path, {' ', '\n', '\t'});
    expectError(path, {"not a glTF 2.0 file", "the file is empty"});
}

// A file that is not a glTF document is refused by what it is (an image passed where a
// scene belongs), not by what a JSON check makes of its bytes; a JSON document that is not an
// object names its first character. A byte order mark and white space before the object are
// accepted (the base file with them loads).
TEST(GltfErrors, AnImageOrOtherJsonInsteadOfAScene) {
    const std::string dir = test::testDir();
    const std::vector<std::pair<std::vector<unsigned char>, std::string>> cases = {
        {{0x76, 0x2F, 0x31, 0x01, 2, 0, 0, 0, '[', '[', '['}, "this is an OpenEXR image"},
        {{0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'}, "this is a PNG image"},
        {{0xFF, 0xD8, 0xFF, 0xE0}, "this is a JPEG image"},
        {{' ', '[', '1', ']'}, "it starts with byte 0x5B at offset 1"},
    };
    for (const auto& [bytes, what] : cases) {
        const std::string path = dir + "/not_a_scene.gltf";
        TestGltf::writeBytes(path, bytes);
        expectError(path, {"not a glTF 2.0 file", what});
    }
    const std::string ok = test::oneTriangle().writeGltf(dir, "bom");
    std::ifstream in(ok, std::ios::binary);
    std::vector<unsigned char> bytes = {0xEF, 0xBB, 0xBF, ' ', '\n'};
    bytes.insert(bytes.end(), std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    in.close();
    TestGltf::writeBytes(ok, bytes);
    EXPECT_EQ(loadGltf(ok).triangles.size(), 1u);
}

TEST(GltfErrors, MissingBufferFile) {
    const std::string dir = test::testDir();
    auto g = test::oneTriangle();
    const std::string path = g.writeGltf(dir, "nobin");
    std::filesystem::remove(dir + "/nobin.bin");
    expectError(path, {"nobin.bin"});
}

TEST(GltfErrors, ShortBuffer) {
    const std::string dir = test::testDir();
    auto g = test::oneTriangle();
    const std::string path = g.writeGltf(dir, "short");
    std::filesystem::resize_file(dir + "/short.bin", 8);  // JSON still claims the full length
    expectError(path, {"parse error"});
}

TEST(GltfErrors, BufferViewOutsideBuffer) {
    auto g = test::oneTriangle();
    g.doc["bufferViews"][0]["byteLength"] = 4096;
    expectError(g.writeGltf(test::testDir(), "bv"),
                {"mesh 'Tri' primitive 0", "accessor 0 (POSITION)", "bufferView 0", "buffer 0"});
}

TEST(GltfErrors, AccessorBeyondBufferView) {
    auto g = test::oneTriangle();
    g.doc["accessors"][0]["count"] = 4;  // 4 x 12 bytes in a 36-byte view
    expectError(g.writeGltf(test::testDir(), "acc"),
                {"mesh 'Tri' primitive 0", "accessor 0 (POSITION)", "needs bytes [0, 48)"});
}

TEST(GltfErrors, AccessorIndexOutOfRange) {
    auto g = test::oneTriangle();
    g.doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 42;
    expectError(g.writeGltf(test::testDir(), "idx"),
                {"mesh 'Tri' primitive 0", "accessor 42 (POSITION) out of range"});
}

TEST(GltfErrors, WrongAccessorType) {
    auto g = test::oneTriangle();
    g.doc["accessors"][0]["type"] = "VEC2";
    expectError(g.writeGltf(test::testDir(), "type"),
                {"mesh 'Tri' primitive 0: accessor 0 (POSITION) has type VEC2, expected VEC3"});
}

TEST(GltfErrors, WrongComponentType) {
    auto g = test::oneTriangle();
    g.doc["accessors"][0]["componentType"] = test::kUShort;
    expectError(g.writeGltf(test::testDir(), "ctype"),
                {"accessor 0 (POSITION) has componentType 5123 (UNSIGNED_SHORT), expected FLOAT"});
}

TEST(GltfErrors, FloatIndices) {
    auto g = test::oneTriangle();
    const int idxAccessor = g.doc["meshes"][0]["primitives"][0]["indices"];
    g.doc["accessors"][static_cast<std::size_t>(idxAccessor)]["componentType"] = test::kFloat;
    expectError(g.writeGltf(test::testDir(), "fidx"),
                {"accessor " + std::to_string(idxAccessor) + " (indices) has componentType 5126"});
}

TEST(GltfErrors, IndexOutOfVertexRange) {
    TestGltf g;
    const int mesh = g.addMesh({g.primitive(test::unitTriangle(), {0, 1, 7})}, "Tri");
    g.setScene({g.addNode({{"mesh", mesh}})});
    expectError(g.writeGltf(test::testDir(), "oob"),
                {"mesh 'Tri' primitive 0", "(indices) element 2 is 7, out of range of the 3 vertices"});
}

TEST(GltfErrors, TriangleIndexCountNotMultipleOfThree) {
    TestGltf g;
    const int mesh = g.addMesh({g.primitive(test::unitTriangle(), {0, 1, 2, 0})}, "Tri");
    g.setScene({g.addNode({{"mesh", mesh}})});
    expectError(g.writeGltf(test::testDir(), "m3"), {"mesh 'Tri' primitive 0", "not a multiple of 3"});
}

TEST(GltfErrors, NanPosition) {
    TestGltf g;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const int mesh = g.addMesh({g.primitive({{0, 0, 0}, {1, nan, 0}, {0, 1, 0}}, {0, 1, 2})}, "Tri");
    g.setScene({g.addNode({{"mesh", mesh}})});
    expectError(g.writeGltf(test::testDir(), "nan"),
                {"mesh 'Tri' primitive 0", "accessor 0 (POSITION) element 1 is not finite"});
}

TEST(GltfErrors, InfinitePosition) {
    TestGltf g;
    const float inf = std::numeric_limits<float>::infinity();
    const int mesh = g.addMesh({g.primitive({{0, 0, 0}, {1, 0, 0}, {0, 1, -inf}}, {})}, "Tri");
    g.setScene({g.addNode({{"mesh", mesh}})});
    expectError(g.writeGltf(test::testDir(), "inf"), {"element 2 is not finite"});
}

TEST(GltfErrors, PositionBeyondTheSupportedRangeAfterTransform) {
    auto g = test::oneTriangle();
    g.doc["nodes"][0]["scale"] = {1e38, 1e38, 1e38};
    expectError(g.writeGltf(test::testDir(), "ovf"),
                {"mesh 'Tri' primitive 0", "vertex 1 is at (1e+38, 0, 0) after the node transform, outside"});
}

TEST(GltfErrors, AbsurdCount) {
    auto g = test::oneTriangle();
    g.doc["accessors"][0]["count"] = 1000000000000ull;
    expectError(g.writeGltf(test::testDir(), "absurd"),
                {"accessor 0 (POSITION) has count 1000000000000, more than the limit"});
}

TEST(GltfErrors, CyclicNodeGraph) {
    auto g = test::oneTriangle();
    const int a = g.addNode({{"name", "A"}});
    const int b = g.addNode({{"name", "B"}, {"children", {a}}});
    g.doc["nodes"][static_cast<std::size_t>(a)]["children"] = {b};
    expectError(g.writeGltf(test::testDir(), "cycle"), {"cyclic node graph"});
}

TEST(GltfErrors, NodeIsItsOwnChild) {
    auto g = test::oneTriangle();
    g.doc["nodes"][0]["children"] = {0};
    expectError(g.writeGltf(test::testDir(), "self"), {"node 'TriNode' is its own child"});
}

TEST(GltfErrors, NodeUsedTwiceAsChild) {
    auto g = test::oneTriangle();
    const int a = g.addNode({{"children", {0}}});
    const int b = g.addNode({{"children", {0}}});
    g.setScene({a, b});
    expectError(g.writeGltf(test::testDir(), "twice"),
                {"node 0 is used twice as a child (by node 1 and node 2)"});
}

TEST(GltfErrors, ChildIndexOutOfRange) {
    auto g = test::oneTriangle();
    g.doc["nodes"][0]["children"] = {9};
    expectError(g.writeGltf(test::testDir(), "child"), {"node 'TriNode': child 9 out of range"});
}

TEST(GltfErrors, CameraIndexOutOfRange) {
    auto g = test::oneTriangle();
    g.doc["cameras"] =
        nlohmann::json::array({{{"type", "perspective"}, {"perspective", {{"yfov", 0.5}, {"znear", 0.1}}}}});
    const int cam = g.addNode({{"name", "Cam"}, {"camera", 3}});
    g.setScene({0, cam});
    expectError(g.writeGltf(test::testDir(), "cam"),
                {"node 'Cam': camera 3 out of range (file has 1 cameras)"});
}

TEST(GltfErrors, MeshIndexOutOfRange) {
    auto g = test::oneTriangle();
    g.doc["nodes"][0]["mesh"] = 5;
    expectError(g.writeGltf(test::testDir(), "mesh"), {"node 'TriNode': mesh 5 out of range"});
}

TEST(GltfErrors, MaterialIndexOutOfRange) {
    auto g = test::oneTriangle();
    g.doc["meshes"][0]["primitives"][0]["material"] = 3;
    expectError(g.writeGltf(test::testDir(), "mat"), {"mesh 'Tri' primitive 0: material 3 out of range"});
}

TEST(GltfErrors, SceneIndexOutOfRange) {
    auto g = test::oneTriangle();
    g.doc["scene"] = 4;
    expectError(g.writeGltf(test::testDir(), "scene"), {"scene"});
}

TEST(GltfErrors, UndecodableImage) {
    auto g = test::oneTriangle();
    const std::string garbage = "this is not a PNG file at all";
    const int view = g.addView(garbage.data(), garbage.size());
    g.doc["images"] = nlohmann::json::array({{{"bufferView", view}, {"mimeType", "image/png"}}});
    g.doc["textures"] = nlohmann::json::array({{{"source", 0}}});
    g.addMaterial({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}});
    g.doc["meshes"][0]["primitives"][0]["material"] = 0;
    expectError(g.writeGltf(test::testDir(), "img"), {"image 0", "cannot decode"});
}

// Class: messages that say nothing ("cannot decode ()") or print raw bytes. A texture PNG cut
// short names the image and says it is truncated, in plain text.
TEST(GltfErrors, TruncatedTextureSaysItIsTruncated) {
    std::vector<unsigned char> png;
    std::vector<unsigned char> pixels(64 * 64 * 4);
    for (std::size_t i = 0; i < pixels.size(); ++i) pixels[i] = static_cast<unsigned char>(i * 7919u >> 3);
    stbi_write_png_to_func(
        [](void* ctx, void* data, int size) {
            auto* v = static_cast<std::vector<unsigned char>*>(ctx);
            v->insert(v->end(), static_cast<unsigned char*>(data), static_cast<unsigned char*>(data) + size);
        },
        &png, 64, 64, 4, pixels.data(), 64 * 4);
    png.resize(png.size() / 2);  // cut in the middle of the image data
    auto g = test::oneTriangle();
    const int view = g.addView(png.data(), png.size());
    g.doc["images"] = nlohmann::json::array({{{"bufferView", view}, {"mimeType", "image/png"}}});
    g.doc["textures"] = nlohmann::json::array({{{"source", 0}}});
    g.addMaterial({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}});
    g.doc["meshes"][0]["primitives"][0]["material"] = 0;
    try {
        (void)loadGltf(g.writeGltf(test::testDir(), "cut"));
        ADD_FAILURE() << "a truncated texture loaded";
    } catch (const Error& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("image 0"), std::string::npos) << m;
        EXPECT_NE(m.find("truncated"), std::string::npos) << m;
        EXPECT_EQ(m.find("()"), std::string::npos) << m;
        for (char ch : m) EXPECT_TRUE(ch >= 0x20 && ch < 0x7f) << "raw byte in: " << m;
    }
}

TEST(GltfErrors, ImageBufferViewOutsideBuffer) {
    // tinygltf does not check this itself; it would hand the decoder a wild pointer.
    auto g = test::oneTriangle();
    g.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", 1 << 20}, {"byteLength", 64}});
    g.doc["images"] =
        nlohmann::json::array({{{"bufferView", g.doc["bufferViews"].size() - 1}, {"mimeType", "image/png"}}});
    expectError(g.writeGltf(test::testDir(), "imgbv"), {"image 0", "lies outside its buffer"});
}

TEST(GltfErrors, MissingExternalImage) {
    auto g = test::oneTriangle();
    g.doc["images"] = nlohmann::json::array({{{"uri", "nowhere.png"}}});
    g.doc["textures"] = nlohmann::json::array({{{"source", 0}}});
    g.addMaterial({{"name", "Tex"}, {"emissiveTexture", {{"index", 0}}}});
    g.doc["meshes"][0]["primitives"][0]["material"] = 0;
    expectError(g.writeGltf(test::testDir(), "noimg"),
                {"material 'Tex'", "image 0 'nowhere.png' could not be loaded"});
}

TEST(GltfErrors, TextureIndexOutOfRange) {
    auto g = test::oneTriangle();
    g.addMaterial({{"name", "M"}, {"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 2}}}}}});
    expectError(g.writeGltf(test::testDir(), "tex"),
                {"material 'M': baseColorTexture: texture 2 out of range"});
}

TEST(GltfErrors, RequiredCompressionIsAnError) {
    auto g = test::oneTriangle();
    g.doc["extensionsUsed"] = {"KHR_draco_mesh_compression"};
    g.doc["extensionsRequired"] = {"KHR_draco_mesh_compression"};
    expectError(g.writeGltf(test::testDir(), "draco"), {"KHR_draco_mesh_compression"});
}

// As a Draco encoder writes it: the primitive's accessors have no bufferView (the data is in
// the extension's compressed buffer view). The file is refused naming the extension, before
// anything reads those accessors.
TEST(GltfErrors, RequiredDracoIsRefusedNamingItBeforeTheAccessors) {
    const std::string dir = test::testDir();
    auto g = test::oneTriangle();
    g.doc["extensionsUsed"] = {"KHR_draco_mesh_compression"};
    g.doc["extensionsRequired"] = {"KHR_draco_mesh_compression"};
    for (auto& accessor : g.doc["accessors"]) accessor.erase("bufferView");
    auto& primitive = g.doc["meshes"][0]["primitives"][0];
    primitive["extensions"]["KHR_draco_mesh_compression"] = {
        {"bufferView", 0}, {"attributes", {{"POSITION", 0}, {"NORMAL", 1}}}};
    const std::vector<std::string> expected = {
        "required extension KHR_draco_mesh_compression is not supported", "decompress"};
    expectError(g.writeGltf(dir, "draco"), expected);
    expectError(g.writeGlb(dir, "draco"), expected);
}

// glTF 2.0 §3.12: a file that requires an extension the loader does not support must not be
// loaded; every such extension is named, the supported ones are not.
TEST(GltfErrors, RequiredUnsupportedExtensionsAreRefused) {
    const std::string dir = test::testDir();
    auto g = test::oneTriangle();
    const std::vector<std::string> unsupported = {"KHR_texture_transform", "KHR_materials_transmission",
                                                  "EXT_made_up_by_a_test"};
    g.doc["extensionsUsed"] = unsupported;
    g.doc["extensionsUsed"].push_back("KHR_lights_punctual");
    g.doc["extensionsRequired"] = {"KHR_lights_punctual", "KHR_texture_transform",
                                   "KHR_materials_transmission", "EXT_made_up_by_a_test"};
    for (const std::string& path : {g.writeGltf(dir, "req"), g.writeGlb(dir, "req")}) {
        expectError(path, {"required extensions KHR_texture_transform, KHR_materials_transmission, "
                           "EXT_made_up_by_a_test are not supported"});
        try {
            (void)loadGltf(path);
        } catch (const Error& e) {
            EXPECT_EQ(std::string(e.what()).find("KHR_lights_punctual"), std::string::npos) << e.what();
        }
    }
    g.doc["extensionsRequired"] = {"KHR_texture_transform"};
    expectError(g.writeGltf(dir, "one"), {"required extension KHR_texture_transform is not supported"});
}

// The extensions gdpt renders may be required.
TEST(GltfErrors, RequiredSupportedExtensionsLoad) {
    auto g = test::oneTriangle();
    const std::vector<std::string> supported = {"KHR_materials_emissive_strength", "KHR_materials_specular",
                                                "KHR_materials_ior", "KHR_lights_punctual"};
    g.doc["extensionsUsed"] = supported;
    g.doc["extensionsRequired"] = supported;
    EXPECT_EQ(loadGltf(g.writeGltf(test::testDir(), "ok")).triangles.size(), 1u);
}

TEST(GltfErrors, TruncatedGlb) {
    const std::string dir = test::testDir();
    auto g = test::oneTriangle();
    const std::string path = g.writeGlb(dir, "trunc");
    std::filesystem::resize_file(path, std::filesystem::file_size(path) - 40);
    expectError(path, {"parse error"});
}

TEST(GltfErrors, BadRotation) {
    auto g = test::oneTriangle();
    g.doc["nodes"][0]["rotation"] = {0, 0, 0, 0};
    expectError(g.writeGltf(test::testDir(), "rot"), {"node 'TriNode': rotation is a zero quaternion"});
}

// Byte-level mutations of a valid GLB and .gltf (fixed seed): each must load or throw
// gdpt::Error, never crash or throw anything else.
TEST(GltfErrors, MutatedFilesNeverCrash) {
    const std::string dir = test::testDir();
    auto g = test::oneTriangle();
    g.doc["cameras"] =
        nlohmann::json::array({{{"type", "perspective"}, {"perspective", {{"yfov", 0.5}, {"znear", 0.1}}}}});
    g.addNode({{"camera", 0}, {"translation", {0, 0, 3}}});
    g.doc["scenes"][0]["nodes"].push_back(1);
    for (const std::string& src : {g.writeGlb(dir, "base"), g.writeGltf(dir, "base")}) {
        std::ifstream in(src, std::ios::binary);
        const std::vector<unsigned char> orig((std::istreambuf_iterator<char>(in)), {});
        std::uint32_t state = 12345u;
        auto rnd = [&] { return state = state * 1664525u + 1013904223u; };
        for (int iter = 0; iter < 150; ++iter) {
            std::vector<unsigned char> bytes = orig;
            const int edits = 1 + static_cast<int>(rnd() % 4);
            for (int e = 0; e < edits; ++e)
                bytes[rnd() % bytes.size()] = static_cast<unsigned char>(rnd() >> 24);
            const std::string path = dir + "/mut" + std::filesystem::path(src).extension().string();
            TestGltf::writeBytes(path, bytes);
            try {
                (void)loadGltf(path);
            } catch (const Error&) {
                // expected for most mutations
            }
        }
    }
}

// Structural mutations: random integer fields of a richer document (camera, light, sparse
// accessor, texture) are replaced by boundary values (-1, 0, 1, 2, 3, large). Each load
// must succeed or throw gdpt::Error. Run under GDPT_SANITIZE to catch silent memory errors.
TEST(GltfErrors, MutatedIndicesNeverCrash) {
    const std::string dir = test::testDir();
    auto g = test::oneTriangle();
    const std::vector<std::uint32_t> sparseIdx = {2};
    const std::vector<glm::vec3> sparseVal = {{0, 2, 0}};
    const int iv = g.addView(sparseIdx.data(), 4), vv = g.addView(sparseVal.data(), 12);
    g.doc["accessors"][0]["sparse"] = {{"count", 1},
                                       {"indices", {{"bufferView", iv}, {"componentType", test::kUInt}}},
                                       {"values", {{"bufferView", vv}}}};
    // A valid 1x1 PNG in a bufferView, so that the base document loads completely.
    std::vector<unsigned char> png;
    const unsigned char pixel[4] = {200, 100, 50, 255};
    stbi_write_png_to_func(
        [](void* ctx, void* data, int size) {
            auto* v = static_cast<std::vector<unsigned char>*>(ctx);
            v->insert(v->end(), static_cast<unsigned char*>(data), static_cast<unsigned char*>(data) + size);
        },
        &png, 1, 1, 4, pixel, 4);
    g.doc["cameras"] =
        nlohmann::json::array({{{"type", "perspective"}, {"perspective", {{"yfov", 0.5}, {"znear", 0.1}}}}});
    g.doc["extensions"]["KHR_lights_punctual"]["lights"] = {{{"type", "point"}}};
    g.addNode({{"camera", 0}, {"children", {}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
    g.doc["scenes"][0]["nodes"].push_back(1);
    g.doc["textures"] = nlohmann::json::array({{{"source", 0}}});
    g.doc["images"] = nlohmann::json::array(
        {{{"bufferView", g.addView(png.data(), png.size())}, {"mimeType", "image/png"}}});
    g.addMaterial({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}});
    g.doc["meshes"][0]["primitives"][0]["material"] = 0;
    const Scene base = loadGltf(g.writeGltf(dir, "base"));
    ASSERT_EQ(base.textures.size(), 1u);
    ASSERT_EQ(base.punctualLights.size(), 1u);
    ASSERT_EQ(base.positions[2], glm::vec3(0, 2, 0));  // sparse substitution applied

    // Collect JSON pointers of all integer fields.
    std::vector<nlohmann::json::json_pointer> fields;
    const nlohmann::json flat = g.doc.flatten();
    for (auto it = flat.begin(); it != flat.end(); ++it)
        if (it.value().is_number_integer()) fields.emplace_back(it.key());
    ASSERT_GT(fields.size(), 20u);
    const std::int64_t values[] = {-1, 0, 1, 2, 3, 5, 4096, 4294967295ll, 1ll << 40};
    std::uint32_t state = 99u;
    auto rnd = [&] { return state = state * 1664525u + 1013904223u; };
    int loaded = 0;
    for (int iter = 0; iter < 300; ++iter) {
        TestGltf m = g;
        const int edits = 1 + static_cast<int>(rnd() % 3);
        for (int e = 0; e < edits; ++e)
            m.doc[fields[rnd() % fields.size()]] = values[rnd() % std::size(values)];
        try {
            (void)loadGltf(m.writeGltf(dir, "mut"));
            ++loaded;
        } catch (const Error&) {
        }
    }
    // Both outcomes occur: the mutations reach the checks, and not every mutation is fatal.
    EXPECT_GT(loaded, 0);
    EXPECT_LT(loaded, 300);
}

}  // namespace
}  // namespace gdpt
