// resource_limit.h — a soft resource limit of the process (getrlimit), for the checks of the
// limits that the drivers do not survive (file_size_limit.h, address_space_limit.h).
#pragma once

#include <sys/resource.h>

#include <cstdint>
#include <optional>

namespace gdpt {

// The soft limit of `resource` (RLIMIT_*) in its unit; nullopt when unlimited or unknown.
[[nodiscard]] inline std::optional<std::uint64_t> softResourceLimit(int resource) {
    rlimit r{};
    if (getrlimit(resource, &r) != 0 || r.rlim_cur == RLIM_INFINITY) return std::nullopt;
    return std::uint64_t(r.rlim_cur);
}

}  // namespace gdpt
