#include "vk/buffer.h"

#include <algorithm>
#include <cstring>

#include "util/huge_pages.h"
#include "util/memory.h"
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
    // Every buffer can be read through its device address (shaders that need ranges beyond
    // maxStorageBufferRange use that; the feature is required, core in Vulkan 1.3).
    const VkMemoryPropertyFlags deviceLocal = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
    const VkMemoryPropertyFlags flags =
        allocate(kUsage | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT, {deviceLocal | kMappable, deviceLocal},
                 "device memory allocating buffer '" + name + "'");
    if (mapped_) {
        hostCached_ = (flags & VK_MEMORY_PROPERTY_HOST_CACHED_BIT) != 0 && !ctx.stagedTransfers();
        // A CPU device's memory is the process's own anonymous memory, first touched when it
        // is written: huge pages spare most of the page faults of a large buffer (a 5M-triangle
        // scene's tables, a 4K image's statistics; util/huge_pages.h).
        if (ctx.info().isCpu) adviseHugePages(mapped_, size_);
    }
    ctx.setName(VK_OBJECT_TYPE_BUFFER, reinterpret_cast<std::uint64_t>(buffer_.get()), name);
}

VkMemoryPropertyFlags Buffer::allocate(VkBufferUsageFlags usage,
                                       std::initializer_list<VkMemoryPropertyFlags> preferred,
                                       const std::string& what) {
    VkDevice device = ctx_->device();
    VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    info.size = size_;
    info.usage = usage;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    VkBuffer buffer = VK_NULL_HANDLE;
    VK_CHECK(vkCreateBuffer(device, &info, nullptr, &buffer));
    Handle<VkBuffer> bufferOwner(buffer, [device](VkBuffer b) { vkDestroyBuffer(device, b, nullptr); });

    VkMemoryRequirements req{};
    vkGetBufferMemoryRequirements(device, buffer, &req);
    // The first of the preferred kinds the device has (findMemoryType names the last if none).
    VkMemoryPropertyFlags flags = *(preferred.end() - 1);
    for (VkMemoryPropertyFlags f : preferred)
        if (ctx_->hasMemoryType(req.memoryTypeBits, f)) {
            flags = f;
            break;
        }
    VkMemoryAllocateFlagsInfo allocFlags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
    allocFlags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    if (usage & VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT) alloc.pNext = &allocFlags;
    alloc.allocationSize = req.size;
    alloc.memoryTypeIndex = ctx_->findMemoryType(req.memoryTypeBits, flags);
    // A CPU device's memory is the process's: under an address-space limit, keep what its
    // driver needs to compile kernels (util/address_space_limit.h).
    if (auto problem = ctx_->addressSpaceProblem(req.size))
        throw Error("out of " + what + " (" + memoryText(size_) + "): " + *problem);
    VkDeviceMemory memory = VK_NULL_HANDLE;
    const VkResult r = vkAllocateMemory(device, &alloc, nullptr, &memory);
    if (r == VK_ERROR_OUT_OF_DEVICE_MEMORY || r == VK_ERROR_OUT_OF_HOST_MEMORY)
        throw Error("out of " + what + " (" + memoryText(size_) + ")");
    VK_CHECK(r);
    ctx_->noteAllocation(req.size);
    memory_ = Handle<VkDeviceMemory>(memory, [device, ctxp = ctx_, bytes = req.size](VkDeviceMemory m) {
        vkFreeMemory(device, m, nullptr);
        ctxp->noteFree(bytes);
    });
    VK_CHECK(vkBindBufferMemory(device, buffer, memory, 0));
    buffer_ = std::move(bufferOwner);
    const VkMemoryPropertyFlags type = ctx_->memoryTypeFlags(alloc.memoryTypeIndex);
    if (flags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT) {  // asked for, not merely what the type has
        VK_CHECK(vkMapMemory(device, memory, 0, VK_WHOLE_SIZE, 0, &mapped_));
        coherent_ = (type & VK_MEMORY_PROPERTY_HOST_COHERENT_BIT) != 0;
    }
    return type;
}

