// address_space_limit.cpp — see address_space_limit.h.
#include "util/address_space_limit.h"

#include <malloc.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <thread>

#include "util/memory.h"
#include "util/resource_limit.h"

namespace gdpt {

std::optional<std::uint64_t> addressSpaceLimit() {
    return softResourceLimit(RLIMIT_AS);
}

std::uint64_t addressSpaceInUse() {
    std::ifstream status("/proc/self/status");
    std::string line;
    std::uint64_t mapped = 0;
    while (std::getline(status, line)) {
        if (line.rfind("VmSize:", 0) != 0) continue;
        std::istringstream fields(line.substr(7));
        std::uint64_t kib = 0;
        if (fields >> kib) mapped = kib * 1024;
        break;
    }
    // Memory that malloc holds free is mapped, but the next allocation (a kernel's compilation)
    // reuses it.
    const std::uint64_t heldFree = mallinfo2().fordblks;
    return mapped > heldFree ? mapped - heldFree : 0;
}

bool fitMallocToAddressSpaceLimit() {
    if (!addressSpaceLimit() || std::getenv("MALLOC_ARENA_MAX")) return false;
    return mallopt(M_ARENA_MAX, 1) == 1;
}

unsigned cpuDeviceThreads() {
    constexpr unsigned kMaxThreads = 32;  // LP_MAX_THREADS
    if (const char* env = std::getenv("LP_NUM_THREADS")) {
        char* end = nullptr;
        const unsigned long n = std::strtoul(env, &end, 10);
        if (end != env) return unsigned(std::min<unsigned long>(n, kMaxThreads));
    }
    return std::min(std::max(std::thread::hardware_concurrency(), 1u), kMaxThreads);
}

std::uint64_t cpuDeviceStartBytes(unsigned threads) {
    return (std::uint64_t(48) + 16 * std::uint64_t(threads)) << 20;
}

std::optional<std::string> addressSpaceLimitProblem(const std::string& device, bool cpuDevice,
                                                    std::optional<std::uint64_t> limit,
                                                    std::uint64_t inUseBytes, std::uint64_t headroomBytes) {
    if (!cpuDevice || !limit || (*limit > inUseBytes && *limit - inUseBytes >= headroomBytes))
        return std::nullopt;
    // The figure to raise the limit above, in whole MiB rounded up (memoryText's "1.0 GiB" could
    // read lower than it).
    const std::string needed = std::to_string((inUseBytes + headroomBytes + (1u << 20) - 1) >> 20) + " MiB";
    return "the address-space limit (ulimit -v) of " + memoryText(*limit) + " would leave less than the " +
           memoryText(headroomBytes) + " that compiling a kernel takes beside the " + memoryText(inUseBytes) +
           " that gdpt and device '" + device + "' hold or are about to take, and the device's driver " +
           "crashes (SIGSEGV) where an allocation of its own fails; raise the limit above " + needed +
           " (ulimit -v unlimited)";
}

std::string driverStartHint(std::optional<std::uint64_t> limit) {
    if (!limit) return "";
    return "; under the address-space limit (ulimit -v) of " + memoryText(*limit) +
           " the driver may not have been able to start: raise it (ulimit -v unlimited)";
}

std::string hostAllocationFailure(std::optional<std::uint64_t> limit) {
    if (!limit) return "out of memory (a host allocation failed); try a smaller image or scene";
    return "out of memory (a host allocation failed) under the address-space limit (ulimit -v) of " +
           memoryText(*limit) + "; raise it (ulimit -v unlimited) or try a smaller image or scene";
}

}  // namespace gdpt
