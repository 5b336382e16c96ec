#include "vk/commands.h"

#include "vk/context.h"
#include "vk/vk_check.h"

namespace gdpt::vk {

CommandStream::CommandStream(const Context& ctx, std::string what) : ctx_(ctx), what_(std::move(what)) {
    VkDevice device = ctx.device();
    VkCommandPoolCreateInfo poolInfo{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    poolInfo.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    poolInfo.queueFamilyIndex = ctx.queueFamily();
    VkCommandPool pool = VK_NULL_HANDLE;
    VK_CHECK(vkCreateCommandPool(device, &poolInfo, nullptr, &pool));
    pool_ =
        Handle<VkCommandPool>(pool, [device](VkCommandPool p) { vkDestroyCommandPool(device, p, nullptr); });
    VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    alloc.commandPool = pool;
    alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    alloc.commandBufferCount = 1;
    VK_CHECK(vkAllocateCommandBuffers(device, &alloc, &cmd_));
    VkFenceCreateInfo fenceInfo{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VkFence fence = VK_NULL_HANDLE;
    VK_CHECK(vkCreateFence(device, &fenceInfo, nullptr, &fence));
    fence_ = Handle<VkFence>(fence, [device](VkFence f) { vkDestroyFence(device, f, nullptr); });
}

CommandStream::~CommandStream() {
    // Work still in flight (an exception was thrown mid-render) must finish before the
    // command buffer and the resources it uses are destroyed.
    if (pending_) {
        VkFence fence = fence_.get();
        vkWaitForFences(ctx_.device(), 1, &fence, VK_TRUE, UINT64_MAX);
    }
}

VkCommandBuffer CommandStream::begin() {
    if (pending_) waitAll();
    VK_CHECK(vkResetCommandBuffer(cmd_, 0));
    VkCommandBufferBeginInfo info{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    info.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    VK_CHECK(vkBeginCommandBuffer(cmd_, &info));
    return cmd_;
}

void CommandStream::submit() {
    VK_CHECK(vkEndCommandBuffer(cmd_));
    VkFence fence = fence_.get();
    VK_CHECK(vkResetFences(ctx_.device(), 1, &fence));
    VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &cmd_;
    try {
        VK_CHECK(vkQueueSubmit(ctx_.queue(), 1, &submit, fence));
    } catch (const Error& e) {
        throw e.withContext("while submitting " + what_);
    }
    pending_ = true;
}

bool CommandStream::wait(std::uint64_t timeoutNs) {
    if (!pending_) return true;
    VkFence fence = fence_.get();
    const VkResult r = vkWaitForFences(ctx_.device(), 1, &fence, VK_TRUE, timeoutNs);
    if (r == VK_TIMEOUT) return false;
    if (r != VK_SUCCESS) {
        pending_ = false;
        try {
            VK_CHECK(r);
        } catch (const Error& e) {
            throw e.withContext("while running " + what_);
        }
    }
    pending_ = false;
    return true;
}

void CommandStream::waitAll(const std::function<void()>& onTick) {
    while (!wait(100'000'000ull))
        if (onTick) onTick();
}

void computeBarrier(VkCommandBuffer cmd) {
    VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT |
                            VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_HOST_READ_BIT |
                            VK_ACCESS_INDIRECT_COMMAND_READ_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                         VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT |
                             VK_PIPELINE_STAGE_HOST_BIT | VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT,
                         0, 1, &barrier, 0, nullptr, 0, nullptr);
}

}  // namespace gdpt::vk
