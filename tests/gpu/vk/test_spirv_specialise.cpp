// test_spirv_specialise.cpp — kernels whose specialisation constants gdpt folds in before the
// driver sees them (vk/spirv_specialise.h): the same images as the driver's own
// specialisation, the constants and the code they switch off gone from the module, and a
// cache on disk that survives corrupt, foreign and unwritable files.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "gdpt_shared.h"
#include "gpu_fixture.h"
#include "integrator/gpt_sampler.h"
#include "integrator/integrator.h"
#include "integrator/pt_sampler.h"
#include "pt.spv.h"
#include "same_bits.h"
#include "scene/gltf_loader.h"
#include "scoped_env.h"
#include "spirv_words.h"
#include "temp_dir.h"
#include "util/error.h"
#include "vk/context.h"
#include "vk/spirv_specialise.h"

namespace gdpt {
namespace {

namespace fs = std::filesystem;

constexpr std::uint32_t kOpDecorate = 71;
constexpr std::uint32_t kDecorationSpecId = 1;

// The SpecId decorations of a module, in order.
std::vector<std::uint32_t> specIds(const std::vector<std::uint32_t>& words) {
    std::vector<std::uint32_t> ids;
    test::forEachSpirvInstruction(words, [&](std::uint32_t op, const std::uint32_t* in, std::uint32_t count) {
        if (op == kOpDecorate && count >= 4 && in[2] == kDecorationSpecId) ids.push_back(in[3]);
    });
    return ids;
}

std::vector<std::uint32_t> ptWords() {
    return std::vector<std::uint32_t>(std::begin(kSpv_pt_opt), std::end(kSpv_pt_opt));
}

// GDPT_SPECIALISE and GDPT_CACHE_DIR are set for a scope (renders read them when their kernels
// are made).
using test::ScopedEnv;

class SpirvSpecialise : public test::TempDirTest {};

TEST_F(SpirvSpecialise, ConstantsAndTheCodeTheySwitchOffAreGone) {
    const std::vector<std::uint32_t> words = ptWords();
    const std::vector<std::uint32_t> before = specIds(words);
    ASSERT_GE(before.size(), 5u);
    ASSERT_NE(std::find(before.begin(), before.end(), gpu::kSpecHasTextures), before.end());

    vk::SpecConstants off, on;
    for (std::uint32_t id :
         {gpu::kSpecHasTextures, gpu::kSpecHasEnv, gpu::kSpecHasGlossy, gpu::kSpecHasAlphaMask}) {
        off.emplace_back(id, 0u);
        on.emplace_back(id, 1u);
    }
    const std::vector<std::uint32_t> a = vk::specialiseSpirv(words.data(), words.size(), off);
    const std::vector<std::uint32_t> b = vk::specialiseSpirv(words.data(), words.size(), on);
    ASSERT_GE(a.size(), 5u);
    EXPECT_EQ(a[0], 0x07230203u);
    // Every constant is frozen, the listed ones and the rest (at their defaults).
    EXPECT_TRUE(specIds(a).empty());
    EXPECT_TRUE(specIds(b).empty());
    // Features off remove their code; on, they keep it.
    EXPECT_LT(a.size(), b.size());
    EXPECT_LT(a.size() * 10, words.size() * 9) << "less than a tenth removed with four features off";
    // Deterministic.
    EXPECT_EQ(vk::specialiseSpirv(words.data(), words.size(), off), a);
    // A constant left to the driver stays a specialisation constant (with its id), the rest
    // are frozen as before.
    const std::vector<std::uint32_t> kept =
        vk::specialiseSpirv(words.data(), words.size(), off, {gpu::kSpecBvhRegisterStack});
    EXPECT_EQ(specIds(kept), std::vector<std::uint32_t>{gpu::kSpecBvhRegisterStack});
    EXPECT_GT(kept.size(), a.size()) << "its branches are not folded";
}

TEST_F(SpirvSpecialise, BadInputIsAnErrorNotACrash) {
    std::vector<std::uint32_t> words = ptWords();
    words.resize(words.size() / 2);  // cut in the middle of the functions
    EXPECT_THROW((void)vk::specialiseSpirv(words.data(), words.size(), {}), Error);
    const std::vector<std::uint32_t> junk(64, 0xDEADBEEFu);
    EXPECT_THROW((void)vk::specialiseSpirv(junk.data(), junk.size(), {}), Error);
}

TEST_F(SpirvSpecialise, TheCacheReturnsWhatTheOptimizerMade) {
    const std::vector<std::uint32_t> words = ptWords();
    const vk::SpecConstants constants = {{gpu::kSpecHasTextures, 0u}, {gpu::kSpecMaxDepth, 9u}};
    const fs::path dir = path("cache");
    const vk::SpecialisedSpirv first = vk::specialiseCached(words.data(), words.size(), constants, dir);
    EXPECT_EQ(first.source, vk::SpecialiseSource::Optimizer);
    const fs::path file = vk::specialisedCachePath(words.data(), words.size(), constants, dir);
    ASSERT_TRUE(fs::exists(file));
    const vk::SpecialisedSpirv second = vk::specialiseCached(words.data(), words.size(), constants, dir);
    EXPECT_EQ(second.source, vk::SpecialiseSource::Cache);
    EXPECT_EQ(second.words, first.words);
    // Another constant left to the driver is another file too.
    EXPECT_NE(vk::specialisedCachePath(words.data(), words.size(), constants, dir, {gpu::kSpecHasEnv}), file);
    // Other values are another file.
    const vk::SpecConstants other = {{gpu::kSpecHasTextures, 0u}, {gpu::kSpecMaxDepth, 10u}};
    EXPECT_NE(vk::specialisedCachePath(words.data(), words.size(), other, dir), file);
    EXPECT_EQ(vk::specialiseCached(words.data(), words.size(), other, dir).source,
              vk::SpecialiseSource::Optimizer);
    // No temporary files are left beside them.
    EXPECT_EQ(listing("cache/spirv").size(), 2u);
}

TEST_F(SpirvSpecialise, DamagedCacheFilesAreReplaced) {
    const std::vector<std::uint32_t> words = ptWords();
    const vk::SpecConstants constants = {{gpu::kSpecHasEnv, 1u}};
    const fs::path dir = path("cache");
    const std::vector<std::uint32_t> good =
        vk::specialiseCached(words.data(), words.size(), constants, dir).words;
    const fs::path file = vk::specialisedCachePath(words.data(), words.size(), constants, dir);
    const std::string bytes = test::readText(file.string());
    ASSERT_GT(bytes.size(), 1000u);

    const auto damaged = [&](const std::string& what, const std::string& content) {
        std::ofstream(file, std::ios::binary | std::ios::trunc) << content;
        const vk::SpecialisedSpirv s = vk::specialiseCached(words.data(), words.size(), constants, dir);
        EXPECT_EQ(s.source, vk::SpecialiseSource::Optimizer) << what;
        EXPECT_EQ(s.words, good) << what;
        EXPECT_EQ(test::readText(file.string()), bytes) << what << ": not rewritten";
    };
    std::string flipped = bytes;
    flipped[bytes.size() / 2] = static_cast<char>(flipped[bytes.size() / 2] ^ 0x10);
    damaged("a flipped bit in the module", flipped);
    damaged("truncated", bytes.substr(0, bytes.size() - 4));
    damaged("trailing bytes", bytes + "xyzw");
    damaged("empty", "");
    damaged("a header only", bytes.substr(0, 32));
    // Another key's file under this name (a renamed file).
    const vk::SpecConstants other = {{gpu::kSpecHasEnv, 0u}};
    (void)vk::specialiseCached(words.data(), words.size(), other, dir);
    damaged("another key's file",
            test::readText(vk::specialisedCachePath(words.data(), words.size(), other, dir).string()));
}

TEST_F(SpirvSpecialise, TheCacheStaysBoundedAndKeepsWhatWasUsedLast) {
    const std::vector<std::uint32_t> words = ptWords();
    const fs::path dir = path("cache");
    const vk::SpecConstants used = {{gpu::kSpecHasEnv, 1u}};
    (void)vk::specialiseCached(words.data(), words.size(), used, dir);
    const fs::path usedFile = vk::specialisedCachePath(words.data(), words.size(), used, dir);
    // Older files than any real one, oldest first; then the used one is read (renewed).
    const auto old = fs::file_time_type::clock::now() - std::chrono::hours(1);
    const std::size_t fill = vk::kSpecialiseCacheFiles + 20;
    for (std::size_t i = 0; i < fill; ++i) {
        const fs::path f = dir / "spirv" / ("old" + std::to_string(1000 + i) + ".spv");
        std::ofstream(f) << "x";
        fs::last_write_time(f, old + std::chrono::seconds(i));
    }
    fs::last_write_time(usedFile, old - std::chrono::hours(1));
    EXPECT_EQ(vk::specialiseCached(words.data(), words.size(), used, dir).source,
              vk::SpecialiseSource::Cache);
    // A write past the bound evicts the oldest.
    const vk::SpecConstants fresh = {{gpu::kSpecHasEnv, 0u}};
    (void)vk::specialiseCached(words.data(), words.size(), fresh, dir);
    const std::vector<std::string> left = listing("cache/spirv");
    EXPECT_EQ(left.size(), vk::kSpecialiseCacheFiles * 3 / 4);
    EXPECT_TRUE(fs::exists(usedFile)) << "the file read last was evicted";
    EXPECT_TRUE(fs::exists(vk::specialisedCachePath(words.data(), words.size(), fresh, dir)));
    EXPECT_FALSE(fs::exists(dir / "spirv" / "old1000.spv")) << "the oldest file was kept";
    EXPECT_TRUE(fs::exists(dir / "spirv" / ("old" + std::to_string(1000 + fill - 1) + ".spv")));
}

TEST_F(SpirvSpecialise, AnUnwritableCacheOnlyCostsTime) {
    const std::vector<std::uint32_t> words = ptWords();
    const vk::SpecConstants constants = {{gpu::kSpecHasEnv, 1u}};
    const std::vector<std::uint32_t> expected = vk::specialiseSpirv(words.data(), words.size(), constants);
    // The cache directory is a regular file: nothing can be created under it.
    std::ofstream(path("file")) << "x";
    for (int i = 0; i < 2; ++i) {
        const vk::SpecialisedSpirv s =
            vk::specialiseCached(words.data(), words.size(), constants, path("file"));
        EXPECT_EQ(s.source, vk::SpecialiseSource::Optimizer);
        EXPECT_EQ(s.words, expected);
    }
    // No cache at all.
    EXPECT_EQ(vk::specialiseCached(words.data(), words.size(), constants, fs::path()).words, expected);
}

TEST(SpirvSpecialiseChoice, CpuDevicesByDefaultAndTheEnvironmentOverrides) {
    vk::DeviceInfo cpu;
    cpu.isCpu = true;
    vk::DeviceInfo mesa22 = cpu;
    mesa22.lavapipeBeforeMesa23 = true;
    vk::DeviceInfo gpu;
    ::unsetenv("GDPT_SPECIALISE");
    EXPECT_TRUE(vk::useSpecialisedSpirv(cpu));
    EXPECT_TRUE(vk::useSpecialisedSpirv(mesa22));
    EXPECT_FALSE(vk::useSpecialisedSpirv(gpu));
    {
        ScopedEnv e("GDPT_SPECIALISE", "on");
        EXPECT_TRUE(vk::useSpecialisedSpirv(gpu));
        EXPECT_TRUE(vk::useSpecialisedSpirv(mesa22));
    }
    {
        ScopedEnv e("GDPT_SPECIALISE", "off");
        EXPECT_FALSE(vk::useSpecialisedSpirv(cpu));
        EXPECT_FALSE(vk::useSpecialisedSpirv(mesa22));
    }
    {
        ScopedEnv e("GDPT_SPECIALISE", "yes");
        EXPECT_THROW((void)vk::useSpecialisedSpirv(cpu), Error);
    }
}

class SpirvSpecialiseGpu : public test::GpuTest {
protected:
    void SetUp() override {
        GpuTest::SetUp();
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = fs::temp_directory_path() / ("gdpt_" + std::to_string(::getpid()) + "_" + info->name());
        fs::remove_all(dir_);
    }
    void TearDown() override {
        fs::remove_all(dir_);
        GpuTest::TearDown();
    }
    fs::path dir_;
};

// Folding the constants before the driver changes what the driver compiles, not what it
// computes: PT, every G-PT buffer (both bounce loops) and G-MLT render the same bits on
// lavapipe (glossy_cornell: glossy vertices and a specular lobe on, textures and the
// environment off). A GPU's compiler may fuse multiply-adds differently in the two modules:
// there they agree up to rounding.
TEST_F(SpirvSpecialiseGpu, SameImagesAsTheDriversOwnSpecialisation) {
    ScopedEnv cache("GDPT_CACHE_DIR", dir_.string());
    const bool bits = ctx().info().isCpu;
    for (const char* name : {"glossy_cornell"}) {
        const Scene scene = loadGltf(std::string(GDPT_SOURCE_DIR "/scenes/") + name + ".gltf");
        const RenderOptions o = renderOptions(24, 24, 2, 5);
        GptSamplingOptions split, single;
        split.splitBounce = GptPassOptions::SplitBounce::On;
        single.splitBounce = GptPassOptions::SplitBounce::Off;
        const auto renderAll = [&] {
            struct {
                Image pt;
                RenderResultGpt split, single;
                Image gmlt;
            } r{renderPt(ctx(), scene, o).image, renderGpt(ctx(), scene, o, split),
                renderGpt(ctx(), scene, o, single), makeIntegrator("gmlt")->render(ctx(), scene, o).image()};
            return r;
        };
        const auto driver = [&] {
            ScopedEnv e("GDPT_SPECIALISE", "off");
            return renderAll();
        }();
        EXPECT_FALSE(fs::exists(dir_ / "spirv")) << name << ": specialised although off";
        const auto ours = [&] {
            ScopedEnv e("GDPT_SPECIALISE", "on");
            return renderAll();
        }();
        ASSERT_TRUE(fs::exists(dir_ / "spirv")) << name << ": nothing was specialised";
        const std::string what = std::string(name) + " ";
        if (bits) {
            test::expectSameBits(driver.pt, ours.pt, what + "pt");
            test::expectSameBits(driver.gmlt, ours.gmlt, what + "gmlt");
        } else {
            test::expectSameUpToRounding(driver.pt, ours.pt, what + "pt");
            test::expectSameUpToRounding(driver.gmlt, ours.gmlt, what + "gmlt");
        }
        test::expectSameGptBits(driver.split, ours.split, what + "gpt split", bits);
        test::expectSameGptBits(driver.single, ours.single, what + "gpt single loop", bits);
    }
}

// The kernels a render specialises are cached: a second render reads them all back.
TEST_F(SpirvSpecialiseGpu, ASecondRenderFindsItsKernelsInTheCache) {
    ScopedEnv cache("GDPT_CACHE_DIR", dir_.string());
    ScopedEnv e("GDPT_SPECIALISE", "on");
    const Scene scene = loadGltf(GDPT_SOURCE_DIR "/scenes/cornell_box.gltf");
    const RenderOptions o = renderOptions(16, 16, 1, 2);
    const vk::SpecialiseCounts start = vk::specialiseCounts();
    const RenderResultGpt first = renderGpt(ctx(), scene, o);
    const vk::SpecialiseCounts afterFirst = vk::specialiseCounts();
    EXPECT_GE(afterFirst.byOptimizer - start.byOptimizer, 2u)
        << "the path kernel and the edge kernel at least";
    EXPECT_EQ(afterFirst.fromCache, start.fromCache);
    const RenderResultGpt second = renderGpt(ctx(), scene, o);
    const vk::SpecialiseCounts afterSecond = vk::specialiseCounts();
    EXPECT_EQ(afterSecond.byOptimizer, afterFirst.byOptimizer) << "a kernel was specialised again";
    EXPECT_EQ(afterSecond.fromCache - afterFirst.fromCache, afterFirst.byOptimizer - start.byOptimizer);
    test::expectSameGptBits(first, second, "second render");
}

}  // namespace
}  // namespace gdpt
