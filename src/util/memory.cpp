// memory.cpp — see memory.h.
#include "util/memory.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>

namespace gdpt {

std::uint64_t physicalMemory() {
    if (const char* test = std::getenv("GDPT_TEST_MEMORY_BYTES"); test && *test)
        return std::strtoull(test, nullptr, 10);
    const long pages = sysconf(_SC_PHYS_PAGES), pageSize = sysconf(_SC_PAGE_SIZE);
    return pages > 0 && pageSize > 0 ? std::uint64_t(pages) * std::uint64_t(pageSize) : 0;
}

std::string gibibytes(std::uint64_t bytes) {
    char text[32];
    std::snprintf(text, sizeof text, "%.1f GiB", double(bytes) / double(1ull << 30));
    return text;
}

std::string memoryText(std::uint64_t bytes) {
    if (bytes >= (1ull << 30)) return gibibytes(bytes);
    char text[32];
    if (bytes >= (1ull << 20))
        std::snprintf(text, sizeof text, "%.0f MiB", double(bytes) / double(1ull << 20));
    else if (bytes >= (1ull << 10))
        std::snprintf(text, sizeof text, "%.0f KiB", double(bytes) / double(1ull << 10));
    else
        std::snprintf(text, sizeof text, "%llu bytes", static_cast<unsigned long long>(bytes));
    return text;
}

}  // namespace gdpt
