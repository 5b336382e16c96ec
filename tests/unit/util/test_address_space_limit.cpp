// The address-space limit and what it leaves a CPU device (util/address_space_limit.h).
#include <gtest/gtest.h>
#include <sys/mman.h>
#include <sys/resource.h>

#include <cstdint>
#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

#include "scoped_env.h"
#include "util/address_space_limit.h"

namespace gdpt {
namespace {

constexpr std::uint64_t kMiB = std::uint64_t(1) << 20;

// A soft limit far above anything this process maps (so that nothing here can fail by it, an
// AddressSanitizer's shadow included), restored when the scope ends.
class FiniteLimit {
public:
    FiniteLimit() {
        getrlimit(RLIMIT_AS, &original_);
        rlimit lowered = original_;
        lowered.rlim_cur = kBytes;
        ok_ = (original_.rlim_max == RLIM_INFINITY || original_.rlim_max >= kBytes) &&
              setrlimit(RLIMIT_AS, &lowered) == 0;
    }
    ~FiniteLimit() { setrlimit(RLIMIT_AS, &original_); }
    FiniteLimit(const FiniteLimit&) = delete;
    FiniteLimit& operator=(const FiniteLimit&) = delete;
    [[nodiscard]] bool ok() const { return ok_; }
    static constexpr std::uint64_t kBytes = std::uint64_t(1) << 62;

private:
    rlimit original_{};
    bool ok_ = false;
};

TEST(AddressSpaceLimit, ReadsTheSoftLimitInBytes) {
    rlimit original{};
    ASSERT_EQ(getrlimit(RLIMIT_AS, &original), 0);
    std::optional<std::uint64_t> limit;
    {
        FiniteLimit finite;
        ASSERT_TRUE(finite.ok());
        limit = addressSpaceLimit();
    }
    ASSERT_TRUE(limit.has_value());
    EXPECT_EQ(*limit, FiniteLimit::kBytes);
    if (original.rlim_cur == RLIM_INFINITY) {
        EXPECT_FALSE(addressSpaceLimit().has_value());
    }
}

TEST(AddressSpaceLimit, InUseCountsANewMapping) {
    constexpr std::size_t kBytes = 256 * kMiB;
    const std::uint64_t before = addressSpaceInUse();
    void* block = mmap(nullptr, kBytes, PROT_NONE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
    ASSERT_NE(block, MAP_FAILED);
    const std::uint64_t during = addressSpaceInUse();
    munmap(block, kBytes);
    EXPECT_GT(before, 0u);
    // Within 16 MiB: the test runner's own threads may map or unmap a little meanwhile.
    EXPECT_NEAR(double(during - before), double(kBytes), double(16 * kMiB));
    EXPECT_NEAR(double(addressSpaceInUse()), double(before), double(16 * kMiB));
}

#if !defined(__SANITIZE_ADDRESS__)  // the sanitizer's allocator is not glibc's malloc
// Memory freed to malloc stays mapped, but a kernel's compilation would reuse it: not in use.
TEST(AddressSpaceLimit, InUseLeavesOutWhatMallocHoldsFree) {
    std::vector<void*> blocks;
    for (int i = 0; i < 64 * 1024; ++i) blocks.push_back(std::malloc(1024));  // 64 MiB on the heap
    const std::uint64_t allocated = addressSpaceInUse();
    // All but the last, so that the heap's top stays and nothing is returned to the system.
    for (std::size_t i = 0; i + 1 < blocks.size(); ++i) std::free(blocks[i]);
    const std::uint64_t freed = addressSpaceInUse();
    std::free(blocks.back());
    EXPECT_LT(freed + 48 * kMiB, allocated) << "allocated " << allocated << ", freed " << freed;
}
#endif

TEST(AddressSpaceLimit, RefusesOnlyACpuDeviceThatTheLimitLeavesTooLittle) {
    const std::uint64_t limit = 500 * kMiB;
    const std::uint64_t headroom = 128 * kMiB;
    // The case that crashed: a CPU device, 400 MiB in use, 100 left.
    const std::optional<std::string> problem =
        addressSpaceLimitProblem("llvmpipe", true, limit, 400 * kMiB, headroom);
    ASSERT_TRUE(problem.has_value());
    EXPECT_NE(problem->find("ulimit -v"), std::string::npos) << *problem;
    EXPECT_NE(problem->find("500 MiB"), std::string::npos) << *problem;
    EXPECT_NE(problem->find("'llvmpipe'"), std::string::npos) << *problem;
    EXPECT_NE(problem->find("above 528 MiB"), std::string::npos) << *problem;
    // Past 1 GiB the figure stays in whole MiB, rounded up (not "1.1 GiB").
    const std::optional<std::string> large =
        addressSpaceLimitProblem("llvmpipe", true, 1024 * kMiB, 1000 * kMiB + 1, headroom);
    ASSERT_TRUE(large.has_value());
    EXPECT_NE(large->find("above 1129 MiB"), std::string::npos) << *large;
    EXPECT_TRUE(addressSpaceLimitProblem("llvmpipe", true, limit, 600 * kMiB, headroom));  // beyond the limit
    EXPECT_TRUE(addressSpaceLimitProblem("llvmpipe", true, limit, limit - headroom + 1, headroom));
    // Any condition missing: no refusal.
    EXPECT_FALSE(addressSpaceLimitProblem("gpu", false, limit, 400 * kMiB, headroom));  // a GPU's memory
    EXPECT_FALSE(
        addressSpaceLimitProblem("llvmpipe", true, std::nullopt, 400 * kMiB, headroom));  // unlimited
    EXPECT_FALSE(
        addressSpaceLimitProblem("llvmpipe", true, limit, limit - headroom, headroom));  // just enough
}

TEST(AddressSpaceLimit, ADeviceStartCountsItsThreads) {
    EXPECT_EQ(cpuDeviceStartBytes(0), 48 * kMiB);
    EXPECT_EQ(cpuDeviceStartBytes(2), 80 * kMiB);
    {
        test::ScopedEnv threads("LP_NUM_THREADS", "3");
        EXPECT_EQ(cpuDeviceThreads(), 3u);
    }
    {
        test::ScopedEnv threads("LP_NUM_THREADS", "0");  // lavapipe without threads
        EXPECT_EQ(cpuDeviceThreads(), 0u);
    }
    {
        test::ScopedEnv threads("LP_NUM_THREADS", "500");  // lavapipe starts at most 32
        EXPECT_EQ(cpuDeviceThreads(), 32u);
    }
    test::ScopedEnv unset("LP_NUM_THREADS", nullptr);
    EXPECT_GE(cpuDeviceThreads(), 1u);
    EXPECT_LE(cpuDeviceThreads(), 32u);
}

TEST(AddressSpaceLimit, MallocGetsOneArenaOnlyUnderALimit) {
    test::ScopedEnv unset("MALLOC_ARENA_MAX", nullptr);
    rlimit current{};
    ASSERT_EQ(getrlimit(RLIMIT_AS, &current), 0);
    if (current.rlim_cur == RLIM_INFINITY) {
        EXPECT_FALSE(fitMallocToAddressSpaceLimit());
    }
    FiniteLimit finite;
    ASSERT_TRUE(finite.ok());
    {
        test::ScopedEnv user("MALLOC_ARENA_MAX", "4");  // the user's choice stands
        EXPECT_FALSE(fitMallocToAddressSpaceLimit());
    }
#if !defined(__SANITIZE_ADDRESS__)  // the sanitizer's allocator has no arenas: its mallopt does nothing
    EXPECT_TRUE(fitMallocToAddressSpaceLimit());
#endif
}

TEST(AddressSpaceLimit, ErrorsNameTheLimitWhereOneIsSet) {
    EXPECT_EQ(driverStartHint(std::nullopt), "");
    EXPECT_NE(driverStartHint(300 * kMiB).find("(ulimit -v) of 300 MiB"), std::string::npos);
    EXPECT_EQ(hostAllocationFailure(std::nullopt).find("ulimit"), std::string::npos);
    EXPECT_NE(hostAllocationFailure(std::nullopt).find("smaller image"), std::string::npos);
    EXPECT_NE(hostAllocationFailure(300 * kMiB).find("(ulimit -v) of 300 MiB"), std::string::npos);
}

}  // namespace
}  // namespace gdpt
