// test_shared_data.cpp — the rule of tests/support/shared_data.h: missing test data outside
// the repository skips a test on a developer's machine but fails it in CI.
#include <gtest/gtest-spi.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <optional>
#include <string>

#include "scoped_env.h"
#include "shared_data.h"

namespace gdpt {
namespace {

using test::ScopedEnv;

const char* const kMissing = "/nonexistent-gdpt-shared/scenes/none.gltf";

void requireMissing() {
    GDPT_REQUIRE_SHARED_DATA(std::string(kMissing));
}

TEST(SharedData, CiValues) {
    EXPECT_TRUE(test::isCiValue("true"));
    EXPECT_TRUE(test::isCiValue("1"));
    EXPECT_FALSE(test::isCiValue(nullptr));
    EXPECT_FALSE(test::isCiValue(""));
    EXPECT_FALSE(test::isCiValue("false"));
    EXPECT_FALSE(test::isCiValue("0"));
}

TEST(SharedData, MissingFileFailsInCi) {
    const ScopedEnv ci("CI", "true");
    EXPECT_FATAL_FAILURE(requireMissing(), "none.gltf: no such file");
}

TEST(SharedData, MissingFileMessageNamesIt) {
    EXPECT_EQ(test::missingSharedData(kMissing).rfind(kMissing, 0), 0u);
    EXPECT_EQ(test::missingSharedData(GDPT_SOURCE_DIR), "");
}

TEST(SharedData, EnvironmentOverridesTheDirectory) {
    const ScopedEnv dir("GDPT_SHARED_DIR", "/some/where");
    EXPECT_EQ(test::sharedDataPath("scenes/a.exr"), "/some/where/scenes/a.exr");
}

}  // namespace
}  // namespace gdpt
