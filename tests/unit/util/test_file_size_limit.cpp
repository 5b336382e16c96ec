// The file-size limit and the memory files it also caps (util/file_size_limit.h).
#include <gtest/gtest.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cstdint>
#include <optional>
#include <string>

#include "util/file_size_limit.h"

namespace gdpt {
namespace {

TEST(FileSizeLimit, ReadsTheSoftLimitInBytes) {
    rlimit original{};
    ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &original), 0);
    rlimit lowered = original;
    lowered.rlim_cur = 8192;
    ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &lowered), 0);
    const std::optional<std::uint64_t> limit = fileSizeLimit();
    ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &original), 0);  // before any assertion can return
    ASSERT_TRUE(limit.has_value());
    EXPECT_EQ(*limit, 8192u);
    if (original.rlim_cur == RLIM_INFINITY) {
        EXPECT_FALSE(fileSizeLimit().has_value());
    }
}

TEST(FileSizeLimit, CountsThisProcesssMemoryFiles) {
    const std::size_t before = memoryFileCount();
    const int fd = memfd_create("gdpt test", MFD_CLOEXEC);
    ASSERT_GE(fd, 0);
    const std::size_t during = memoryFileCount();
    close(fd);
    EXPECT_EQ(during, before + 1);
    EXPECT_EQ(memoryFileCount(), before);
}

TEST(FileSizeLimit, RefusesOnlyACpuDeviceWithMemoryFilesUnderALimitBelowItsHeap) {
    constexpr std::uint64_t kHeap = 1ull << 30;
    // The case that crashed: every condition holds.
    const std::optional<std::string> problem = memoryFileLimitProblem("llvmpipe", true, 1, 2048, kHeap);
    ASSERT_TRUE(problem.has_value());
    EXPECT_NE(problem->find("2 KiB"), std::string::npos) << *problem;
    EXPECT_NE(problem->find("'llvmpipe'"), std::string::npos) << *problem;
    EXPECT_NE(problem->find("1.0 GiB"), std::string::npos) << *problem;
    EXPECT_NE(problem->find("ulimit -f unlimited"), std::string::npos) << *problem;
    EXPECT_NE(memoryFileLimitProblem("llvmpipe", true, 1, 3u << 20, kHeap)->find("3 MiB"), std::string::npos);
    // Any condition missing: no refusal.
    EXPECT_FALSE(memoryFileLimitProblem("gpu", false, 1, 2048, kHeap));              // a GPU's memory
    EXPECT_FALSE(memoryFileLimitProblem("llvmpipe", true, 0, 2048, kHeap));          // Mesa 22.3: no memfd
    EXPECT_FALSE(memoryFileLimitProblem("llvmpipe", true, 1, std::nullopt, kHeap));  // unlimited
    EXPECT_FALSE(memoryFileLimitProblem("llvmpipe", true, 1, kHeap, kHeap));         // above the heap
}

}  // namespace
}  // namespace gdpt
