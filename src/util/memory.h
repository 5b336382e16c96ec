// memory.h — the memory this process may use, and byte counts as people read them, for the
// checks that refuse work too large for the machine before it starts (the glTF loader, the
// image's buffers, the scene's tables, tgpt's windows).
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace gdpt {

// The memory this process may use, in bytes (0 if unknown): the machine's physical memory, or
// the memory limit of its control group where that is lower (a container's, a batch job's:
// cgroup v2 `memory.max` or v1 `memory.limit_in_bytes`), past which the kernel kills the process
// instead of failing an allocation. The tests of the refusals set it with the environment
// variable GDPT_TEST_MEMORY_BYTES (a byte count), as if the machine had that much.
[[nodiscard]] std::uint64_t physicalMemory();

// The lowest memory limit of the control group that `procSelfCgroup` (the text of
// /proc/self/cgroup) names and of every group above it, read under `root` (where the cgroup
// file systems are mounted); nullopt where none is set or none can be read.
[[nodiscard]] std::optional<std::uint64_t> cgroupMemoryLimit(const std::string& procSelfCgroup,
                                                             const std::string& root = "/sys/fs/cgroup");

// physicalMemory()'s `bytes` as the refusals name them: "this machine's 23.5 GiB", or "the 2.0
// GiB memory limit of this process's control group" where that is what they are.
[[nodiscard]] std::string availableMemoryText(std::uint64_t bytes);

// "1.5 GiB": bytes in gibibytes with one decimal.
[[nodiscard]] std::string gibibytes(std::uint64_t bytes);
// gibibytes from 1 GiB up, "37 MiB" below, "12 KiB" below 1 MiB, "512 bytes" below 1 KiB.
[[nodiscard]] std::string memoryText(std::uint64_t bytes);

}  // namespace gdpt
