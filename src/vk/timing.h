// timing.h — GPU timestamps around named dispatches (what --profile prints). A GpuTimer
// belongs to one command stream: reset() at the start of recording, begin()/end() around
// each dispatch, collect() after the fence has signalled. Totals accumulate per name.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "vk/handle.h"

namespace gdpt::vk {

class Context;

struct KernelTime {
    std::uint64_t count = 0;  // dispatches timed
    double totalMs = 0.0;     // summed GPU time
};

class GpuTimer {
public:
    GpuTimer(const Context& ctx, std::uint32_t maxScopesPerSubmit = 128);
    [[nodiscard]] bool enabled() const { return enabled_; }

    void reset(VkCommandBuffer cmd);
    void begin(VkCommandBuffer cmd, const std::string& name);
    void end(VkCommandBuffer cmd);
    // Reads back the scopes recorded since reset() (the work must be complete).
    void collect();

    [[nodiscard]] const std::map<std::string, KernelTime>& totals() const { return totals_; }
    [[nodiscard]] double totalMs() const;

private:
    const Context& ctx_;
    bool enabled_ = false;
    std::uint32_t capacity_ = 0;
    double periodNs_ = 1.0;
    std::uint64_t validMask_ = ~0ull;
    Handle<VkQueryPool> pool_;
    std::vector<std::string> names_;  // one per begun scope since reset()
    std::uint32_t used_ = 0;          // queries written since reset()
    std::map<std::string, KernelTime> totals_;
};

}  // namespace gdpt::vk
