#include "vk/buffer.h"

#include <cstring>

#include "util/huge_pages.h"
#include "vk/commands.h"
#include "vk/context.h"
#include "vk/vk_check.h"

namespace gdpt::vk {

namespace {
constexpr VkBufferUsageFlags kUsage =
    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT |
    VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT;
constexpr VkMemoryPropertyFlags kMappable =
    VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
}  // namespace

Buffer::Buffer(const Context& ctx, std::uint64_t bytes, const std::string& name)
    : ctx_(&ctx), name_(name), size_(bytes < 16 ? 16 : (bytes + 3) & ~std::uint64_t{3}) {
    VkDevice device = ctx.device();
    VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    info.size = size_;
    // Every buffer can be read through its device address (shaders that need ranges beyond
    // maxStorageBufferRange use that; the feature is required, core in Vulkan 1.3).
    info.usage = kUsage | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    VkBuffer buffer = VK_NULL_HANDLE;
    VK_CHECK(vkCreateBuffer(device, &info, nullptr, &buffer));
    Handle<VkBuffer> bufferOwner(buffer, [device](VkBuffer b) { vkDestroyBuffer(device, b, nullptr); });

    VkMemoryRequirements req{};
    vkGetBufferMemoryRequirements(device, buffer, &req);
    const VkMemoryPropertyFlags deviceLocal = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
    VkMemoryPropertyFlags flags = deviceLocal | kMappable;
    if (!ctx.hasMemoryType(req.memoryTypeBits, flags)) flags = deviceLocal;
    VkMemoryAllocateFlagsInfo allocFlags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
    allocFlags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    alloc.pNext = &allocFlags;
    alloc.allocationSize = req.size;
    alloc.memoryTypeIndex = ctx.findMemoryType(req.memoryTypeBits, flags);
    VkDeviceMemory memory = VK_NULL_HANDLE;
    const VkResult r = vkAllocateMemory(device, &alloc, nullptr, &memory);
    if (r == VK_ERROR_OUT_OF_DEVICE_MEMORY || r == VK_ERROR_OUT_OF_HOST_MEMORY)
        throw Error("out of device memory allocating buffer '" + name + "' (" + std::to_string(size_ >> 20) +
                    " MiB)");
    VK_CHECK(r);
    ctx.noteAllocation(req.size);
    memory_ = Handle<VkDeviceMemory>(memory, [device, ctxp = &ctx, bytes = req.size](VkDeviceMemory m) {
        vkFreeMemory(device, m, nullptr);
        ctxp->noteFree(bytes);
    });
    VK_CHECK(vkBindBufferMemory(device, buffer, memory, 0));
    buffer_ = std::move(bufferOwner);
    if ((flags & kMappable) == kMappable) {
        VK_CHECK(vkMapMemory(device, memory, 0, VK_WHOLE_SIZE, 0, &mapped_));
        // A CPU device's memory is the process's own anonymous memory, first touched when it
        // is written: huge pages spare most of the page faults of a large buffer (a 5M-triangle
        // scene's tables, a 4K image's statistics; util/huge_pages.h).
        if (ctx.info().isCpu) adviseHugePages(mapped_, req.size);
    }
    ctx.setName(VK_OBJECT_TYPE_BUFFER, reinterpret_cast<std::uint64_t>(buffer), name);
}

std::uint64_t Buffer::deviceAddress() const {
    VkBufferDeviceAddressInfo info{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO};
    info.buffer = buffer_.get();
    return vkGetBufferDeviceAddress(ctx_->device(), &info);
}

void Buffer::upload(const void* data, std::uint64_t bytes, std::uint64_t offset) {
    GDPT_CHECK(offset + bytes <= size_);
    if (mapped_)
        std::memcpy(static_cast<char*>(mapped_) + offset, data, bytes);
    else
        stagedCopy(const_cast<void*>(data), bytes, offset, true);
}

void Buffer::download(void* data, std::uint64_t bytes, std::uint64_t offset) const {
    GDPT_CHECK(offset + bytes <= size_);
    if (mapped_)
        std::memcpy(data, static_cast<const char*>(mapped_) + offset, bytes);
    else
        stagedCopy(data, bytes, offset, false);
}

void Buffer::zero() {
    if (mapped_) {
        std::memset(mapped_, 0, size_);
        return;
    }
    CommandStream cmd(*ctx_, "zero " + name_);
    vkCmdFillBuffer(cmd.begin(), buffer_.get(), 0, VK_WHOLE_SIZE, 0);
    cmd.submitAndWait();
}

void Buffer::stagedCopy(void* hostData, std::uint64_t bytes, std::uint64_t offset, bool toDevice) const {
    Buffer staging;
    {
        // A host-visible staging buffer: built by hand because Buffer() prefers device-local.
        staging.ctx_ = ctx_;
        staging.size_ = bytes;
        VkDevice device = ctx_->device();
        VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
        info.size = bytes;
        info.usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
        VkBuffer b = VK_NULL_HANDLE;
        VK_CHECK(vkCreateBuffer(device, &info, nullptr, &b));
        staging.buffer_ = Handle<VkBuffer>(b, [device](VkBuffer x) { vkDestroyBuffer(device, x, nullptr); });
        VkMemoryRequirements req{};
        vkGetBufferMemoryRequirements(device, b, &req);
        VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
        alloc.allocationSize = req.size;
        alloc.memoryTypeIndex = ctx_->findMemoryType(req.memoryTypeBits, kMappable);
        VkDeviceMemory m = VK_NULL_HANDLE;
        VK_CHECK(vkAllocateMemory(device, &alloc, nullptr, &m));
        ctx_->noteAllocation(req.size);
        Handle<VkDeviceMemory> mem(m, [device, ctxp = ctx_, bytes = req.size](VkDeviceMemory x) {
            vkFreeMemory(device, x, nullptr);
            ctxp->noteFree(bytes);
        });
        VK_CHECK(vkBindBufferMemory(device, b, m, 0));
        VK_CHECK(vkMapMemory(device, m, 0, VK_WHOLE_SIZE, 0, &staging.mapped_));
        // Keep the memory alive as long as the buffer: destroy order buffer -> memory.
        Handle<VkBuffer> keep = std::move(staging.buffer_);
        staging.memory_ = std::move(mem);
        staging.buffer_ = std::move(keep);
    }
    if (toDevice) std::memcpy(staging.mapped_, hostData, bytes);
    CommandStream cmd(*ctx_, "copy " + name_);
    VkBufferCopy region{};
    region.size = bytes;
    if (toDevice) {
        region.dstOffset = offset;
        vkCmdCopyBuffer(cmd.begin(), staging.get(), buffer_.get(), 1, &region);
    } else {
        region.srcOffset = offset;
        vkCmdCopyBuffer(cmd.begin(), buffer_.get(), staging.get(), 1, &region);
    }
    cmd.submitAndWait();
    if (!toDevice) std::memcpy(hostData, staging.mapped_, bytes);
}

}  // namespace gdpt::vk
