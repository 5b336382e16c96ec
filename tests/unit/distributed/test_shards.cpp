// shards.h: the merge of a render's shards checks that they are the parts 0..N-1 of one
// render, each once and complete, and merges them in part order whatever the order given;
// every refusal names the file (or the missing parts) and the reason.
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "distributed/shards.h"
#include "integrator/checkpoint.h"
#include "integrator/stats_merge.h"
#include "temp_dir.h"
#include "util/error.h"

namespace gdpt {
namespace {

constexpr int kW = 4, kH = 3;

// A shard file as `gdpt render --shard I/N` writes it (a PT checkpoint of 4x3 pixels), with
// statistics that depend on the part, so that a wrong merge shows.
SamplerState shardState(SampleShare part, std::uint32_t spp) {
    SamplerState s;
    s.spp = spp;
    s.nextBatch = 1;
    s.preview = Image(kW, kH);
    std::vector<gpu::PixelStats> path(kW * kH), visible(kW * kH);
    for (std::size_t i = 0; i < path.size(); ++i) {
        path[i].count = spp;
        path[i].mean = glm::vec3(0.1f * float(part.index + 1) + 0.01f * float(i), 0.5f, 1.0f / 3.0f);
        path[i].m2 = glm::vec3(0.25f * float(spp), 0.0f, 0.125f);
    }
    s.buffers = {path, visible};
    return s;
}

class Shards : public test::TempDirTest {
protected:
    // Writes part `part` of a `spp`-spp render; `seed` stands for any identity entry.
    std::string shard(const std::string& name, SampleShare part, std::uint32_t spp, std::uint32_t seed = 7,
                      std::uint32_t samples = ~0u) const {
        const ExrAttributes identity = {{"scene_fingerprint", "0123"},  {"method", "pt"},
                                        {"width", std::to_string(kW)},  {"height", std::to_string(kH)},
                                        {"seed", std::to_string(seed)}, {"share", part.text()}};
        const ExrAttributes info = {{"render_spp", std::to_string(spp)},
                                    {"render_args", "{}"},
                                    {"scene_path", "/nowhere/scene.gltf"}};
        const std::string p = path(name);
        writeCheckpoint(p, identity, info, shardState(part, samples == ~0u ? part.localSpp(spp) : samples));
        return p;
    }
    // The error mergeShards gives for `paths` ("" if none).
    static std::string mergeError(const std::vector<std::string>& paths) {
        try {
            (void)mergeShards(paths);
        } catch (const Error& e) {
            return e.what();
        }
        return "";
    }
};

TEST_F(Shards, MergeInPartOrderWhateverTheOrderGiven) {
    const std::string a = shard("a.exr", {0, 3}, 10), b = shard("b.exr", {1, 3}, 10),
                      c = shard("c.exr", {2, 3}, 10);
    const MergedShards inOrder = mergeShards({a, b, c});
    EXPECT_EQ(inOrder.state.spp, 10u);
    EXPECT_EQ(inOrder.stats.parts, 3u);
    EXPECT_EQ(inOrder.stats.partSpp, (std::vector<std::uint32_t>{4, 3, 3}));
    EXPECT_EQ(inOrder.identity.count("share"), 0u);
    // By hand, in part order.
    SamplerState expected = shardState({0, 3}, 4);
    mergeStateInto(expected, shardState({1, 3}, 3));
    mergeStateInto(expected, shardState({2, 3}, 3));
    for (const auto& order : std::vector<std::vector<std::string>>{{c, a, b}, {b, c, a}, {c, b, a}}) {
        const MergedShards m = mergeShards(order);
        ASSERT_EQ(m.state.buffers.size(), expected.buffers.size());
        for (std::size_t k = 0; k < expected.buffers.size(); ++k)
            EXPECT_EQ(std::memcmp(m.state.buffers[k].data(), expected.buffers[k].data(),
                                  expected.buffers[k].size() * sizeof(gpu::PixelStats)),
                      0)
                << "buffer " << k;
    }
    EXPECT_EQ(inOrder.state.buffers[0][5].count, 10u);
}

TEST_F(Shards, MissingDuplicatedAndForeignShardsAreRefusedByName) {
    const std::string a = shard("a.exr", {0, 3}, 10), b = shard("b.exr", {1, 3}, 10),
                      c = shard("c.exr", {2, 3}, 10);
    std::string e = mergeError({a, c});
    EXPECT_NE(e.find("1 of the 3 parts are missing: 1/3"), std::string::npos) << e;
    e = mergeError({a, b, shard("b2.exr", {1, 3}, 10), c});
    EXPECT_NE(e.find("b2.exr and "), std::string::npos) << e;
    EXPECT_NE(e.find("b.exr are both part 1/3"), std::string::npos) << e;
    // Another render: another seed, another number of parts, another spp.
    e = mergeError({a, shard("x.exr", {1, 3}, 10, /*seed=*/8), c});
    EXPECT_NE(e.find("x.exr belongs to another render than " + a + ": seed 8 (7 in"), std::string::npos) << e;
    e = mergeError({a, shard("y.exr", {1, 4}, 10), c});
    EXPECT_NE(e.find("y.exr is part 1/4 of a render in 4 parts"), std::string::npos) << e;
    e = mergeError({a, shard("z.exr", {1, 3}, 12), c});
    EXPECT_NE(e.find("z.exr is a part of a 12-spp render"), std::string::npos) << e;
    // An incomplete shard (interrupted, say).
    e = mergeError({a, shard("short.exr", {1, 3}, 10, 7, /*samples=*/2), c});
    EXPECT_NE(e.find("short.exr has 2 spp; part 1/3 of a 10-spp render takes 3"), std::string::npos) << e;
}

TEST_F(Shards, AWholeRendersCheckpointIsNotAShard) {
    const std::string whole = path("whole.exr");
    writeCheckpoint(whole, {{"scene_fingerprint", "0123"}, {"method", "pt"}, {"width", "4"}, {"height", "3"}},
                    {}, shardState({0, 1}, 5));
    const std::string e = mergeError({whole});
    EXPECT_NE(e.find("whole.exr: not a shard"), std::string::npos) << e;
}

}  // namespace
}  // namespace gdpt
