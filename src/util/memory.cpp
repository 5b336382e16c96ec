// memory.cpp — see memory.h.
#include "util/memory.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace gdpt {

namespace {

std::uint64_t machineMemory() {
    const long pages = sysconf(_SC_PHYS_PAGES), pageSize = sysconf(_SC_PAGE_SIZE);
    return pages > 0 && pageSize > 0 ? std::uint64_t(pages) * std::uint64_t(pageSize) : 0;
}

std::optional<std::uint64_t> processCgroupLimit() {
    std::ifstream in("/proc/self/cgroup");
    std::stringstream text;
    text << in.rdbuf();
    return cgroupMemoryLimit(text.str());
}

// A limit file's value; nullopt for "max" (v2), v1's "no limit" (2^63 - 1 rounded to pages) or
// anything unreadable.
std::optional<std::uint64_t> readLimit(const std::string& file) {
    std::ifstream in(file);
    std::string value;
    if (!(in >> value) || value.empty() || value == "max") return std::nullopt;
    char* end = nullptr;
    const unsigned long long bytes = std::strtoull(value.c_str(), &end, 10);
    if (*end != '\0' || bytes >= (1ull << 60)) return std::nullopt;
    return bytes;
}

bool listsController(const std::string& controllers, const std::string& name) {
    std::stringstream list(controllers);
    std::string item;
    while (std::getline(list, item, ','))
        if (item == name) return true;
    return false;
}

}  // namespace

std::optional<std::uint64_t> cgroupMemoryLimit(const std::string& procSelfCgroup, const std::string& root) {
    std::optional<std::uint64_t> lowest;
    std::stringstream lines(procSelfCgroup);
    std::string line;
    while (std::getline(lines, line)) {
        // "hierarchy-id:controllers:path"; v2's one line is "0::path".
        const std::size_t first = line.find(':'), second = line.find(':', first + 1);
        if (first == std::string::npos || second == std::string::npos) continue;
        const std::string controllers = line.substr(first + 1, second - first - 1);
        std::string dir, file;
        if (line.compare(0, first, "0") == 0 && controllers.empty()) {
            dir = root;
            file = "memory.max";
        } else if (listsController(controllers, "memory")) {
            dir = root + "/memory";
            file = "memory.limit_in_bytes";
        } else {
            continue;
        }
        // The group and every group above it (a container sees its own group as the root).
        std::string path = line.substr(second + 1);
        while (true) {
            const std::string at = dir + (path == "/" ? "" : path) + "/" + file;
            if (const auto limit = readLimit(at); limit && (!lowest || *limit < *lowest)) lowest = limit;
            if (path.empty() || path == "/") break;
            const std::size_t slash = path.rfind('/');
            path = slash == 0 || slash == std::string::npos ? "/" : path.substr(0, slash);
        }
    }
    return lowest;
}

namespace {

// physicalMemory()'s figure, and whether it is the control group's limit.
struct MemoryFigure {
    std::uint64_t bytes = 0;
    bool groupLimit = false;
};

MemoryFigure processMemory() {
    if (const char* test = std::getenv("GDPT_TEST_MEMORY_BYTES"); test && *test)
        return {std::strtoull(test, nullptr, 10), false};
    const std::uint64_t machine = machineMemory();
    const std::optional<std::uint64_t> group = processCgroupLimit();
    if (group && (*group < machine || machine == 0)) return {*group, true};
    return {machine, false};
}

}  // namespace

std::uint64_t physicalMemory() {
    return processMemory().bytes;
}

std::string availableMemoryText(std::uint64_t bytes) {
    const MemoryFigure memory = processMemory();
    if (memory.groupLimit && memory.bytes == bytes)
        return "the " + memoryText(bytes) + " memory limit of this process's control group";
    return "this machine's " + memoryText(bytes);
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
