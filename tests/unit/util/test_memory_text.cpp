// Byte counts as people read them (util/memory.h): no size prints as "0 MiB".
#include <gtest/gtest.h>

#include "util/memory.h"

namespace gdpt {
namespace {

TEST(MemoryText, EachSizeInItsOwnUnit) {
    EXPECT_EQ(memoryText(0), "0 bytes");
    EXPECT_EQ(memoryText(512), "512 bytes");
    EXPECT_EQ(memoryText(2048), "2 KiB");
    EXPECT_EQ(memoryText(3ull << 20), "3 MiB");
    EXPECT_EQ(memoryText(3ull << 29), "1.5 GiB");
}

}  // namespace
}  // namespace gdpt
