// An image too large for the device is refused up front with a message naming the buffer,
// the image size and the device limit, for every method. Guards the class "device limits are
// checked before allocating": PT at 16384x16384 used to fail inside vkCreateBuffer with a raw
// "VK_ERROR_OUT_OF_DEVICE_MEMORY: vkCreateBuffer(...) (src/vk/buffer.cpp:29)", where G-PT
// named the limit. 16384² pixel statistics (32 bytes each) need 8 GiB per buffer, above
// every device's maxStorageBufferRange (at most 4 GiB) and maxMemoryAllocationSize.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>

#include "cli_runner.h"

namespace gdpt {
namespace {

namespace fs = std::filesystem;
using test::runGdpt;
using test::RunResult;

const std::string kScene = std::string(GDPT_SOURCE_DIR) + "/scenes/cornell_box.gltf";

class SizeLimitsCli : public test::TempDirTest {};

TEST_F(SizeLimitsCli, ImageTooLargeForTheDeviceNamesTheLimit) {
    for (const char* method : {"pt", "gpt"}) {
        // As if the machine had 10 TB, so that its memory (checked first) does not bind.
        const RunResult r =
            runGdpt("render " + kScene + " --width 16384 --height 16384 --spp 1 --quiet --method " + method +
                        " -o " + path("big.exr"),
                    "GDPT_TEST_MEMORY_BYTES=10000000000000");
        EXPECT_EQ(r.code, 1) << method << ": " << r.output;
        EXPECT_NE(r.output.find("16384x16384"), std::string::npos) << method << ": " << r.output;
        EXPECT_NE(r.output.find("device limit"), std::string::npos) << method << ": " << r.output;
        EXPECT_EQ(r.output.find("VK_ERROR"), std::string::npos) << method << ": " << r.output;
        EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << "one line: " << r.output;
        EXPECT_FALSE(fs::exists(path("big.exr")));
    }
}

}  // namespace
}  // namespace gdpt
