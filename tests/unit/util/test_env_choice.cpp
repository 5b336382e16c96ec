// The per-device choices that an environment variable overrides (util/env_choice.h).
#include <gtest/gtest.h>
#include <stdlib.h>

#include <string>

#include "util/env_choice.h"
#include "util/error.h"

namespace gdpt {
namespace {

constexpr const char* kVar = "GDPT_TEST_ENV_CHOICE";

TEST(EnvChoice, UnsetEmptyOrAutoKeepTheDefault) {
    ::unsetenv(kVar);
    EXPECT_TRUE(envChoice(kVar, "nodes", "units", true));
    EXPECT_FALSE(envChoice(kVar, "nodes", "units", false));
    for (const char* v : {"", "auto"}) {
        ::setenv(kVar, v, 1);
        EXPECT_TRUE(envChoice(kVar, "nodes", "units", true)) << v;
        EXPECT_FALSE(envChoice(kVar, "nodes", "units", false)) << v;
    }
    ::unsetenv(kVar);
}

TEST(EnvChoice, EitherNameOverridesTheDefault) {
    ::setenv(kVar, "units", 1);
    EXPECT_TRUE(envChoice(kVar, "nodes", "units", false));
    ::setenv(kVar, "nodes", 1);
    EXPECT_FALSE(envChoice(kVar, "nodes", "units", true));
    ::unsetenv(kVar);
}

TEST(EnvChoice, AnotherValueIsRefusedWithTheAcceptedOnes) {
    ::setenv(kVar, "Units", 1);
    try {
        envChoice(kVar, "nodes", "units", true);
        ADD_FAILURE() << "no error";
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()), "GDPT_TEST_ENV_CHOICE='Units': expected auto, nodes or units");
    }
    ::unsetenv(kVar);
}

}  // namespace
}  // namespace gdpt
