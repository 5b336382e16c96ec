// test_spirv_variants.cpp — the two embedded SPIR-V forms of every kernel (glslang's, and
// spirv-opt's: cmake/GdptSpirvEmbed.cmake) render the same image, and which one a device
// gets (vk::useOptimizedSpirv: lavapipe before Mesa 23, read from the driver string).
#include <gtest/gtest-spi.h>
#include <gtest/gtest.h>

#include <cstdlib>

#include "gpu_fixture.h"
#include "integrator/gpt_sampler.h"
#include "integrator/pt_sampler.h"
#include "integrator/render_options.h"
#include "same_bits.h"
#include "scene/gltf_loader.h"
#include "util/error.h"
#include "vk/kernel.h"

namespace gdpt {
namespace {

TEST(SpirvVariants, MesaMajorVersionComesFromTheDriverString) {
    EXPECT_EQ(vk::mesaMajorVersion("Mesa 22.3.6 (LLVM 15.0.6)", VK_MAKE_VERSION(22, 3, 6)), 22u);
    // Mesa 25's lavapipe reports driverVersion 1: the string decides.
    EXPECT_EQ(vk::mesaMajorVersion("Mesa 25.0.7-2~bpo12+1 (LLVM 15.0.6)", 1u), 25u);
    // Not Mesa's format: driverVersion as VK_MAKE_VERSION.
    EXPECT_EQ(vk::mesaMajorVersion("NVIDIA 550.54", VK_MAKE_VERSION(550, 54, 0)), 550u & 0x7Fu);
    EXPECT_EQ(vk::mesaMajorVersion("Mesa x", VK_MAKE_VERSION(23, 1, 0)), 23u);
}

TEST(SpirvVariants, EnvironmentChoosesTheVariant) {
    vk::DeviceInfo old;
    old.lavapipeBeforeMesa23 = true;
    vk::DeviceInfo other;
    ::unsetenv("GDPT_SPIRV");
    EXPECT_TRUE(vk::useOptimizedSpirv(old));
    EXPECT_FALSE(vk::useOptimizedSpirv(other));
    ::setenv("GDPT_SPIRV", "opt", 1);
    EXPECT_TRUE(vk::useOptimizedSpirv(other));
    ::setenv("GDPT_SPIRV", "raw", 1);
    EXPECT_FALSE(vk::useOptimizedSpirv(old));
    ::setenv("GDPT_SPIRV", "fast", 1);
    EXPECT_THROW(vk::useOptimizedSpirv(old), Error);
    ::unsetenv("GDPT_SPIRV");
}

class SpirvVariantsGpu : public test::GpuTest {};

// spirv-opt only inlines, promotes locals to SSA and removes dead code: on lavapipe the
// arithmetic is the same, so the images are the same bits (PT, and every buffer G-PT's
// sampler writes, with the split bounce loop and without). A GPU's compiler may fuse
// multiply-adds differently in the two forms (an NVIDIA driver did, 2026-12-04): there the
// images must agree up to rounding (same_bits.h).
TEST_F(SpirvVariantsGpu, OptimizedAndRawSpirvRenderTheSameImage) {
    const Scene scene = loadGltf(GDPT_SOURCE_DIR "/scenes/glossy_cornell.gltf");
    RenderOptions o = renderOptions(24, 24, 2, 5);
    ::setenv("GDPT_SPIRV", "raw", 1);
    const Image ptRaw = renderPt(ctx(), scene, o).image;
    GptSamplingOptions split;
    split.splitBounce = GptPassOptions::SplitBounce::On;
    GptSamplingOptions single;
    single.splitBounce = GptPassOptions::SplitBounce::Off;
    const RenderResultGpt splitRaw = renderGpt(ctx(), scene, o, split);
    const RenderResultGpt singleRaw = renderGpt(ctx(), scene, o, single);
    ::setenv("GDPT_SPIRV", "opt", 1);
    const Image ptOpt = renderPt(ctx(), scene, o).image;
    const RenderResultGpt splitOpt = renderGpt(ctx(), scene, o, split);
    const RenderResultGpt singleOpt = renderGpt(ctx(), scene, o, single);
    ::unsetenv("GDPT_SPIRV");
    const bool bits = ctx().info().isCpu;
    if (bits) {
        test::expectSameBits(ptRaw, ptOpt, "pt");
    } else {
        test::expectSameUpToRounding(ptRaw, ptOpt, "pt");
    }
    test::expectSameGptBits(splitRaw, splitOpt, "gpt split", bits);
    test::expectSameGptBits(singleRaw, singleOpt, "gpt single loop", bits);
}

// The rounding tolerance the GPUs get still tells two estimates apart: renders with different
// seeds (the smallest change of an estimator's output) fail it.
TEST_F(SpirvVariantsGpu, TheRoundingToleranceTellsDifferentSamplesApart) {
    const Scene scene = loadGltf(GDPT_SOURCE_DIR "/scenes/glossy_cornell.gltf");
    const Image a = renderPt(ctx(), scene, renderOptions(24, 24, 2, 5)).image;
    const Image b = renderPt(ctx(), scene, renderOptions(24, 24, 2, 6)).image;
    EXPECT_NONFATAL_FAILURE(test::expectSameUpToRounding(a, b, "seeds 5 and 6"),
                            "differ by more than rounding");
    test::expectSameUpToRounding(a, a, "itself");
}

}  // namespace
}  // namespace gdpt
