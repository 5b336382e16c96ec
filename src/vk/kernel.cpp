#include "vk/kernel.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <memory>
#include <string>
#include <utility>

#include "util/cache_dir.h"
#include "util/env_choice.h"
#include "vk/buffer.h"
#include "vk/context.h"
#include "vk/pipeline_cache.h"
#include "vk/spirv_specialise.h"
#include "vk/timing.h"
#include "vk/vk_check.h"

namespace gdpt::vk {
namespace {

// What vkCreateComputePipelines needs, owned, so that a worker thread can run it.
struct PipelineJob {
    VkDevice device = VK_NULL_HANDLE;
    VkShaderModule module = VK_NULL_HANDLE;
    // Or, when the kernel is specialised first (spirv_specialise.h), its SPIR-V, from which
    // the job makes a module of its own (destroyed once the pipeline exists), and the cache.
    std::vector<std::uint32_t> spirv;
    std::vector<std::uint32_t> kept;  // KernelDesc::driverSpecConstants
    std::filesystem::path cacheDirectory;
    VkPipelineLayout layout = VK_NULL_HANDLE;
    std::vector<VkSpecializationMapEntry> entries;
    std::vector<std::uint32_t> values;
    std::string name;
};

// A module of the job's SPIR-V with its specialisation constants folded in (through the cache).
Handle<VkShaderModule> specialisedModule(const PipelineJob& job) {
    SpecConstants constants;
    for (std::size_t i = 0; i < job.entries.size(); ++i)
        constants.emplace_back(job.entries[i].constantID, job.values[i]);
    std::vector<std::uint32_t> words;
    try {
        words = specialiseCached(job.spirv.data(), job.spirv.size(), constants, job.cacheDirectory, job.kept)
                    .words;
    } catch (const Error& e) {
        throw e.withContext("creating pipeline '" + job.name + "'");
    }
    VkShaderModuleCreateInfo moduleInfo{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    moduleInfo.codeSize = words.size() * sizeof(std::uint32_t);
    moduleInfo.pCode = words.data();
    VkShaderModule module = VK_NULL_HANDLE;
    VK_CHECK(vkCreateShaderModule(job.device, &moduleInfo, nullptr, &module));
    const VkDevice device = job.device;
    return Handle<VkShaderModule>(module,
                                  [device](VkShaderModule m) { vkDestroyShaderModule(device, m, nullptr); });
}

VkPipeline createPipeline(const PipelineJob& job) {
    // A module may be destroyed once its pipelines exist.
    Handle<VkShaderModule> specialised;
    if (!job.spirv.empty()) specialised = specialisedModule(job);

    VkSpecializationInfo spec{};
    spec.mapEntryCount = static_cast<std::uint32_t>(job.entries.size());
    spec.pMapEntries = job.entries.data();
    spec.dataSize = job.values.size() * sizeof(std::uint32_t);
    spec.pData = job.values.data();

    VkComputePipelineCreateInfo pipeInfo{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    pipeInfo.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    pipeInfo.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    pipeInfo.stage.module = specialised ? specialised.get() : job.module;
    pipeInfo.stage.pName = "main";
    pipeInfo.stage.pSpecializationInfo = job.entries.empty() ? nullptr : &spec;
    pipeInfo.layout = job.layout;
    VkPipeline pipeline = VK_NULL_HANDLE;
    try {
        VK_CHECK(vkCreateComputePipelines(job.device, VK_NULL_HANDLE, 1, &pipeInfo, nullptr, &pipeline));
    } catch (const Error& e) {
        throw e.withContext("creating pipeline '" + job.name + "'");
    }
    return pipeline;
}

// What creating a kernel's pipeline uses, and what binding its descriptor set needs: the
// shader module and the layouts (each Kernel has its own; a kept pipeline has its own too).
struct PipelineObjects {
    Handle<VkShaderModule> module;
    Handle<VkDescriptorSetLayout> setLayout;
    Handle<VkPipelineLayout> pipelineLayout;
    std::uint32_t texelCount = 0;  // texel bindings of the set layout
    std::size_t bindingCount = 0;
};

// The SPIR-V form the device gets (KernelDesc::spirvOptimized), as words.
std::pair<const std::uint32_t*, std::size_t> chosenSpirv(const Context& ctx, const KernelDesc& desc) {
    const bool optimized = desc.spirvOptimized != nullptr && useOptimizedSpirv(ctx.info());
    return optimized ? std::make_pair(desc.spirvOptimized, desc.spirvOptimizedBytes / sizeof(std::uint32_t))
                     : std::make_pair(desc.spirv, desc.spirvBytes / sizeof(std::uint32_t));
}

// Whether the pipeline job specialises the kernel's SPIR-V itself (spirv_specialise.h).
bool specialises(const Context& ctx, const KernelDesc& desc) {
    return !desc.specConstants.empty() && chosenSpirv(ctx, desc).second >= kSpecialiseMinWords &&
           useSpecialisedSpirv(ctx.info());
}

PipelineObjects makeObjects(const Context& ctx, const KernelDesc& desc) {
    const VkDevice device = ctx.device();
    PipelineObjects o;
    if (!specialises(ctx, desc)) {
        const auto [words, count] = chosenSpirv(ctx, desc);
        VkShaderModuleCreateInfo moduleInfo{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
        moduleInfo.codeSize = count * sizeof(std::uint32_t);
        moduleInfo.pCode = words;
        VkShaderModule module = VK_NULL_HANDLE;
        VK_CHECK(vkCreateShaderModule(device, &moduleInfo, nullptr, &module));
        o.module = Handle<VkShaderModule>(
            module, [device](VkShaderModule m) { vkDestroyShaderModule(device, m, nullptr); });
        ctx.setName(VK_OBJECT_TYPE_SHADER_MODULE, reinterpret_cast<std::uint64_t>(module), desc.name);
    }

    std::vector<VkDescriptorSetLayoutBinding> bindings;
    for (const auto& [b, format] : desc.texelBindings)
        GDPT_CHECK(std::find(desc.bindings.begin(), desc.bindings.end(), b) != desc.bindings.end());
    for (std::uint32_t b : desc.bindings) {
        VkDescriptorSetLayoutBinding lb{};
        lb.binding = b;
        const bool texel = texelFormat(desc.texelBindings, b) != VK_FORMAT_UNDEFINED;
        lb.descriptorType =
            texel ? VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        o.texelCount += texel ? 1u : 0u;
        lb.descriptorCount = 1;
        lb.stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
        bindings.push_back(lb);
    }
    o.bindingCount = bindings.size();
    VkDescriptorSetLayoutCreateInfo setInfo{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    setInfo.bindingCount = static_cast<std::uint32_t>(bindings.size());
    setInfo.pBindings = bindings.data();
    VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
    VK_CHECK(vkCreateDescriptorSetLayout(device, &setInfo, nullptr, &setLayout));
    o.setLayout = Handle<VkDescriptorSetLayout>(
        setLayout, [device](VkDescriptorSetLayout l) { vkDestroyDescriptorSetLayout(device, l, nullptr); });

    VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, desc.pushConstantBytes};
    VkPipelineLayoutCreateInfo layoutInfo{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    layoutInfo.setLayoutCount = 1;
    layoutInfo.pSetLayouts = &setLayout;
    layoutInfo.pushConstantRangeCount = desc.pushConstantBytes ? 1u : 0u;
    layoutInfo.pPushConstantRanges = &range;
    VkPipelineLayout pipelineLayout = VK_NULL_HANDLE;
    VK_CHECK(vkCreatePipelineLayout(device, &layoutInfo, nullptr, &pipelineLayout));
    o.pipelineLayout = Handle<VkPipelineLayout>(
        pipelineLayout, [device](VkPipelineLayout l) { vkDestroyPipelineLayout(device, l, nullptr); });
    return o;
}

// The job that creates a pipeline of `desc` with `module` and `layout`.
// Without a module (makeObjects made none), the job specialises the SPIR-V itself.
PipelineJob pipelineJob(const Context& ctx, const KernelDesc& desc, VkShaderModule module,
                        VkPipelineLayout layout) {
    PipelineJob job;
    job.device = ctx.device();
    job.module = module;
    if (module == VK_NULL_HANDLE) {
        const auto [words, count] = chosenSpirv(ctx, desc);
        job.spirv.assign(words, words + count);
        job.kept = desc.driverSpecConstants;
        job.cacheDirectory = cacheDirectory();
    }
    job.layout = layout;
    job.name = desc.name;
    for (const auto& [id, value] : desc.specConstants) {
        VkSpecializationMapEntry e{};
        e.constantID = id;
        e.offset = static_cast<std::uint32_t>(job.values.size() * sizeof(std::uint32_t));
        e.size = sizeof(std::uint32_t);
        job.entries.push_back(e);
        job.values.push_back(value);
    }
    return job;
}

// What makes two kernels' pipelines interchangeable: the SPIR-V (by its embedded array and the
// form used), the set layout, the push constants and the specialisation constants.
std::string pipelineKey(const Context& ctx, const KernelDesc& desc) {
    const bool optimized = desc.spirvOptimized != nullptr && useOptimizedSpirv(ctx.info());
    std::string key = desc.name + "|" + std::to_string(reinterpret_cast<std::uintptr_t>(desc.spirv)) +
                      (optimized ? "|opt|" : "|raw|") + std::to_string(desc.pushConstantBytes) + "|b";
    for (std::uint32_t b : desc.bindings)
        key += "," + std::to_string(b) + ":" +
               std::to_string(static_cast<int>(texelFormat(desc.texelBindings, b)));
    key += "|s";
    for (const auto& [id, value] : desc.specConstants)
        key += "," + std::to_string(id) + "=" + std::to_string(value);
    return key;
}

}  // namespace

std::uint64_t texelBytes(VkFormat format) {
    switch (format) {
        case VK_FORMAT_R32G32B32A32_UINT:
        case VK_FORMAT_R32G32B32A32_SFLOAT:
            return 16;
        case VK_FORMAT_R32G32_UINT:
            return 8;
        default:
            throw Error("unsupported texel-buffer format " + std::to_string(static_cast<int>(format)));
    }
}

VkFormat texelFormat(const std::vector<std::pair<std::uint32_t, VkFormat>>& texelBindings,
                     std::uint32_t binding) {
    for (const auto& [b, format] : texelBindings)
        if (b == binding) return format;
    return VK_FORMAT_UNDEFINED;
}

bool useOptimizedSpirv(const DeviceInfo& device) {
    return envChoice("GDPT_SPIRV", "raw", "opt", device.lavapipeBeforeMesa23);
}

Kernel::Kernel(const Context& ctx, const KernelDesc& desc, PipelineCreation creation)
    : ctx_(ctx), desc_(desc) {
    if (ctx.serialPipelines()) creation = PipelineCreation::Now;
    VkDevice device = ctx.device();
    GDPT_CHECK(desc.spirv != nullptr && desc.spirvBytes > 0);
    if (desc.pushConstantBytes > ctx.info().maxPushConstantsSize)
        throw Error("kernel '" + desc.name + "' needs " + std::to_string(desc.pushConstantBytes) +
                    " bytes of push constants; device limit maxPushConstantsSize = " +
                    std::to_string(ctx.info().maxPushConstantsSize));

    PipelineObjects objects = makeObjects(ctx, desc);
    module_ = std::move(objects.module);
    setLayout_ = std::move(objects.setLayout);
    pipelineLayout_ = std::move(objects.pipelineLayout);
    const VkDescriptorSetLayout setLayout = setLayout_.get();
    const std::uint32_t texelCount = objects.texelCount;
    const std::size_t bindingCount = objects.bindingCount;

    if (bindingCount > 0) {
        std::vector<VkDescriptorPoolSize> sizes;
        const auto storageCount = static_cast<std::uint32_t>(bindingCount) - texelCount;
        if (storageCount) sizes.push_back({VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, storageCount});
        if (texelCount) sizes.push_back({VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, texelCount});
        VkDescriptorPoolCreateInfo poolInfo{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
        poolInfo.maxSets = 1;
        poolInfo.poolSizeCount = static_cast<std::uint32_t>(sizes.size());
        poolInfo.pPoolSizes = sizes.data();
        VkDescriptorPool pool = VK_NULL_HANDLE;
        VK_CHECK(vkCreateDescriptorPool(device, &poolInfo, nullptr, &pool));
        pool_ = Handle<VkDescriptorPool>(
            pool, [device](VkDescriptorPool p) { vkDestroyDescriptorPool(device, p, nullptr); });
        VkDescriptorSetAllocateInfo alloc{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
        alloc.descriptorPool = pool;
        alloc.descriptorSetCount = 1;
        alloc.pSetLayouts = &setLayout;
        VK_CHECK(vkAllocateDescriptorSets(device, &alloc, &set_));
    }

    // Last, so that nothing after it can throw while a worker is running.
    if (PipelineCache* cache = ctx.pipelineCache()) {
        // A kept pipeline: created once per description, with objects of its own that live as
        // long as it (the kernel binds its set with its own, identical, layout).
        shared_ = cache->get(pipelineKey(ctx, desc), [&] {
            auto owned = std::make_shared<PipelineObjects>(makeObjects(ctx, desc));
            PipelineJob job = pipelineJob(ctx, desc, owned->module.get(), owned->pipelineLayout.get());
            std::shared_future<VkPipeline> pipeline =
                creation == PipelineCreation::Background
                    ? std::async(std::launch::async, [job = std::move(job)] { return createPipeline(job); })
                          .share()
                    : std::async(std::launch::deferred, [job = std::move(job)] {
                          return createPipeline(job);
                      }).share();
            return PipelineCache::Creation{
                pipeline, [device, owned](VkPipeline p) { vkDestroyPipeline(device, p, nullptr); }};
        });
        if (creation == PipelineCreation::Now) (void)wait();
        return;
    }
    PipelineJob job = pipelineJob(ctx, desc, module_.get(), pipelineLayout_.get());
    if (creation == PipelineCreation::Background) {
        pending_ = std::async(std::launch::async, [job = std::move(job)] { return createPipeline(job); });
    } else {
        adopt(createPipeline(job));
    }
}

Kernel::~Kernel() {
    // The worker uses the module and the layout: it must finish before they are destroyed.
    if (!pending_.valid()) return;
    try {
        const VkPipeline pipeline = pending_.get();
        vkDestroyPipeline(ctx_.device(), pipeline, nullptr);
    } catch (const std::exception&) {
        // Its error was never asked for (the kernel was not used): nothing to destroy.
    }
}

void Kernel::adopt(VkPipeline pipeline) const {
    const VkDevice device = ctx_.device();
    pipeline_ =
        Handle<VkPipeline>(pipeline, [device](VkPipeline p) { vkDestroyPipeline(device, p, nullptr); });
    ctx_.setName(VK_OBJECT_TYPE_PIPELINE, reinterpret_cast<std::uint64_t>(pipeline), desc_.name);
}

double Kernel::wait() const {
    if (shared_.valid()) {
        if (keptPipeline_ != VK_NULL_HANDLE) return 0.0;
        const auto start = std::chrono::steady_clock::now();
        keptPipeline_ = shared_.get();  // rethrows the creation's error
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
    if (!pending_.valid()) return 0.0;
    const auto start = std::chrono::steady_clock::now();
    adopt(pending_.get());  // rethrows the worker's error
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void Kernel::bind(std::uint32_t binding, const Buffer& buffer) {
    GDPT_CHECK(std::find(desc_.bindings.begin(), desc_.bindings.end(), binding) != desc_.bindings.end());
    VkDescriptorBufferInfo info{buffer.get(), 0, VK_WHOLE_SIZE};
    VkWriteDescriptorSet write{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    write.dstSet = set_;
    write.dstBinding = binding;
    write.descriptorCount = 1;
    const VkFormat format = texelFormat(desc_.texelBindings, binding);
    VkBufferView view = VK_NULL_HANDLE;
    if (format != VK_FORMAT_UNDEFINED) {
        write.descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
        view = texelView(binding, buffer, format);
        write.pTexelBufferView = &view;
    } else {
        write.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        write.pBufferInfo = &info;
    }
    vkUpdateDescriptorSets(ctx_.device(), 1, &write, 0, nullptr);
}

void Kernel::bindAddress(std::uint32_t binding, const Buffer& target) {
    auto it = addresses_.find(binding);
    if (it == addresses_.end())
        it = addresses_
                 .emplace(binding,
                          Buffer(ctx_, sizeof(std::uint64_t), desc_.name + " address of " + target.name()))
                 .first;
    const std::uint64_t address = target.deviceAddress();
    it->second.upload(&address, sizeof address);
    bind(binding, it->second);
}

VkBufferView Kernel::createTexelView(const Buffer& buffer, VkFormat format) const {
    // The view covers the whole texels of the buffer.
    const std::uint64_t bytesPerTexel = texelBytes(format);
    const std::uint64_t texels = buffer.size() / bytesPerTexel;
    ctx_.checkTexelBufferSize(texels, buffer.name());
    VkBufferViewCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO};
    info.buffer = buffer.get();
    info.format = format;
    info.offset = 0;
    info.range = texels * bytesPerTexel;
    const VkDevice device = ctx_.device();
    VkBufferView view = VK_NULL_HANDLE;
    VK_CHECK(vkCreateBufferView(device, &info, nullptr, &view));
    ctx_.setName(VK_OBJECT_TYPE_BUFFER_VIEW, reinterpret_cast<std::uint64_t>(view), buffer.name());
    return view;
}

VkBufferView Kernel::texelView(std::uint32_t binding, const Buffer& buffer, VkFormat format) {
    Handle<VkBufferView> view(createTexelView(buffer, format), [device = ctx_.device()](VkBufferView v) {
        vkDestroyBufferView(device, v, nullptr);
    });
    const VkBufferView raw = view.get();
    // A rebinding replaces the earlier view (bind() is never called while work is pending).
    auto it =
        std::find_if(views_.begin(), views_.end(), [binding](const auto& e) { return e.first == binding; });
    if (it != views_.end())
        it->second = std::move(view);
    else
        views_.emplace_back(binding, std::move(view));
    return raw;
}

void Kernel::bindState(VkCommandBuffer cmd, const void* push) const {
    (void)wait();
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, shared_.valid() ? keptPipeline_ : pipeline_.get());
    if (set_ != VK_NULL_HANDLE)
        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipelineLayout_.get(), 0, 1, &set_, 0,
                                nullptr);
    if (push && desc_.pushConstantBytes)
        vkCmdPushConstants(cmd, pipelineLayout_.get(), VK_SHADER_STAGE_COMPUTE_BIT, 0,
                           desc_.pushConstantBytes, push);
}

void Kernel::dispatch(VkCommandBuffer cmd, std::uint32_t x, std::uint32_t y, std::uint32_t z,
                      const void* push, GpuTimer* timer) const {
    if (x == 0 || y == 0 || z == 0) return;
    if (timer) timer->begin(cmd, desc_.name);
    bindState(cmd, push);
    vkCmdDispatch(cmd, x, y, z);
    if (timer) timer->end(cmd);
}

void Kernel::dispatchIndirect(VkCommandBuffer cmd, const Buffer& args, std::uint64_t offset, const void* push,
                              GpuTimer* timer) const {
    if (timer) timer->begin(cmd, desc_.name);
    bindState(cmd, push);
    vkCmdDispatchIndirect(cmd, args.get(), offset);
    if (timer) timer->end(cmd);
}

void Kernel::dispatchItems(VkCommandBuffer cmd, std::uint32_t itemsX, std::uint32_t itemsY, const void* push,
                           GpuTimer* timer) const {
    const std::uint32_t gx = (itemsX + desc_.localSizeX - 1) / desc_.localSizeX;
    const std::uint32_t gy = (itemsY + desc_.localSizeY - 1) / desc_.localSizeY;
    dispatch(cmd, gx, gy, 1, push, timer);
}

}  // namespace gdpt::vk
