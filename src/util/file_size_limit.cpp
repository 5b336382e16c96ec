// file_size_limit.cpp — see file_size_limit.h.
#include "util/file_size_limit.h"

#include <filesystem>
#include <system_error>

#include "util/memory.h"
#include "util/resource_limit.h"

namespace gdpt {

std::optional<std::uint64_t> fileSizeLimit() {
    return softResourceLimit(RLIMIT_FSIZE);
}

std::size_t memoryFileCount() {
    namespace fs = std::filesystem;
    std::error_code ec;
    std::size_t count = 0;
    for (fs::directory_iterator it("/proc/self/fd", ec), end; !ec && it != end; it.increment(ec)) {
        std::error_code linkError;
        const fs::path target = fs::read_symlink(it->path(), linkError);
        if (!linkError && target.native().rfind("/memfd:", 0) == 0) ++count;
    }
    return count;
}

std::optional<std::string> memoryFileLimitProblem(const std::string& device, bool cpuDevice,
                                                  std::size_t memoryFilesAdded,
                                                  std::optional<std::uint64_t> limit,
                                                  std::uint64_t heapBytes) {
    if (!cpuDevice || memoryFilesAdded == 0 || !limit || *limit >= heapBytes) return std::nullopt;
    return "the file-size limit (ulimit -f) of " + memoryText(*limit) + " also caps the memory of device '" +
           device +
           "', which keeps it in a memory file, and the driver would be killed (SIGBUS) past it; raise the "
           "limit to at least the device's " +
           memoryText(heapBytes) + " (ulimit -f unlimited)";
}

}  // namespace gdpt
