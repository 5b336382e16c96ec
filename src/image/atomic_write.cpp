// atomic_write.cpp — one staged file (util/output_files.h) written by a callback.
#include "image/atomic_write.h"

#include <exception>

#include "util/error.h"
#include "util/output_files.h"

namespace gdpt {

void writeStaged(const StagedFile& file, const std::function<void(const std::string& tmpPath)>& write) {
    try {
        write(file.tmpPath());
    } catch (const std::exception& e) {
        throw Error(file.path() + ": cannot write: " + e.what());
    } catch (...) {
        throw Error(file.path() + ": cannot write: unknown error");
    }
}

void writeStagedText(const StagedFile& file, const std::string& text) {
    writeStaged(file, [&](const std::string& tmp) { writeBytes(tmp, text.data(), text.size()); });
}

void writeFileAtomically(const std::string& path,
                         const std::function<void(const std::string& tmpPath)>& write) {
    StagedFile file(path);
    writeStaged(file, write);
    file.commit();
}

void writeTextFileAtomically(const std::string& path, const std::string& text) {
    writeFileAtomically(path, [&](const std::string& tmp) { writeBytes(tmp, text.data(), text.size()); });
}

}  // namespace gdpt
