// atomic_write.cpp — tmp + rename helper shared by the EXR and PNG writers.
#include "image/atomic_write.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>
#include <fstream>

#include "util/error.h"

namespace gdpt {

void writeFileAtomically(const std::string& path,
                         const std::function<void(const std::string& tmpPath)>& write) {
    const std::string tmpPath = path + ".tmp";
    try {
        write(tmpPath);
    } catch (const std::exception& e) {
        std::remove(tmpPath.c_str());
        throw Error(path + ": cannot write: " + e.what());
    } catch (...) {
        std::remove(tmpPath.c_str());
        throw Error(path + ": cannot write: unknown error");
    }
    if (std::rename(tmpPath.c_str(), path.c_str()) != 0) {
        const std::string reason = std::strerror(errno);
        std::remove(tmpPath.c_str());
        throw Error(path + ": cannot rename " + tmpPath + " into place: " + reason);
    }
}

void writeTextFileAtomically(const std::string& path, const std::string& text) {
    writeFileAtomically(path, [&](const std::string& tmp) {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        out << text;
        out.close();
        if (!out) throw Error("write failed");
    });
}

}  // namespace gdpt
