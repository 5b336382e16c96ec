// sample_share.h: the parts of a split render take every sample of the render exactly once
// (each part's samples s ≡ I mod N, its local counts summing to the render's spp), and "I/N" is
// parsed strictly.
#include <gtest/gtest.h>

#include <set>

#include "integrator/sample_share.h"
#include "util/error.h"

namespace gdpt {
namespace {

TEST(SampleShare, PartsTakeEverySampleOfTheRenderExactlyOnce) {
    for (std::uint32_t parts = 1; parts <= 9; ++parts)
        for (std::uint32_t spp = parts; spp <= 40; ++spp) {
            std::multiset<std::uint64_t> taken;
            std::uint32_t total = 0;
            for (std::uint32_t i = 0; i < parts; ++i) {
                const SampleShare share{i, parts};
                const std::uint32_t local = share.localSpp(spp);
                total += local;
                // Every part takes at least one sample, and the shares differ by at most one.
                EXPECT_GE(local, 1u);
                EXPECT_LE(local, (spp + parts - 1) / parts);
                for (std::uint32_t j = 0; j < local; ++j) taken.insert(share.globalSample(j));
            }
            ASSERT_EQ(total, spp) << parts << " parts of " << spp;
            std::uint64_t expected = 0;
            for (std::uint64_t s : taken) EXPECT_EQ(s, expected++) << parts << " parts of " << spp;
        }
}

TEST(SampleShare, APartIsSpreadOverTheSampleIndices) {
    // Part 2 of 4 takes 2, 6, 10, ...: over any 4 consecutive samples, one.
    const SampleShare share{2, 4};
    EXPECT_EQ(share.globalSample(0), 2u);
    EXPECT_EQ(share.globalSample(1), 6u);
    EXPECT_EQ(share.globalSample(10), 42u);
    EXPECT_EQ(share.localSpp(2), 0u);
    EXPECT_EQ(share.localSpp(3), 1u);
    EXPECT_EQ(share.localSpp(7), 2u);
}

TEST(SampleShare, ParsesIOverNStrictly) {
    const SampleShare s = parseSampleShare("3/8", "--shard");
    EXPECT_EQ(s.index, 3u);
    EXPECT_EQ(s.count, 8u);
    EXPECT_EQ(s.text(), "3/8");
    EXPECT_FALSE(parseSampleShare("0/1", "--shard").split());
    for (const char* bad : {"", "3", "/8", "3/", "8/8", "9/8", "-1/8", "1/0", "a/b", "1/8x", " 1/8", "1//8",
                            "0/65537", "1234567890/1234567891"}) {
        try {
            (void)parseSampleShare(bad, "--shard");
            ADD_FAILURE() << "'" << bad << "' was accepted";
        } catch (const UsageError& e) {
            EXPECT_NE(std::string(e.what()).find("--shard"), std::string::npos) << e.what();
        }
    }
    EXPECT_EQ(parseSampleShare("65535/65536", "--shard").count, kMaxShares);
}

}  // namespace
}  // namespace gdpt
