// cli_runner.h — end-to-end CLI tests: run the gdpt binary (GDPT_BINARY, set by the build)
// and capture its exit code and output; a fixture with a private temporary directory.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "temp_dir.h"

namespace gdpt::test {

struct RunResult {
    int code = -1;
    std::string output;  // stdout + stderr
};

// The gdpt binary under test: GDPT_BINARY (this build's), or the file named by the
// environment variable GDPT_TEST_BINARY, so that the CLI tests can be run against another
// build (e.g. an older binary, to show that a regression test fails there).
inline std::string gdptBinary() {
    const char* other = std::getenv("GDPT_TEST_BINARY");
    return other && *other ? std::string(other) : std::string(GDPT_BINARY);
}

// Runs `command` through the shell, stderr with stdout.
inline RunResult runShell(const std::string& command) {
    const std::string cmd = command + " 2>&1";
    RunResult r;
    FILE* pipe = popen(cmd.c_str(), "r");
    if (!pipe) return r;
    char buf[4096];
    while (std::fgets(buf, sizeof buf, pipe)) r.output += buf;
    const int status = pclose(pipe);
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return r;
}

// Runs `gdpt <args>` through the shell; `env` ("NAME=value ..."), if given, is set for it.
inline RunResult runGdpt(const std::string& args, const std::string& env = "") {
    return runShell((env.empty() ? "" : "env " + env + " ") + gdptBinary() + " " + args);
}

}  // namespace gdpt::test