std::uint64_t Buffer::deviceAddress() const {
    VkBufferDeviceAddressInfo info{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO};
    info.buffer = buffer_.get();
    return vkGetBufferDeviceAddress(ctx_->device(), &info);
}

void Buffer::upload(const void* data, std::uint64_t bytes, std::uint64_t offset) {
    GDPT_CHECK(offset + bytes <= size_);
    // Writes through a write-combined mapping run at the bus's speed: only reads are staged.
    if (mapped_ && !ctx_->stagedTransfers())
        std::memcpy(static_cast<char*>(mapped_) + offset, data, bytes);
    else
        stagedCopy(const_cast<void*>(data), bytes, offset, true);
}

void Buffer::download(void* data, std::uint64_t bytes, std::uint64_t offset) const {
    GDPT_CHECK(offset + bytes <= size_);
    if (hostCached_)
        std::memcpy(data, static_cast<const char*>(mapped_) + offset, bytes);
    else
        stagedCopy(data, bytes, offset, false);
}

void Buffer::zero() {
    if (hostCached_) {
        std::memset(mapped_, 0, size_);
        return;
    }
    CommandStream cmd(*ctx_, "zero " + name_);
    vkCmdFillBuffer(cmd.begin(), buffer_.get(), 0, VK_WHOLE_SIZE, 0);
    cmd.submitAndWait();
}

Buffer Buffer::makeStaging(const Context& ctx, std::uint64_t bytes, bool forReading) {
    Buffer staging;
    staging.ctx_ = &ctx;
    staging.name_ = "staging";
    staging.size_ = bytes;
    // Reading: host-cached memory (coherent if there is such, else invalidated before reads);
    // writing: any mappable memory (write-combined is what writes want).
    constexpr VkMemoryPropertyFlags cached =
        VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_CACHED_BIT;
    const auto usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    const std::string what = "host-visible memory allocating a staging buffer";
    if (forReading)
        staging.allocate(usage, {cached | kMappable, cached, kMappable}, what);
    else
        staging.allocate(usage, {kMappable}, what);
    return staging;
}

void Buffer::stagedCopy(void* hostData, std::uint64_t bytes, std::uint64_t offset, bool toDevice) const {
    if (bytes == 0) return;
    const Buffer staging = makeStaging(*ctx_, std::min(bytes, kStagingChunk), !toDevice);
    auto* host = static_cast<char*>(hostData);
    for (std::uint64_t done = 0; done < bytes;) {
        const std::uint64_t n = std::min(bytes - done, kStagingChunk);
        if (toDevice) std::memcpy(staging.mapped_, host + done, n);
        CommandStream cmd(*ctx_, "copy " + name_);
        VkBufferCopy region{};
        region.size = n;
        if (toDevice) {
            region.dstOffset = offset + done;
            vkCmdCopyBuffer(cmd.begin(), staging.get(), buffer_.get(), 1, &region);
        } else {
            region.srcOffset = offset + done;
            vkCmdCopyBuffer(cmd.begin(), buffer_.get(), staging.get(), 1, &region);
            // The copy's writes become visible to the host once the queue is waited on.
            VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
            barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
            barrier.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
            vkCmdPipelineBarrier(cmd.cmd(), VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1,
                                 &barrier, 0, nullptr, 0, nullptr);
        }
        cmd.submitAndWait();
        if (!toDevice) {
            if (!staging.coherent_) {
                VkMappedMemoryRange range{VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE};
                range.memory = staging.memory_.get();
                range.size = VK_WHOLE_SIZE;
                VK_CHECK(vkInvalidateMappedMemoryRanges(ctx_->device(), 1, &range));
            }
            std::memcpy(host + done, staging.mapped_, n);
        }
        done += n;
    }
}

}  // namespace gdpt::vk
