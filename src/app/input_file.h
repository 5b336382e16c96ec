// input_file.h — the CLI11 check for input files (scenes, EXR inputs, checkpoints,
// references). CLI::ExistingFile reports a missing file as a usage error (exit 2); a missing
// or unreadable input is an input error instead (exit 1, one line naming the file), so this
// check throws gdpt::Error, which passes out of CLI::App::parse to main().
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace gdpt {

// Empty if `path` names something readable that is not a directory; else the reason, e.g. "no such file or
// directory" (from errno).
std::string inputFileProblem(const std::string& path);

class InputFileValidator : public CLI::Validator {
public:
    InputFileValidator();
};

// Use as `->check(gdpt::InputFile)`: throws gdpt::Error("PATH: REASON").
inline const InputFileValidator InputFile;

}  // namespace gdpt
