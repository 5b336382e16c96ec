// commands.h — a command buffer with its pool and fence: record, submit, wait. Waiting
// uses a fence with a timeout (never a spin), and a failure names what was running
// ("pt batch 12 (samples 48..51)") so a device-lost report says how to reproduce it.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <functional>
#include <string>

#include "vk/handle.h"

namespace gdpt::vk {

class Context;

class CommandStream {
public:
    CommandStream(const Context& ctx, std::string what);
    ~CommandStream();
    CommandStream(const CommandStream&) = delete;
    CommandStream& operator=(const CommandStream&) = delete;

    // Resets the command buffer and begins recording; returns it.
    VkCommandBuffer begin();
    [[nodiscard]] VkCommandBuffer cmd() const { return cmd_; }
    // Ends recording and submits. `what` describes the work for error messages.
    void submit();
    void setWhat(std::string what) { what_ = std::move(what); }
    // Waits up to timeoutNs; returns true when the submitted work has completed.
    bool wait(std::uint64_t timeoutNs);
    // Waits until done, calling `onTick` about every 100 ms (progress, interruption).
    void waitAll(const std::function<void()>& onTick = {});
    void submitAndWait() {
        submit();
        waitAll();
    }

private:
    const Context& ctx_;
    std::string what_;
    Handle<VkCommandPool> pool_;
    VkCommandBuffer cmd_ = VK_NULL_HANDLE;
    Handle<VkFence> fence_;
    bool pending_ = false;
};

// Makes compute-shader writes visible to later compute-shader reads and to host/transfer.
void computeBarrier(VkCommandBuffer cmd);

}  // namespace gdpt::vk
