// vk::Buffer's two ways of reading and clearing memory: from the host where the memory is
// host-cached (a CPU device), and through the device (a copy into host-cached staging memory,
// in chunks of Buffer::kStagingChunk; vkCmdFillBuffer) where it is not (a discrete GPU's
// write-combined memory). A context with ContextOptions::stagedTransfers takes the second way on
// lavapipe, so both run in CI: the bytes and a whole render must come out the same.
#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <vector>

#include "gpu_fixture.h"
#include "integrator/gpt_sampler.h"
#include "integrator/pt_sampler.h"
#include "same_bits.h"
#include "scene/gltf_loader.h"
#include "vk/buffer.h"

namespace gdpt {
namespace {

void stageTransfers(vk::ContextOptions& o) {
    o.stagedTransfers = true;
}

class BufferTransfers : public test::SecondContextTest<stageTransfers> {
protected:
    static vk::Context& staged() { return second(); }
};

std::vector<std::uint8_t> randomBytes(std::size_t n, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::vector<std::uint8_t> v(n);
    for (auto& b : v) b = static_cast<std::uint8_t>(rng());
    return v;
}

TEST_F(BufferTransfers, TheStagedContextReadsThroughTheDevice) {
    const vk::Buffer s(staged(), 1024, "staged probe");
    EXPECT_FALSE(s.hostReadsDirectly());
    // The default context on a CPU device reads its own memory.
    const vk::Buffer d(ctx(), 1024, "direct probe");
    if (ctx().info().isCpu) {
        EXPECT_TRUE(d.hostReadsDirectly());
    }
}

// Past one staging chunk, at offsets that straddle the chunk boundary and are not multiples of
// the copy's natural sizes: every byte comes back, and nothing outside the range is touched.
TEST_F(BufferTransfers, StagedDownloadsAcrossChunksReturnEveryByte) {
    const std::size_t n = vk::Buffer::kStagingChunk + 3 * 4096 + 12;
    const auto bytes = randomBytes(n, 11);
    vk::Buffer b(staged(), n, "staged round trip");
    b.upload(bytes.data(), n);
    std::vector<std::uint8_t> back(n, 0xAB);
    b.download(back.data(), n);
    EXPECT_EQ(std::memcmp(back.data(), bytes.data(), n), 0);

    const std::size_t offset = vk::Buffer::kStagingChunk - 4000;
    const std::size_t len = 9000;
    std::vector<std::uint8_t> part(len + 8, 0xCD);
    b.download(part.data() + 4, len, offset);
    EXPECT_EQ(std::memcmp(part.data() + 4, bytes.data() + offset, len), 0);
    for (int i = 0; i < 4; ++i) {
        EXPECT_EQ(part[i], 0xCD);
        EXPECT_EQ(part[len + 4 + i], 0xCD);
    }
}

TEST_F(BufferTransfers, ZeroClearsThroughTheDevice) {
    const std::size_t n = 1 << 16;
    const auto bytes = randomBytes(n, 12);
    vk::Buffer b(staged(), n, "staged zero");
    b.uploadVector(bytes);
    b.zero();
    const auto back = b.downloadVector<std::uint8_t>(n);
    for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(back[i], 0) << "byte " << i;
}

// Everything a render reads back (its statistics, its image) through staged copies is the same
// bits as through the host's own reads.
TEST_F(BufferTransfers, ARenderReadThroughStagingIsTheSameImage) {
    const Scene scene = loadGltf(GDPT_SOURCE_DIR "/scenes/cornell_box.gltf");
    const RenderOptions o = renderOptions(40, 30, 2, 3);
    const Image direct = renderPt(ctx(), scene, o).image;
    const Image viaStaging = renderPt(staged(), scene, o).image;
    test::expectSameBits(direct, viaStaging, "pt");
    test::expectSameGptBits(renderGpt(ctx(), scene, o), renderGpt(staged(), scene, o), "gpt");
}

}  // namespace
}  // namespace gdpt
