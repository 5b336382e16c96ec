// The memory limit of the process's control group (util/memory.h), read from cgroup trees laid
// out in a temporary directory as the kernel lays them out under /sys/fs/cgroup.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

#include "scoped_env.h"
#include "util/memory.h"

namespace gdpt {
namespace {

namespace fs = std::filesystem;

class CgroupMemory : public ::testing::Test {
protected:
    void SetUp() override {
        root_ = fs::temp_directory_path() / ("gdpt-cgroup-" + std::to_string(getpid()) + "-" +
                                             ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::remove_all(root_);
    }
    void TearDown() override { fs::remove_all(root_); }
    // Writes `value` to root/relative, creating its folders.
    void write(const std::string& relative, const std::string& value) {
        const fs::path file = root_ / relative;
        fs::create_directories(file.parent_path());
        std::ofstream(file) << value << "\n";
    }
    [[nodiscard]] std::string root() const { return root_.string(); }

private:
    fs::path root_;
};

TEST_F(CgroupMemory, Version2TakesTheLowestLimitOfTheGroupAndTheGroupsAboveIt) {
    write("memory.max", "max");  // the root: no limit
    write("batch/memory.max", "4294967296");
    write("batch/job7/memory.max", "8589934592");  // a child may not raise its parent's limit
    write("batch/job7/step0/memory.max", "max");
    EXPECT_EQ(cgroupMemoryLimit("0::/batch/job7/step0\n", root()),
              std::optional<std::uint64_t>(4294967296ull));
    write("batch/job7/step0/memory.max", "1073741824");
    EXPECT_EQ(cgroupMemoryLimit("0::/batch/job7/step0\n", root()),
              std::optional<std::uint64_t>(1073741824ull));
}

TEST_F(CgroupMemory, Version1ReadsTheMemoryControllersHierarchyOnly) {
    const std::string self = "12:pids:/jobs/a\n4:cpu,cpuacct:/jobs/a\n3:memory:/jobs/a\n0::/\n";
    write("memory/memory.limit_in_bytes", "9223372036854771712");  // v1's "no limit"
    EXPECT_EQ(cgroupMemoryLimit(self, root()), std::nullopt);
    write("memory/jobs/a/memory.limit_in_bytes", "2147483648");
    write("pids/jobs/a/memory.limit_in_bytes", "1024");  // not the memory controller's
    EXPECT_EQ(cgroupMemoryLimit(self, root()), std::optional<std::uint64_t>(2147483648ull));
    // A controller list that names memory among others.
    EXPECT_EQ(cgroupMemoryLimit("3:memory,hugetlb:/jobs/a\n", root()),
              std::optional<std::uint64_t>(2147483648ull));
}

// A container often sees its own group as the root of the tree, while /proc/self/cgroup names the
// host's path: the folders of that path are missing, and the root's limit is the one.
TEST_F(CgroupMemory, AContainersLimitAtTheRootIsFound) {
    write("memory.max", "536870912");
    EXPECT_EQ(cgroupMemoryLimit("0::/system.slice/docker-1234.scope\n", root()),
              std::optional<std::uint64_t>(536870912ull));
    write("memory/memory.limit_in_bytes", "268435456");
    EXPECT_EQ(cgroupMemoryLimit("5:memory:/docker/1234\n", root()),
              std::optional<std::uint64_t>(268435456ull));
}

TEST_F(CgroupMemory, NoLimitWhereNothingIsSetOrReadable) {
    EXPECT_EQ(cgroupMemoryLimit("", root()), std::nullopt);
    EXPECT_EQ(cgroupMemoryLimit("0::/a/b\n", root()), std::nullopt);  // no files at all
    write("a/memory.max", "not a number");
    EXPECT_EQ(cgroupMemoryLimit("0::/a\n", root()), std::nullopt);
    EXPECT_EQ(cgroupMemoryLimit("garbage without colons\n", root()), std::nullopt);
}

TEST(AvailableMemoryText, NamesTheMachineUnlessTheGroupsLimitIsTheFigure) {
    // GDPT_TEST_MEMORY_BYTES stands in for the machine's memory: always "this machine's".
    {
        test::ScopedEnv memory("GDPT_TEST_MEMORY_BYTES", "2147483648");
        EXPECT_EQ(physicalMemory(), 2147483648ull);
        EXPECT_EQ(availableMemoryText(2147483648ull), "this machine's 2.0 GiB");
    }
    test::ScopedEnv unset("GDPT_TEST_MEMORY_BYTES", nullptr);
    EXPECT_GT(physicalMemory(), 0u);
}

}  // namespace
}  // namespace gdpt
