// `render --json`'s memory section: peak host and device memory, and per megapixel. The device
// peak must grow with the image by at least the per-pixel statistics every method keeps on the
// device: a Welford mean and M2 per channel and a sample count, 32-bit each (28 bytes a pixel).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "cli_runner.h"

namespace gdpt {
namespace {

const std::string kScene = std::string(GDPT_SOURCE_DIR) + "/scenes/cornell_box.gltf";

class MemoryReportCli : public test::TempDirTest {
protected:
    nlohmann::json memoryAt(int size) {
        const std::string s = std::to_string(size);
        const test::RunResult r =
            test::runGdpt("render " + kScene + " --method pt --spp 1 --quiet --width " + s + " --height " +
                          s + " -o " + path("m.exr") + " --json " + path("m.json"));
        EXPECT_EQ(r.code, 0) << r.output;
        return nlohmann::json::parse(test::readText(path("m.json"))).at("memory");
    }
};

TEST_F(MemoryReportCli, DevicePeakGrowsByAtLeastThePerPixelStatistics) {
    const nlohmann::json small = memoryAt(32);
    const nlohmann::json large = memoryAt(256);
    EXPECT_GT(small.at("host_peak_bytes").get<double>(), 0.0);
    const double extraPixels = 256.0 * 256.0 - 32.0 * 32.0;
    EXPECT_GE(large.at("device_peak_bytes").get<double>() - small.at("device_peak_bytes").get<double>(),
              extraPixels * 28);
    EXPECT_DOUBLE_EQ(large.at("megapixels").get<double>(), 256.0 * 256.0 * 1e-6);
    EXPECT_NEAR(large.at("device_peak_bytes_per_megapixel").get<double>(),
                large.at("device_peak_bytes").get<double>() / (256.0 * 256.0 * 1e-6), 1.0);
}

}  // namespace
}  // namespace gdpt
