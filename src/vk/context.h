// context.h — the Vulkan instance, the chosen physical device, the logical device and its
// compute queue. Headless (no window-system extensions). Picks lavapipe by default when
// several devices exist; --device NAME|INDEX overrides. With validation on, a debug
// messenger counts validation errors (tests fail on any).
#pragma once

#include <vulkan/vulkan.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "vk/handle.h"

namespace gdpt::vk {

struct ContextOptions {
    std::string device;           // "" = default choice; else a device index or name substring
    bool validation = false;      // enable VK_LAYER_KHRONOS_validation + error-counting messenger
    bool printValidation = true;  // print validation messages to stderr
    // Keep every compute pipeline for the context's life and share it among kernels of the
    // same description (pipeline_cache.h): for many renders in one process, e.g. the frames
    // of a sequence. Off: each Kernel creates and owns its pipeline.
    bool keepPipelines = false;
    // Reads and clears of buffers go through the device (a copy into host-cached staging
    // memory, vkCmdFillBuffer) even where the buffer's memory is host-cached: the path a
    // discrete GPU takes, for tests on a CPU device (vk/buffer.h).
    bool stagedTransfers = false;
};

// What `gdpt devices` prints and what the limits check reads.
struct DeviceInfo {
    std::uint32_t index = 0;
    std::string name;
    std::string type;                 // "cpu", "discrete-gpu", ...
    std::string driverName;           // e.g. "llvmpipe"
    std::string driverInfo;           // e.g. "Mesa 22.3.6 (LLVM 15.0.6)"
    std::uint32_t driverVersion = 0;  // VkPhysicalDeviceProperties::driverVersion (vendor encoding)
    std::uint32_t apiVersion = 0;
    bool isCpu = false;
    // Lavapipe with Mesa before 23 (mesaMajorVersion): it runs every branch under lane masks,
    // and its pipeline creation is what spirv-opt'd SPIR-V shortens (KernelDesc::spirvOptimized).
    bool lavapipeBeforeMesa23 = false;
    std::uint64_t maxStorageBufferRange = 0;    // largest descriptor range
    std::uint64_t maxTexelBufferElements = 0;   // largest texel-buffer view, in texels
    std::uint64_t maxMemoryAllocationSize = 0;  // largest buffer (device-address access)
    std::uint32_t maxPushConstantsSize = 0;
    std::uint32_t maxComputeWorkGroupInvocations = 0;
    std::uint32_t maxComputeSharedMemorySize = 0;
    std::uint32_t maxComputeWorkGroupCountX = 0;
    std::uint32_t subgroupSize = 0;
    float timestampPeriodNs = 0.0f;
    std::uint64_t deviceLocalHeapBytes = 0;
    bool scalarBlockLayout = false;
    bool bufferDeviceAddress = false;  // required (core in Vulkan 1.3)
    bool timestamps = false;
    std::string unsuitable;  // why gdpt cannot use it ("" = usable)
};

// Mesa's major version from driverInfo ("Mesa 22.3.6 (LLVM 15.0.6)" -> 22), else from
// driverVersion read as VK_MAKE_VERSION(major, minor, patch). Lavapipe 22.3 encodes its
// version there, but 25.0 reports driverVersion 1, so the string is read first.
std::uint32_t mesaMajorVersion(const std::string& driverInfo, std::uint32_t driverVersion);

class PipelineCache;

class Context {
public:
    explicit Context(const ContextOptions& options = {});
    ~Context();
    Context(const Context&) = delete;
    Context& operator=(const Context&) = delete;

    // Enumerates devices with a throw-away instance (for `gdpt devices`).
    static std::vector<DeviceInfo> listDevices();

    [[nodiscard]] VkInstance instance() const { return instance_.get(); }
    [[nodiscard]] VkPhysicalDevice physicalDevice() const { return physical_; }
    [[nodiscard]] VkDevice device() const { return device_.get(); }
    [[nodiscard]] VkQueue queue() const { return queue_; }
    [[nodiscard]] std::uint32_t queueFamily() const { return queueFamily_; }
    [[nodiscard]] const DeviceInfo& info() const { return info_; }
    [[nodiscard]] std::uint32_t validationErrors() const { return validationErrors_.load(); }

