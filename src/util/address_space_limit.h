// address_space_limit.h — the process's address-space limit (RLIMIT_AS, `ulimit -v`), as batch
// systems and shared machines set it. Lavapipe (22.3 and 25) does not survive every failed
// allocation of its own: one inside vkCreateDevice (its threads' stacks) or a kernel's compilation
// kills the process with SIGSEGV. Under a limit, therefore: glibc gets one malloc arena (each
// reserves 64 MiB of address space, and every thread that allocates may add one; main.cpp); a
// CPU device is refused before it starts unless the limit leaves room for its threads and a
// compilation, and again once it has started (vk/context.cpp); its kernels are compiled one at a
// time (vk/kernel.cpp); and no buffer may take the room of the next compilation (vk/buffer.cpp).
// Each refusal names the limit and how far to raise it.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace gdpt {

// The soft address-space limit in bytes; nullopt when unlimited.
[[nodiscard]] std::optional<std::uint64_t> addressSpaceLimit();

// The address space this process holds, in bytes: what it has mapped (VmSize of
// /proc/self/status) less what malloc keeps free for reuse; 0 if unknown.
[[nodiscard]] std::uint64_t addressSpaceInUse();

// Under an address-space limit, and unless MALLOC_ARENA_MAX says otherwise, limits glibc to one
// malloc arena. Call before any thread starts. Returns whether it did.
bool fitMallocToAddressSpaceLimit();

// What a CPU device needs free beyond what it holds: the compilation of a kernel. G-PT's, gdpt's
// largest, mapped 83 MiB at its peak beyond what the process held before it (28 MiB of it kept
// with the pipeline) on lavapipe 22.3 (bench/RESULTS.md, "Lavapipe under an address-space
// limit"); half again as much for margin.
constexpr std::uint64_t kCpuDeviceHeadroomBytes = std::uint64_t(128) << 20;

// The threads a CPU device starts: lavapipe's, LP_NUM_THREADS or one per CPU, at most 32.
[[nodiscard]] unsigned cpuDeviceThreads();

// What starting a CPU device maps: 21-45 MiB and 16 MiB per thread on lavapipe 22.3 and 25.0
// (its stacks; bench/RESULTS.md), estimated as 48 MiB and 16 MiB per thread.
[[nodiscard]] std::uint64_t cpuDeviceStartBytes(unsigned threads);

// Why a device cannot go on under the address-space limit, or nullopt when it can: the device is
// a CPU device, a limit is set, and beside `inUseBytes` (what the process holds and what it is
// about to take) the limit leaves less than `headroomBytes`.
[[nodiscard]] std::optional<std::string> addressSpaceLimitProblem(const std::string& device, bool cpuDevice,
                                                                  std::optional<std::uint64_t> limit,
                                                                  std::uint64_t inUseBytes,
                                                                  std::uint64_t headroomBytes);

// What to add to the error of a driver that did not start: the address-space limit and the way
// out when one is set (a driver that cannot map its libraries and memory lists no device), else "".
[[nodiscard]] std::string driverStartHint(std::optional<std::uint64_t> limit);

// The error for a failed host allocation: the address-space limit and the way out when one is
// set, or the advice to make the work smaller.
[[nodiscard]] std::string hostAllocationFailure(std::optional<std::uint64_t> limit);

}  // namespace gdpt
