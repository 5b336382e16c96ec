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

}  // namespace
}  // namespace gdpt
