// Real image sizes on the default device (lavapipe: a few minutes and up to ~8 GB of memory,
// hence the slow label): 3840x2160 with PT and G-PT, 7680x4320 with PT, one sample per pixel of
// the Cornell box. Each renders a finite image of the asked size and reports its peak memory
// per megapixel in --json. (The buffers beyond maxStorageBufferRange are checked pixel by pixel
// in the default suite, tests/gpu/app/test_large_images_cli.cpp.)
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_runner.h"
#include "image/exr_io.h"

namespace gdpt {
namespace {

struct Size {
    const char* method;
    int width, height;
};

class RealSizes : public test::TempDirTest, public ::testing::WithParamInterface<Size> {};

TEST_P(RealSizes, RendersAFiniteImageAndReportsItsMemory) {
    const Size s = GetParam();
    const std::string scene = std::string(GDPT_SOURCE_DIR) + "/scenes/cornell_box.gltf";
    const test::RunResult r = test::runGdpt(
        "render " + scene + " --method " + s.method + " --width " + std::to_string(s.width) + " --height " +
        std::to_string(s.height) + " --spp 1 --quiet -o " + path("out.exr") + " --json " + path("out.json"));
    ASSERT_EQ(r.code, 0) << r.output;
    const auto layers = readExr(path("out.exr"));
    ASSERT_FALSE(layers.empty());
    const Image& image = layers.front().image;
    ASSERT_EQ(image.width(), s.width);
    ASSERT_EQ(image.height(), s.height);
    double sum = 0.0;
    for (int c = 0; c < 3; ++c)
        for (float v : image.plane(c)) {
            ASSERT_TRUE(std::isfinite(v));
            sum += v;
        }
    EXPECT_GT(sum, 0.0);
    const nlohmann::json j = nlohmann::json::parse(test::readText(path("out.json")));
    EXPECT_NEAR(j.at("memory").at("megapixels").get<double>(), s.width * double(s.height) * 1e-6, 1e-6);
    EXPECT_GT(j.at("memory").at("device_peak_bytes").get<double>(), 0.0);
    RecordProperty("device_peak_bytes_per_megapixel",
                   std::to_string(j.at("memory").at("device_peak_bytes_per_megapixel").get<double>()));
}

INSTANTIATE_TEST_SUITE_P(Sizes, RealSizes,
                         ::testing::Values(Size{"pt", 3840, 2160}, Size{"gpt", 3840, 2160},
                                           Size{"pt", 7680, 4320}),
                         [](const auto& p) {
                             return std::string(p.param.method) + "_" + std::to_string(p.param.width);
                         });

}  // namespace
}  // namespace gdpt
