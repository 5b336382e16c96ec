// temp_dir.h — a per-test scratch directory under the system temp dir, removed afterwards, with
// the helpers tests of written files need.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace gdpt::test {

// The whole content of a file ("" if it cannot be read).
inline std::string readText(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

// One path component from a test's suite and name: a parameterised test's names hold '/'
// ("Phases/SignalsCli", "Stops/0"), which would make nested directories that TearDown's
// removal of the innermost one leaves behind.
inline std::string testDirName(const ::testing::TestInfo& info) {
    std::string name = std::string(info.test_suite_name()) + "_" + info.name();
    std::replace(name.begin(), name.end(), '/', '_');
    return name;
}

// Each test gets an empty directory named after the process, suite and test.
class TempDirTest : public ::testing::Test {
protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = std::filesystem::temp_directory_path() /
               ("gdpt_" + std::to_string(::getpid()) + "_" + testDirName(*info));
        std::filesystem::remove_all(dir_);
        std::filesystem::create_directories(dir_);
    }
    void TearDown() override { std::filesystem::remove_all(dir_); }
    [[nodiscard]] std::string path(const std::string& name) const { return (dir_ / name).string(); }

    // The sorted names in `sub` (default: the test's directory), hidden files included.
    [[nodiscard]] std::vector<std::string> listing(const std::string& sub = "") const {
        std::vector<std::string> names;
        for (const auto& e : std::filesystem::directory_iterator(sub.empty() ? dir_ : dir_ / sub))
            names.push_back(e.path().filename().string());
        std::sort(names.begin(), names.end());
        return names;
    }
    // Temporary files of staged outputs (".<name>.gdpt-XXXXXX", util/output_files.h) left in
    // `sub`: a failed or interrupted write must leave none.
    [[nodiscard]] std::vector<std::string> temporaryFiles(const std::string& sub = "") const {
        std::vector<std::string> found;
        for (const std::string& name : listing(sub))
            if (name.find(".gdpt-") != std::string::npos) found.push_back(name);
        return found;
    }

    std::filesystem::path dir_;
};

}  // namespace gdpt::test
