// buffer.h — a storage buffer with its own memory allocation (one allocation per buffer:
// gdpt uses a handful of large buffers, so no sub-allocator is needed). Host-visible
// device-local memory is used when the device has it (lavapipe, ReBAR GPUs); otherwise
// the buffer is device-local and uploads go through a staging copy. Downloads and clears
// touch the memory from the host only where it is host-cached (a CPU device): a GPU's
// host-visible device memory is write-combined across PCIe, where the host reads at tens of
// MB/s (an H200 read a 1080p render's 140 MB in 5.5 s, 2026-12-04), so they go through a
// device copy into host-cached staging memory, in chunks, and vkCmdFillBuffer.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <initializer_list>
#include <string>
#include <vector>

#include "util/error.h"
#include "vk/handle.h"

namespace gdpt::vk {

class Context;

class Buffer {
public:
    Buffer() = default;
    // A zero size is rounded up to 16 bytes (Vulkan forbids empty buffers; empty tables
    // such as "no punctual lights" still need something bound).
    Buffer(const Context& ctx, std::uint64_t bytes, const std::string& name);

    [[nodiscard]] VkBuffer get() const { return buffer_.get(); }
    [[nodiscard]] std::uint64_t size() const { return size_; }
    [[nodiscard]] const std::string& name() const { return name_; }
    // The buffer's device address (GL_EXT_buffer_reference), for access beyond
    // maxStorageBufferRange.
    [[nodiscard]] std::uint64_t deviceAddress() const;

    // The buffer's memory mapped into the process when it is host-visible (CPU devices,
    // ReBAR GPUs), for writing tables in place (not for reading: see the header's note);
    // nullptr otherwise (use upload).
    [[nodiscard]] void* mapped() const { return mapped_; }
    // Whether download and zero touch the memory from the host (host-cached memory) rather
    // than through a device copy or fill.
    [[nodiscard]] bool hostReadsDirectly() const { return hostCached_; }

    // Copies `bytes` bytes from host memory into the buffer at `offset`.
    void upload(const void* data, std::uint64_t bytes, std::uint64_t offset = 0);
    // Copies `bytes` bytes out of the buffer at `offset`. The caller has waited for the
    // GPU work that wrote it.
    void download(void* data, std::uint64_t bytes, std::uint64_t offset = 0) const;
    // Fills the whole buffer with zero bytes.
    void zero();

    template <typename T>
    void uploadVector(const std::vector<T>& v) {
        if (!v.empty()) upload(v.data(), v.size() * sizeof(T));
    }
    template <typename T>
    std::vector<T> downloadVector(std::size_t count) const {
        std::vector<T> v(count);
        if (count) download(v.data(), count * sizeof(T));
        return v;
    }

    // The buffer's first `count` records as the host reads them: the mapping itself where the
    // host reads it directly (no copy of a 4K image's statistics, hundreds of MiB), else a
    // downloaded copy. The caller has waited for the GPU work that wrote them; the view lives
    // no longer than the buffer.
    template <typename T>
    class ReadView {
    public:
        [[nodiscard]] const T* data() const { return data_; }
        [[nodiscard]] std::size_t size() const { return size_; }
        const T& operator[](std::size_t i) const { return data_[i]; }

    private:
        friend class Buffer;
        std::vector<T> copy_;
        const T* data_ = nullptr;
        std::size_t size_ = 0;
    };
    template <typename T>
    ReadView<T> read(std::size_t count) const {
        GDPT_CHECK(count * sizeof(T) <= size_);
        ReadView<T> view;
        view.size_ = count;
        if (hostCached_) {
            view.data_ = static_cast<const T*>(mapped_);
        } else {
            view.copy_ = downloadVector<T>(count);
            view.data_ = view.copy_.data();
        }
        return view;
    }

    // The most bytes one staged copy moves at once (the staging buffer's size).
    static constexpr std::uint64_t kStagingChunk = std::uint64_t{64} << 20;

private:
    // Creates buffer_ (size_ bytes, `usage`) and its memory, of the first of the `preferred`
    // property flags the device has, and maps it when those ask for host-visible memory
    // (setting coherent_ from the memory type); both
    // the constructor's buffers and staging buffers. `what` completes "out of ..." when the
    // memory is exhausted. Returns the memory type's flags.
    VkMemoryPropertyFlags allocate(VkBufferUsageFlags usage,
                                   std::initializer_list<VkMemoryPropertyFlags> preferred,
                                   const std::string& what);
    // A host-visible buffer for staged copies: host-cached when `forReading` and the device
    // has such memory (then `coherent_` says whether reads need an invalidate).
    static Buffer makeStaging(const Context& ctx, std::uint64_t bytes, bool forReading);
    void stagedCopy(void* hostData, std::uint64_t bytes, std::uint64_t offset, bool toDevice) const;

    const Context* ctx_ = nullptr;
    std::string name_;
    std::uint64_t size_ = 0;
    Handle<VkDeviceMemory> memory_;  // declared before buffer_: the buffer dies first
    Handle<VkBuffer> buffer_;
    void* mapped_ = nullptr;   // persistent mapping when host-visible
    bool hostCached_ = false;  // mapped_ is host-cached memory: the host reads it directly
    bool coherent_ = true;     // mapped_ needs no flush/invalidate
};

}  // namespace gdpt::vk
