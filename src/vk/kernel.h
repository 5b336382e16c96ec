// kernel.h — one compute pipeline: a .comp file's embedded SPIR-V, its descriptor-set
// layout (storage buffers, and uniform texel buffers where the description says so),
// push-constant range and specialisation constants, plus one descriptor set that buffers
// are bound to by binding number.
#pragma once

#include <vulkan/vulkan.h>

#include <cstddef>
#include <cstdint>
#include <future>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "vk/buffer.h"
#include "vk/handle.h"

namespace gdpt::vk {

class Buffer;
class Context;
struct DeviceInfo;
class GpuTimer;

struct KernelDesc {
    std::string name;  // shown in --profile and error messages
    const std::uint32_t* spirv = nullptr;
    std::size_t spirvBytes = 0;
    // The same kernel through spirv-opt (cmake/GdptSpirvEmbed.cmake), if not null: lavapipe
    // before Mesa 23 creates its pipeline in about half the time and runs it as fast; Mesa 25
    // runs it ~12 % slower, so every other device gets `spirv` (bench/RESULTS.md,
    // spirv-opt). GDPT_SPIRV=raw|opt in the environment overrides the choice.
    const std::uint32_t* spirvOptimized = nullptr;
    std::size_t spirvOptimizedBytes = 0;
    std::vector<std::uint32_t> bindings;  // binding numbers of set 0 (storage buffers unless below)
    // Bindings of `bindings` that the shader reads as uniform texel buffers (GLSL
    // textureBuffer / utextureBuffer + texelFetch), with the format of their view. Lavapipe
    // before Mesa 23 loads a storage buffer lane by lane with a branch per lane and
    // component, but fetches texels with vector gathers (bench/RESULTS.md,
    // texel buffers).
    std::vector<std::pair<std::uint32_t, VkFormat>> texelBindings;
    std::uint32_t pushConstantBytes = 0;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> specConstants;  // (id, 32-bit value)
    // Ids of specConstants that stay specialisation constants when gdpt folds the others into
    // the SPIR-V (spirv_specialise.h): the driver specialises these itself.
    std::vector<std::uint32_t> driverSpecConstants;
    std::uint32_t localSizeX = 1;  // workgroup size, for dispatch-by-items helpers
    std::uint32_t localSizeY = 1;
};

// Bytes per texel of a texel-binding format (the formats gdpt's kernels use: RGBA32 and
// RG32, whose uniform-texel-buffer support Vulkan requires); throws for any other.
std::uint64_t texelBytes(VkFormat format);

// The view format that `texelBindings` (KernelDesc::texelBindings) gives `binding`;
// VK_FORMAT_UNDEFINED if it lists no such binding (a storage buffer).
VkFormat texelFormat(const std::vector<std::pair<std::uint32_t, VkFormat>>& texelBindings,
                     std::uint32_t binding);

// KernelDesc with the SPIR-V of the embedded arrays kSpv_<name> and kSpv_<name>_opt from the
// build (GDPT_KERNEL_SPIRV(name) names both).
template <std::size_t N, std::size_t M>
KernelDesc kernelDesc(std::string name, const std::uint32_t (&spirv)[N],
                      const std::uint32_t (&optimized)[M]) {
    KernelDesc d;
    d.name = std::move(name);
    d.spirv = spirv;
    d.spirvBytes = N * sizeof(std::uint32_t);
    d.spirvOptimized = optimized;
    d.spirvOptimizedBytes = M * sizeof(std::uint32_t);
    return d;
}
#define GDPT_KERNEL_SPIRV(name) kSpv_##name, kSpv_##name##_opt

// Whether a kernel on this device is created from KernelDesc::spirvOptimized: GDPT_SPIRV=opt
// or raw in the environment, else lavapipe before Mesa 23 only. Throws for another value.
bool useOptimizedSpirv(const DeviceInfo& device);

// When a Kernel's pipeline is created. Background: on a worker thread started by the
// constructor; the first dispatch (or wait()) waits for it. Lavapipe spends most of a large
// kernel's set-up in vkCreateComputePipelines (0.3-1 s for gpt.comp with Mesa 22.3), on one
// core, so a pass can create its pipelines while the scene is built and uploaded.
enum class PipelineCreation { Now, Background };

class Kernel {
public:
    Kernel(const Context& ctx, const KernelDesc& desc, PipelineCreation creation = PipelineCreation::Now);
    // Waits for a pipeline still being created (and destroys it).
    ~Kernel();
    Kernel(const Kernel&) = delete;
    Kernel& operator=(const Kernel&) = delete;

