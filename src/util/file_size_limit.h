// file_size_limit.h — the process's file-size limit (RLIMIT_FSIZE, `ulimit -f`) and the memory
// files it also caps. Lavapipe of Mesa 25 (not 22.3) keeps all device memory in one memory file
// (memfd) that it grows with ftruncate: past the limit the growth fails, the driver maps pages
// beyond the file's end anyway, and the first touch kills the process with SIGBUS. The Vulkan
// context (vk/context.cpp) refuses such a device under such a limit before any allocation, with
// the limit and the way out, instead of crashing mid-render.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

namespace gdpt {

// The soft file-size limit in bytes; nullopt when unlimited.
[[nodiscard]] std::optional<std::uint64_t> fileSizeLimit();

// The memory files (memfd) among this process's open file descriptors.
[[nodiscard]] std::size_t memoryFileCount();

// Why a device cannot run under the file-size limit, or nullopt when it can: the device is a CPU
// device that opened memory files when it was created (memoryFilesAdded > 0), a limit is set, and
// the limit is below the device's largest heap (`heapBytes`, what its allocations may reach).
[[nodiscard]] std::optional<std::string> memoryFileLimitProblem(const std::string& device, bool cpuDevice,
                                                                std::size_t memoryFilesAdded,
                                                                std::optional<std::uint64_t> limit,
                                                                std::uint64_t heapBytes);

}  // namespace gdpt