    // Memory type with all `required` flags among `typeBits`; throws if none.
    [[nodiscard]] std::uint32_t findMemoryType(std::uint32_t typeBits, VkMemoryPropertyFlags required) const;
    [[nodiscard]] bool hasMemoryType(std::uint32_t typeBits, VkMemoryPropertyFlags required) const;
    // The property flags of memory type `index`.
    [[nodiscard]] VkMemoryPropertyFlags memoryTypeFlags(std::uint32_t index) const;
    // ContextOptions::stagedTransfers.
    [[nodiscard]] bool stagedTransfers() const { return stagedTransfers_; }
    // Whether pipelines are created one at a time, never beside an allocation: a CPU device under
    // an address-space limit, whose driver crashes where a compilation runs out of it, so every
    // allocation keeps room for the next compilation (util/address_space_limit.h).
    [[nodiscard]] bool serialPipelines() const { return addressSpaceLimit_.has_value(); }
    // Why taking `aboutToTake` more bytes would leave such a device too little address space for
    // the next compilation; nullopt when it would not, or when no limit applies (then without
    // reading the process's address space).
    [[nodiscard]] std::optional<std::string> addressSpaceProblem(std::uint64_t aboutToTake) const;
    // Debug name shown by validation messages and tools (no-op without debug utils).
    void setName(VkObjectType type, std::uint64_t handle, const std::string& name) const;

    // Device memory held by gdpt's allocations (every vkAllocateMemory goes through
    // vk::Buffer, which reports here): now, and the most at any time since the context was made.
    [[nodiscard]] std::uint64_t deviceBytesNow() const { return deviceBytesNow_.load(); }
    [[nodiscard]] std::uint64_t deviceBytesPeak() const { return deviceBytesPeak_.load(); }
    void noteAllocation(std::uint64_t bytes) const;
    void noteFree(std::uint64_t bytes) const;

    // The pipelines kept for the context's life (ContextOptions::keepPipelines), else null.
    [[nodiscard]] PipelineCache* pipelineCache() const { return pipelineCache_.get(); }

    // Throws gdpt::Error naming the limit if a single storage buffer of `bytes` bytes
    // (what: "triangle geometry") exceeds the device's maxStorageBufferRange.
    void checkStorageBufferSize(std::uint64_t bytes, const std::string& what) const;
    // The same for a buffer read through its device address (no descriptor range limit):
    // throws if `bytes` exceeds maxMemoryAllocationSize.
    void checkAllocationSize(std::uint64_t bytes, const std::string& what) const;
    // The same for a texel-buffer view of `texels` texels: throws if it exceeds
    // maxTexelBufferElements.
    void checkTexelBufferSize(std::uint64_t texels, const std::string& what) const;

private:
    static VkBool32 VKAPI_PTR messengerCallback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                VkDebugUtilsMessageTypeFlagsEXT types,
                                                const VkDebugUtilsMessengerCallbackDataEXT* data, void* user);

    bool validation_ = false;
    bool printValidation_ = true;
    bool stagedTransfers_ = false;
    std::optional<std::uint64_t> addressSpaceLimit_;  // a CPU device's address-space limit, if set
    std::atomic<std::uint32_t> validationErrors_{0};
    mutable std::atomic<std::uint64_t> deviceBytesNow_{0};
    mutable std::atomic<std::uint64_t> deviceBytesPeak_{0};
    Handle<VkInstance> instance_;
    Handle<VkDebugUtilsMessengerEXT> messenger_;
    VkPhysicalDevice physical_ = VK_NULL_HANDLE;
    DeviceInfo info_;
    VkPhysicalDeviceMemoryProperties memory_{};
    Handle<VkDevice> device_;
    VkQueue queue_ = VK_NULL_HANDLE;
    std::uint32_t queueFamily_ = 0;
    PFN_vkSetDebugUtilsObjectNameEXT setObjectName_ = nullptr;
    // After device_: destroyed (its pipelines released) before the device.
    std::unique_ptr<PipelineCache> pipelineCache_;
};

}  // namespace gdpt::vk