    // Points `binding` at `buffer` (whole range; for a texel binding, a view of the whole
    // texels it holds, which the kernel owns). Not while a submitted command buffer that
    // uses this kernel is pending.
    void bind(std::uint32_t binding, const Buffer& buffer);
    // Points `binding` at an 8-byte buffer (owned by the kernel) that holds `target`'s device
    // address: for the per-pixel buffers the kernels reach through a buffer reference
    // (shaders/lib/pixel_buffers.glsl), which maxStorageBufferRange does not limit. `target`
    // must outlive the kernel's use of it.
    void bindAddress(std::uint32_t binding, const Buffer& target);
    // Records bind + push constants + dispatch of groups (x, y, z). With a timer, the
    // dispatch is wrapped in a named timestamp scope.
    void dispatch(VkCommandBuffer cmd, std::uint32_t x, std::uint32_t y, std::uint32_t z,
                  const void* push = nullptr, GpuTimer* timer = nullptr) const;
    // Dispatch with the group counts read by the device from `args` at `offset` (three
    // uint32; zeros make it a no-op), so that device code can cancel recorded work.
    void dispatchIndirect(VkCommandBuffer cmd, const Buffer& args, std::uint64_t offset,
                          const void* push = nullptr, GpuTimer* timer = nullptr) const;
    // Dispatch enough workgroups to cover itemsX × itemsY invocations.
    void dispatchItems(VkCommandBuffer cmd, std::uint32_t itemsX, std::uint32_t itemsY,
                       const void* push = nullptr, GpuTimer* timer = nullptr) const;
    [[nodiscard]] const std::string& name() const { return desc_.name; }
    // Waits until the pipeline exists; rethrows the error of a failed background creation
    // (with the kernel's name). Returns the seconds waited.
    double wait() const;

private:
    void bindState(VkCommandBuffer cmd, const void* push) const;  // pipeline, set, push constants
    void adopt(VkPipeline pipeline) const;                        // owns and names a created pipeline
    [[nodiscard]] VkBufferView createTexelView(const Buffer& buffer, VkFormat format) const;
    // A `format` view of `buffer` for texel binding `binding`, kept in views_ (replacing an
    // older one).
    VkBufferView texelView(std::uint32_t binding, const Buffer& buffer, VkFormat format);

    const Context& ctx_;
    KernelDesc desc_;
    Handle<VkShaderModule> module_;
    Handle<VkDescriptorSetLayout> setLayout_;
    Handle<VkPipelineLayout> pipelineLayout_;
    // The pipeline, once created; pending_ holds a background creation until wait() takes
    // it (both mutable: resolving it does not change what the kernel is).
    mutable Handle<VkPipeline> pipeline_;
    mutable std::future<VkPipeline> pending_;
    // Or a pipeline the context keeps (ContextOptions::keepPipelines), not owned.
    std::shared_future<VkPipeline> shared_;
    mutable VkPipeline keptPipeline_ = VK_NULL_HANDLE;
    Handle<VkDescriptorPool> pool_;
    VkDescriptorSet set_ = VK_NULL_HANDLE;
    std::vector<std::pair<std::uint32_t, Handle<VkBufferView>>> views_;  // texel bindings' views
    std::map<std::uint32_t, Buffer> addresses_;  // bindAddress's 8-byte buffers, per binding
};

}  // namespace gdpt::vk
