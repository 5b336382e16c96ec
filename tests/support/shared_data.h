// shared_data.h — test data kept outside the repository: ../shared/scenes holds glTF scenes
// with reference images rendered by an independent path tracer, so that no gdpt code or test
// shaped them. A test that needs such a file starts with GDPT_REQUIRE_SHARED_DATA(path):
// where the file is missing the test is skipped on a developer's machine, but fails in CI
// (environment variable CI=true or CI=1, as CI runs .ci/run), so that CI cannot pass while
// silently skipping the independent checks.
//
// GDPT_SHARED_DIR (compile definition, <source>/../shared) is the default location; the
// environment variable of the same name overrides it at run time.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

namespace gdpt::test {

// Whether `ci` (the value of the environment variable CI, null if unset) marks a CI run.
inline bool isCiValue(const char* ci) {
    if (ci == nullptr) return false;
    const std::string v(ci);
    return v == "true" || v == "1";
}

inline bool runningInCi() {
    return isCiValue(std::getenv("CI"));
}

// The shared data directory: $GDPT_SHARED_DIR if set and not empty, else the compiled-in one.
inline std::string sharedDataDir() {
    const char* env = std::getenv("GDPT_SHARED_DIR");
    if (env != nullptr && *env != '\0') return env;
#ifdef GDPT_SHARED_DIR
    return GDPT_SHARED_DIR;
#else
    return "../shared";
#endif
}

// `relative` (e.g. "scenes/cbox/cbox.gltf") inside the shared data directory.
inline std::string sharedDataPath(const std::string& relative) {
    return sharedDataDir() + "/" + relative;
}

// Empty if `path` exists; else the message a skip or failure reports.
inline std::string missingSharedData(const std::string& path) {
    std::error_code ec;
    if (std::filesystem::exists(path, ec)) return {};
    return path + ": no such file (test data outside the repository, see tests/support/shared_data.h)";
}

}  // namespace gdpt::test

// Returns from the calling test (or void helper) unless `path` exists: a fatal failure in CI,
// a skip elsewhere.
#define GDPT_REQUIRE_SHARED_DATA(path)                                               \
    do {                                                                             \
        const std::string gdptMissingShared = ::gdpt::test::missingSharedData(path); \
        if (!gdptMissingShared.empty()) {                                            \
            if (::gdpt::test::runningInCi())                                         \
                FAIL() << gdptMissingShared << " (in CI a test fails without it)";   \
            GTEST_SKIP() << gdptMissingShared;                                       \
        }                                                                            \
    } while (false)
