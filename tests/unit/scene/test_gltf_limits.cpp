// test_gltf_limits.cpp — hostile files that cost stack, memory or time are refused before
// they cost it, with a message naming the file, the element and the limit: JSON nesting depth,
// bufferView strides, accessor counts and byte ranges, zero-filled accessors and instanced
// scenes beyond memory. The expensive cases run in a forked child whose address space may
// grow by only kHeadroom (bounded_child.h): a loader that allocates before it checks fails
// there with "out of memory" (or crashes) instead of passing slowly.
#include <gtest/gtest.h>
#include <stb/stb_image_write.h>

#include <string>

#include "bounded_child.h"
#include "gltf_test_writer.h"
#include "scene/gltf_loader.h"
#include "util/error.h"

namespace gdpt {
namespace {

using test::TestGltf;

// A few times what loading a small file needs; far below what the hostile files cost when
// materialised (hundreds of MiB to terabytes).
constexpr std::uint64_t kHeadroom = 256ull << 20;
constexpr double kTimeout = 30.0;

// "loaded" or the error message of loading `path`.
std::string loadOutcome(const std::string& path) {
    const std::string error = test::loadError(path);
    return error.empty() ? "loaded" : error;
}

// Loads `path` in a bounded child and requires a refusal naming the file and every substring,
// within a few seconds.
void expectCheapRefusal(const std::string& path, const std::vector<std::string>& substrings) {
    const test::ChildResult r = test::runBounded([&] { return loadOutcome(path); }, kHeadroom, kTimeout);
    ASSERT_TRUE(r.exited) << "the loader crashed (signal " << r.signal << ") or ran past " << kTimeout
                          << " s; output: " << r.output;
    EXPECT_LT(r.seconds, 10.0);
    EXPECT_NE(r.output.find(path), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("out of memory"), std::string::npos) << r.output;
    for (const auto& s : substrings)
        EXPECT_NE(r.output.find(s), std::string::npos) << "'" << s << "' not in: " << r.output;
}

// Class: JSON nesting depth. 20,000 nested arrays in `extras` (51 KB) overflowed the stack in
// tinygltf's recursive JSON conversion; they are refused by a linear scan before any parser,
// in a .gltf and in a .glb's JSON chunk.
TEST(GltfLimits, DeepJsonNestingIsRefusedBeforeParsing) {
    const std::string dir = test::testDir();
    auto g = test::oneTriangle();
    g.rawExtras = std::string(20000, '[') + std::string(20000, ']');
    for (const std::string& path : {g.writeGltf(dir, "deep"), g.writeGlb(dir, "deep")})
        expectCheapRefusal(path, {"deeper than 128 levels"});
}

// Guards the depth limit's generosity: 120 levels load, and brackets inside strings (even
// after escaped quotes) are not nesting.
TEST(GltfLimits, NestingWithinTheLimitAndBracketsInStringsLoad) {
    const std::string dir = test::testDir();
    auto g = test::oneTriangle();
    g.rawExtras = std::string(120, '[') + std::string(120, ']');
    EXPECT_EQ(loadGltf(g.writeGltf(dir, "deep120")).triangles.size(), 1u);
    g.rawExtras = "{\"a\": \"\\\"" + std::string(1000, '[') + "\", \"b\": \"{{{\\\\\"}";
    for (const std::string& path : {g.writeGltf(dir, "strings"), g.writeGlb(dir, "strings")})
        EXPECT_EQ(loadGltf(path).triangles.size(), 1u) << path;
}

// Class: accessor counts checked after allocation. An index count of 2^28 in a 3.9 KB file
// made the loader allocate 2 GiB before it found that the 12-byte bufferView cannot hold it.
TEST(GltfLimits, HugeIndexCountIsRefusedBeforeAllocating) {
    auto g = test::oneTriangle();
    g.doc["accessors"][2]["count"] = 1u << 28;
    expectCheapRefusal(
        g.writeGltf(test::testDir(), "indices"),
        {"mesh 'Tri' primitive 0: accessor 2 (indices) needs bytes [0, 1073741824) of bufferView 2, "
         "which has only 12 bytes"});
}

// The same for POSITION (2^28 vertices: 6 GiB and 35 s before the error).
TEST(GltfLimits, HugePositionCountIsRefusedBeforeAllocating) {
    const std::string dir = test::testDir();
    auto g = test::oneTriangle();
    g.doc["accessors"][0]["count"] = 1u << 28;
    for (const std::string& path : {g.writeGltf(dir, "positions"), g.writeGlb(dir, "positions")})
        expectCheapRefusal(path, {"accessor 0 (POSITION) needs bytes [0, 3221225472) of bufferView 0"});
}

// Accessors nothing reads are checked as well (the file is invalid either way).
TEST(GltfLimits, UnusedAccessorBeyondItsBufferViewIsRefused) {
    auto g = test::oneTriangle();
    g.addAccessor(0, test::kFloat, 1u << 20, "VEC3");
    expectCheapRefusal(g.writeGltf(test::testDir(), "unused"),
                       {"accessor 3 needs bytes [0, 12582912) of bufferView 0, which has only 36 bytes"});
}

// An accessor without bufferView is zeros (glTF 2.0 §3.6.2.3); 2^24 of them in a 3 KB file
// cost 1.6 GB. The loader creates no more zeros than the file's buffers hold plus 1 MiB.
TEST(GltfLimits, ZeroFilledAccessorBeyondTheFileIsRefused) {
    auto g = test::oneTriangle();
    g.doc["accessors"][0].erase("bufferView");
    g.doc["accessors"][0]["count"] = 1u << 24;
    g.doc["accessors"][1].erase("bufferView");
    g.doc["accessors"][1]["count"] = 1u << 24;
    g.doc["meshes"][0]["primitives"][0].erase("indices");
    expectCheapRefusal(
        g.writeGltf(test::testDir(), "zeros"),
        {"mesh 'Tri' primitive 0: accessor 0 (POSITION) has no bufferView: its 16777216 elements "
         "would be zeros that the file does not hold"});
}

// Guards spec-valid use of zero-filled accessors: a small one with sparse values loads.
TEST(GltfLimits, SmallZeroFilledAccessorWithSparseValuesLoads) {
    auto g = test::oneTriangle();
    const std::vector<std::uint32_t> idx = {1, 2};
    const std::vector<glm::vec3> val = {{1, 0, 0}, {0, 1, 0}};
    const int iv = g.addView(idx.data(), 8), vv = g.addView(val.data(), 24);
    g.doc["accessors"][0].erase("bufferView");
    g.doc["accessors"][0]["sparse"] = {{"count", 2},
                                       {"indices", {{"bufferView", iv}, {"componentType", test::kUInt}}},
                                       {"values", {{"bufferView", vv}}}};
    const Scene s = loadGltf(g.writeGltf(test::testDir(), "sparse"));
    ASSERT_EQ(s.positions.size(), 3u);
    EXPECT_EQ(s.positions[0], glm::vec3(0, 0, 0));
    EXPECT_EQ(s.positions[2], glm::vec3(0, 1, 0));
}

// Classes: memory before checks, and scene size known only after loading. A 1 MiB strip
// (2^20 indices cycling over 3 vertices: 2^20 - 2 triangles) in 64 primitives of a mesh that
// 4096 nodes instance is 2.8e11 triangles, terabytes once loaded; the estimate from the JSON
// refuses it before anything is read.
TEST(GltfLimits, InstancedSceneBeyondMemoryIsRefusedBeforeLoading) {
    TestGltf g;
    const int pos = g.addVec3(test::unitTriangle());
    std::vector<unsigned char> strip(1u << 20);
    for (std::size_t i = 0; i < strip.size(); ++i) strip[i] = static_cast<unsigned char>(i % 3);
    const int idx =
        g.addAccessor(g.addView(strip.data(), strip.size()), test::kUByte, strip.size(), "SCALAR");
    std::vector<nlohmann::json> prims(64,
                                      {{"attributes", {{"POSITION", pos}}}, {"indices", idx}, {"mode", 5}});
    const int mesh = g.addMesh(prims, "Strips");
    std::vector<int> roots;
    for (int i = 0; i < 4096; ++i) roots.push_back(g.addNode({{"mesh", mesh}}));
    g.setScene(roots);
    expectCheapRefusal(g.writeGltf(test::testDir(), "instanced"),
                       {"loading the scene (274877382656 triangles", "after instancing) needs about",
                        "more than the memory budget"});
}

// Class: memory spent before the checks, for textures. A 70 KB PNG of 8192x4096 pixels decodes
// to 128 MiB of RGBA and 512 MiB of float texels; with a 64 MiB budget it is refused from its
// header, before anything is decoded (the child could not map the 640 MiB otherwise).
TEST(GltfLimits, TextureBeyondTheMemoryBudgetIsRefusedBeforeDecoding) {
    const int w = 8192, h = 4096;
    std::vector<unsigned char> gray(std::size_t(w) * h, 0);
    for (int x = 0; x < w; ++x) gray[std::size_t(x)] = static_cast<unsigned char>(x);  // one row of detail
    std::vector<unsigned char> png;
    stbi_write_png_to_func(
        [](void* ctx, void* data, int size) {
            auto* v = static_cast<std::vector<unsigned char>*>(ctx);
            v->insert(v->end(), static_cast<unsigned char*>(data), static_cast<unsigned char*>(data) + size);
        },
        &png, w, h, 1, gray.data(), w);
    gray = {};
    ASSERT_LT(png.size(), 1u << 20);
    auto g = test::oneTriangle();
    g.doc["images"] = nlohmann::json::array(
        {{{"bufferView", g.addView(png.data(), png.size())}, {"mimeType", "image/png"}}});
    g.doc["textures"] = nlohmann::json::array({{{"source", 0}}});
    g.addMaterial({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}});
    g.doc["meshes"][0]["primitives"][0]["material"] = 0;
    const std::string path = g.writeGltf(test::testDir(), "bigtexture");
    const auto load = [&](std::uint64_t budget) {
        LoadOptions opts;
        opts.memoryBudget = budget;
        try {
            (void)loadGltf(path, opts);
            return std::string("loaded");
        } catch (const Error& e) {
            return std::string(e.what());
        }
    };
    const test::ChildResult r = test::runBounded([&] { return load(64ull << 20); }, kHeadroom, kTimeout);
    ASSERT_TRUE(r.exited) << "signal " << r.signal << ": " << r.output;
    EXPECT_NE(r.output.find("image 0"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("8192x4096 pixels need 640 MiB decoded"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("memory budget"), std::string::npos) << r.output;
    // Power: with room for it, the same file loads.
    EXPECT_EQ(load(1ull << 30), "loaded");
}

// Class: byteStride silently ignored. glTF 2.0 §5.11.4 allows 4..252, a multiple of 4;
// tinygltf drops a negative or non-integer stride (the data is then read tightly packed) and
// refuses others without naming the bufferView.
TEST(GltfLimits, InvalidByteStrideIsRefusedNamingTheBufferView) {
    const std::string dir = test::testDir();
    const std::vector<nlohmann::json> strides = {-4, 0, 2, 14, 256, 4.5, 1e30, 1ull << 40};
    for (const auto& stride : strides) {
        auto g = test::oneTriangle();
        g.doc["bufferViews"][0]["byteStride"] = stride;
        const std::string path = g.writeGltf(dir, "stride");
        try {
            (void)loadGltf(path);
            ADD_FAILURE() << "byteStride " << stride.dump() << " loaded";
        } catch (const Error& e) {
            const std::string msg = e.what();
            EXPECT_NE(msg.find(path + ": bufferView 0: byteStride " + stride.dump() +
                               " is not a multiple of 4 in [4, 252]"),
                      std::string::npos)
                << msg;
        }
    }
}

// byteStride is for vertex attributes only ("Buffer views with other types of data MUST NOT
// define byteStride"): index data, sparse storage and images with a stride are refused.
TEST(GltfLimits, ByteStrideOutsideVertexAttributesIsRefused) {
    const std::string dir = test::testDir();
    auto g = test::oneTriangle();
    g.doc["bufferViews"][2]["byteStride"] = 4;
    try {
        (void)loadGltf(g.writeGltf(dir, "indexstride"));
        ADD_FAILURE() << "a strided index bufferView loaded";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("bufferView 2 holds the indices of mesh 'Tri' primitive 0 but "
                                             "defines byteStride 4, which only vertex attributes may"),
                  std::string::npos)
            << e.what();
    }

    auto s = test::oneTriangle();
    const std::vector<std::uint32_t> idx = {2};
    const std::vector<glm::vec3> val = {{0, 2, 0}};
    const int iv = s.addView(idx.data(), 4), vv = s.addView(val.data(), 12, 12);
    s.doc["accessors"][0]["sparse"] = {{"count", 1},
                                       {"indices", {{"bufferView", iv}, {"componentType", test::kUInt}}},
                                       {"values", {{"bufferView", vv}}}};
    try {
        (void)loadGltf(s.writeGltf(dir, "sparsestride"));
        ADD_FAILURE() << "a strided sparse bufferView loaded";
    } catch (const Error& e) {
        EXPECT_NE(
            std::string(e.what()).find("bufferView 4 holds the sparse values of mesh 'Tri' primitive 0: "
                                       "accessor 0 (POSITION) but defines byteStride 12"),
            std::string::npos)
            << e.what();
    }

    auto img = test::oneTriangle();
    const std::string png = "not decoded: refused before";
    img.doc["images"] = nlohmann::json::array(
        {{{"uri", "data:image/png;base64,AAAA"}}, {{"bufferView", img.addView(png.data(), png.size(), 8)}}});
    try {
        (void)loadGltf(img.writeGltf(dir, "imagestride"));
        ADD_FAILURE() << "a strided image bufferView loaded";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("bufferView 3 holds an image but defines byteStride 8"),
                  std::string::npos)
            << e.what();
    }
}

}  // namespace
}  // namespace gdpt
