// Images whose per-pixel buffers exceed maxStorageBufferRange (128 MiB on lavapipe) render every
// pixel: the sampling kernels reach those buffers through device addresses
// (shaders/lib/pixel_buffers.glsl). The scene is the white furnace with --max-depth 0, where
// every camera ray sees emission 0.5 and nothing else, so every pixel of PT and of G-PT (its
// very-direct light, through the resolved images; the L2 reconstruction of zero gradients and
// primal is zero) is exactly 0.5: a buffer address or a 64-bit offset computed wrongly leaves
// pixels at 0 or garbage. The images are thin so that the test stays short:
//   PT   16384 x 300 = 4.9 Mpixel: its statistics (32 B/pixel) and emitter supersampling's are
//        150 MiB each;
//   G-PT 4096 x 352 = 1.4 Mpixel: its resolved images (96 B/pixel) are 132 MiB.
// That every buffer's binding is the right one is checked at small sizes by the rest of the
// suite (bit-exact checkpoints, G-PT against PT), since the same code serves every size.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include "cli_runner.h"
#include "image/exr_io.h"

namespace gdpt {
namespace {

class LargeImagesCli : public test::TempDirTest {};

TEST_F(LargeImagesCli, BuffersBeyondTheStorageBufferRangeHoldEveryPixel) {
    const std::string scene = std::string(GDPT_SOURCE_DIR) + "/scenes/furnace.gltf";
    struct Case {
        const char* method;
        int width, height;
        const char* extra;
    };
    for (const Case& c : {Case{"pt", 16384, 300, ""}, Case{"gpt", 4096, 352, "--recon l2"}}) {
        const std::string out = path(std::string(c.method) + ".exr");
        const test::RunResult r =
            test::runGdpt("render " + scene + " --method " + c.method + " --width " +
                          std::to_string(c.width) + " --height " + std::to_string(c.height) +
                          " --spp 1 --max-depth 0 --quiet --validate " + c.extra + " -o " + out);
        ASSERT_EQ(r.code, 0) << c.method << ": " << r.output;
        const auto layers = readExr(out);
        ASSERT_FALSE(layers.empty());
        const Image& image = layers.front().image;
        ASSERT_EQ(image.width(), c.width);
        ASSERT_EQ(image.height(), c.height);
        std::size_t wrong = 0, first = image.pixelCount();
        for (int ch = 0; ch < 3; ++ch)
            for (std::size_t i = 0; i < image.pixelCount(); ++i)
                if (image.plane(ch)[i] != 0.5f) {
                    ++wrong;
                    first = std::min(first, i);
                }
        EXPECT_EQ(wrong, 0u) << c.method << ": first at pixel " << first % image.width() << ", "
                             << first / image.width();
    }
}

// A render whose image would not fit the machine's memory is refused before any work with the
// largest image of the same shape that fits (GDPT_TEST_MEMORY_BYTES stands in for a 2 GB
// machine). That the advised image passes the check, and one a pixel wider does not, is
// tested on the check itself (PixelBuffers.ImageMemory*).
TEST_F(LargeImagesCli, AnImageBeyondTheMachinesMemoryIsRefusedWithTheLargestThatFits) {
    const std::string scene = std::string(GDPT_SOURCE_DIR) + "/scenes/cornell_box.gltf";
    const std::string exr = path("r.exr");
    const std::string small = "GDPT_TEST_MEMORY_BYTES=2000000000";
    for (const char* method : {"gpt", "pt"}) {
        // G-PT takes about 850 MiB per megapixel, PT 170: 2 GB holds 2.2 and 11 megapixels.
        const std::string size =
            std::string(method) == "gpt" ? "--width 2000 --height 1500" : "--width 6000 --height 3000";
        const test::RunResult r = test::runGdpt(
            "render " + scene + " --method " + method + " " + size + " --spp 1 -o " + exr, small);
        EXPECT_EQ(r.code, 1) << r.output;
        EXPECT_NE(r.output.find("more than this machine's"), std::string::npos) << r.output;
        const auto at = r.output.find("the largest image of this shape that fits is ");
        ASSERT_NE(at, std::string::npos) << r.output;
        unsigned w = 0, h = 0;
        ASSERT_EQ(std::sscanf(r.output.c_str() + at + 45, "%ux%u", &w, &h), 2) << r.output;
        EXPECT_LT(w, std::string(method) == "gpt" ? 2000u : 6000u);
        EXPECT_NEAR(double(w) / double(h), 2.0 / (std::string(method) == "gpt" ? 1.5 : 1.0), 0.01);
        EXPECT_FALSE(std::filesystem::exists(exr)) << "output left behind";
    }
}

}  // namespace
}  // namespace gdpt
