// input_file.cpp — see input_file.h.
#include "app/input_file.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstring>

#include "util/error.h"

namespace gdpt {
namespace {

std::string errnoText(int err) {
    std::string text = std::strerror(err);
    if (!text.empty()) text[0] = static_cast<char>(std::tolower(static_cast<unsigned char>(text[0])));
    return text;
}

}  // namespace

std::string inputFileProblem(const std::string& path) {
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) return errnoText(errno);
    if (S_ISDIR(st.st_mode)) return errnoText(EISDIR);
    if (::access(path.c_str(), R_OK) != 0) return errnoText(errno);
    return {};
}

InputFileValidator::InputFileValidator() : CLI::Validator("FILE") {
    func_ = [](std::string& path) -> std::string {
        const std::string problem = inputFileProblem(path);
        if (!problem.empty()) throw Error(path + ": " + problem);
        return {};
    };
}

}  // namespace gdpt
