// temp_dir.h — a per-test scratch directory under the system temp dir, removed afterwards.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

namespace gdpt::test {

class TempDirTest : public ::testing::Test {
protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = std::filesystem::temp_directory_path() / ("gdpt_image_" + std::to_string(::getpid()) + "_" +
                                                         info->test_suite_name() + "_" + info->name());
        std::filesystem::remove_all(dir_);
        std::filesystem::create_directories(dir_);
    }
    void TearDown() override { std::filesystem::remove_all(dir_); }
    [[nodiscard]] std::string path(const std::string& name) const { return (dir_ / name).string(); }
    // Temporary files of staged outputs (".<name>.gdpt-XXXXXX", util/output_files.h) left in
    // `sub` (default: the test's directory): a failed or interrupted write must leave none.
    [[nodiscard]] std::vector<std::string> temporaryFiles(const std::string& sub = "") const {
        std::vector<std::string> found;
        for (const auto& e : std::filesystem::directory_iterator(sub.empty() ? dir_ : dir_ / sub))
            if (e.path().filename().string().find(".gdpt-") != std::string::npos)
                found.push_back(e.path().filename().string());
        return found;
    }

    std::filesystem::path dir_;
};

}  // namespace gdpt::test
