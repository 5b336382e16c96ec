// input_file.h — the CLI11 check for input files (scenes, EXR inputs, checkpoints,
// references). CLI::ExistingFile reports a missing file as a usage error (exit 2); a missing
// or unreadable input is an input error instead (exit 1, one line naming the file), so this
// check throws gdpt::Error, which passes out of CLI::App::parse to main().
#pragma once

#include <sys/stat.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <string>

#include "util/error.h"

namespace gdpt {

// Empty if `path` names something readable that is not a directory; else the reason, e.g.
// "no such file or directory" (errno's text, lower case).
inline std::string inputFileProblem(const std::string& path) {
    auto text = [](int err) {
        std::string s = std::strerror(err);
        if (!s.empty()) s[0] = static_cast<char>(std::tolower(static_cast<unsigned char>(s[0])));
        return s;
    };
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) return text(errno);
    if (S_ISDIR(st.st_mode)) return text(EISDIR);
    if (::access(path.c_str(), R_OK) != 0) return text(errno);
    return {};
}

class InputFileValidator : public CLI::Validator {
public:
    InputFileValidator() : CLI::Validator("FILE") {
        func_ = [](std::string& path) -> std::string {
            const std::string problem = inputFileProblem(path);
            if (!problem.empty()) throw Error(path + ": " + problem);
            return {};
        };
    }
};

// Use as `->check(gdpt::InputFile)`: throws gdpt::Error("PATH: REASON").
inline const InputFileValidator InputFile;

}  // namespace gdpt
