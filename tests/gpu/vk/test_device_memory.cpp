// Device-memory accounting of vk::Context (what `render --json` reports as memory.device_peak_bytes):
// every allocation made through vk::Buffer is counted while it lives, and the peak is kept.
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "gpu_fixture.h"
#include "vk/buffer.h"

namespace gdpt {
namespace {

class DeviceMemory : public test::GpuTest {};

TEST_F(DeviceMemory, BuffersAreCountedWhileTheyLiveAndThePeakIsKept) {
    const std::uint64_t before = ctx().deviceBytesNow();
    const std::uint64_t sizes[] = {1u << 20, 3u << 20, 5u << 20};
    std::uint64_t sum = 0;
    {
        std::vector<std::unique_ptr<vk::Buffer>> buffers;
        for (std::uint64_t bytes : sizes) {
            buffers.push_back(std::make_unique<vk::Buffer>(ctx(), bytes, "accounting probe"));
            sum += bytes;
            // The driver may round an allocation up to its alignment (a few KiB at most).
            EXPECT_GE(ctx().deviceBytesNow(), before + sum);
            EXPECT_LE(ctx().deviceBytesNow(), before + sum + buffers.size() * 65536u);
        }
        EXPECT_GE(ctx().deviceBytesPeak(), before + sum);
        buffers.pop_back();  // the 5 MiB one
        EXPECT_LT(ctx().deviceBytesNow(), before + sum - (4u << 20));
    }
    EXPECT_EQ(ctx().deviceBytesNow(), before);
    EXPECT_GE(ctx().deviceBytesPeak(), before + sum);
}

}  // namespace
}  // namespace gdpt
