#include "vk/context.h"

#include <algorithm>
#include <cstdio>
#include <cstring>

#include "util/address_space_limit.h"
#include "util/error.h"
#include "util/file_size_limit.h"
#include "vk/pipeline_cache.h"
#include "vk/vk_check.h"

namespace gdpt::vk {

std::uint32_t mesaMajorVersion(const std::string& driverInfo, std::uint32_t driverVersion) {
    unsigned major = 0;
    if (std::sscanf(driverInfo.c_str(), "Mesa %u", &major) == 1) return major;
    return VK_API_VERSION_MAJOR(driverVersion);
}

namespace {

const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

bool layerAvailable(const char* name) {
    std::uint32_t count = 0;
    vkEnumerateInstanceLayerProperties(&count, nullptr);
    std::vector<VkLayerProperties> layers(count);
    vkEnumerateInstanceLayerProperties(&count, layers.data());
    return std::any_of(layers.begin(), layers.end(),
                       [&](const VkLayerProperties& l) { return std::strcmp(l.layerName, name) == 0; });
}

bool instanceExtensionAvailable(const char* name) {
    std::uint32_t count = 0;
    vkEnumerateInstanceExtensionProperties(nullptr, &count, nullptr);
    std::vector<VkExtensionProperties> exts(count);
    vkEnumerateInstanceExtensionProperties(nullptr, &count, exts.data());
    return std::any_of(exts.begin(), exts.end(), [&](const VkExtensionProperties& e) {
        return std::strcmp(e.extensionName, name) == 0;
    });
}

VkInstance createInstance(bool validation, bool debugUtils) {
    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.pApplicationName = "gdpt";
    app.applicationVersion = VK_MAKE_VERSION(0, 1, 0);
    app.pEngineName = "gdpt";
    app.apiVersion = VK_API_VERSION_1_2;
    std::vector<const char*> layers;
    std::vector<const char*> extensions;
    if (validation) layers.push_back(kValidationLayer);
    if (debugUtils) extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    info.pApplicationInfo = &app;
    info.enabledLayerCount = static_cast<std::uint32_t>(layers.size());
    info.ppEnabledLayerNames = layers.data();
    info.enabledExtensionCount = static_cast<std::uint32_t>(extensions.size());
    info.ppEnabledExtensionNames = extensions.data();
    VkInstance instance = VK_NULL_HANDLE;
    const VkResult r = vkCreateInstance(&info, nullptr, &instance);
    if (r == VK_ERROR_INCOMPATIBLE_DRIVER || r == VK_ERROR_INITIALIZATION_FAILED)
        throw Error(std::string("no Vulkan driver found (") + vkResultName(r) +
                    "); install mesa-vulkan-drivers for the CPU device (lavapipe), or check "
                    "VK_DRIVER_FILES / VK_ICD_FILENAMES" +
                    driverStartHint(addressSpaceLimit()));
    if (r != VK_SUCCESS)
        throw Error("vkCreateInstance failed with " + std::string(vkResultName(r)) +
                    driverStartHint(addressSpaceLimit()));
    return instance;
}

const char* deviceTypeName(VkPhysicalDeviceType t) {
    switch (t) {
        case VK_PHYSICAL_DEVICE_TYPE_CPU:
            return "cpu";
        case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
            return "discrete-gpu";
        case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
            return "integrated-gpu";
        case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
            return "virtual-gpu";
        default:
            return "other";
    }
}

DeviceInfo queryDevice(VkPhysicalDevice pd, std::uint32_t index) {
    DeviceInfo d;
    d.index = index;
    VkPhysicalDeviceDriverProperties driver{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
    VkPhysicalDeviceMaintenance3Properties maint3{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_3_PROPERTIES};
    maint3.pNext = &driver;
    VkPhysicalDeviceSubgroupProperties subgroup{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES};
    subgroup.pNext = &maint3;
    VkPhysicalDeviceProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
    props.pNext = &subgroup;
    vkGetPhysicalDeviceProperties2(pd, &props);
    const auto& p = props.properties;
    d.name = p.deviceName;
    d.type = deviceTypeName(p.deviceType);
    d.isCpu = p.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
    d.driverName = driver.driverName;
    d.driverInfo = driver.driverInfo;
    d.driverVersion = p.driverVersion;
    d.lavapipeBeforeMesa23 =
        d.driverName == "llvmpipe" && mesaMajorVersion(d.driverInfo, p.driverVersion) < 23;
    d.apiVersion = p.apiVersion;
    d.maxStorageBufferRange = p.limits.maxStorageBufferRange;
    d.maxTexelBufferElements = p.limits.maxTexelBufferElements;
    d.maxMemoryAllocationSize = maint3.maxMemoryAllocationSize;
    d.maxPushConstantsSize = p.limits.maxPushConstantsSize;
    d.maxComputeWorkGroupInvocations = p.limits.maxComputeWorkGroupInvocations;
    d.maxComputeSharedMemorySize = p.limits.maxComputeSharedMemorySize;
    d.maxComputeWorkGroupCountX = p.limits.maxComputeWorkGroupCount[0];
    d.subgroupSize = subgroup.subgroupSize;
    d.timestampPeriodNs = p.limits.timestampPeriod;

    VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
    VkPhysicalDeviceFeatures2 f{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
    f.pNext = &f12;
    vkGetPhysicalDeviceFeatures2(pd, &f);
    d.scalarBlockLayout = f12.scalarBlockLayout == VK_TRUE;
    d.bufferDeviceAddress = f12.bufferDeviceAddress == VK_TRUE;

    VkPhysicalDeviceMemoryProperties mem{};
    vkGetPhysicalDeviceMemoryProperties(pd, &mem);
    for (std::uint32_t i = 0; i < mem.memoryHeapCount; ++i)
        if (mem.memoryHeaps[i].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT)
            d.deviceLocalHeapBytes = std::max<std::uint64_t>(d.deviceLocalHeapBytes, mem.memoryHeaps[i].size);

    std::uint32_t qCount = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(pd, &qCount, nullptr);
    std::vector<VkQueueFamilyProperties> families(qCount);
    vkGetPhysicalDeviceQueueFamilyProperties(pd, &qCount, families.data());
    bool compute = false;
    for (const auto& fam : families) {
        if (fam.queueFlags & VK_QUEUE_COMPUTE_BIT) {
            compute = true;
            d.timestamps = fam.timestampValidBits > 0;
            break;
        }
    }
    if (VK_API_VERSION_MAJOR(d.apiVersion) == 1 && VK_API_VERSION_MINOR(d.apiVersion) < 2)
        d.unsuitable = "Vulkan 1.2 is required";
    else if (!compute)
        d.unsuitable = "no compute queue";
    else if (!d.scalarBlockLayout)
        d.unsuitable = "scalarBlockLayout is not supported";
    else if (!d.bufferDeviceAddress)
        d.unsuitable = "bufferDeviceAddress is not supported";
    else if (d.maxPushConstantsSize < 128)
        d.unsuitable = "maxPushConstantsSize < 128";
    return d;
}

std::vector<VkPhysicalDevice> physicalDevices(VkInstance instance) {
    try {
        std::uint32_t count = 0;
        VK_CHECK(vkEnumeratePhysicalDevices(instance, &count, nullptr));
        std::vector<VkPhysicalDevice> devices(count);
        VK_CHECK(vkEnumeratePhysicalDevices(instance, &count, devices.data()));
        return devices;
    } catch (const VulkanError& e) {  // a driver that could not start under `ulimit -v`
        throw Error(e.what() + driverStartHint(addressSpaceLimit()));
    }
}

// Default choice: lavapipe (a CPU device) first, as the product's first-class target; then
// discrete, integrated, anything usable. An explicit --device is an index or a
// case-sensitive substring of the device name.
std::uint32_t chooseDevice(const std::vector<DeviceInfo>& infos, const std::string& wanted) {
    if (infos.empty())
        throw Error("no Vulkan devices found; install mesa-vulkan-drivers" +
                    driverStartHint(addressSpaceLimit()));
    if (!wanted.empty()) {
        const bool numeric = std::all_of(wanted.begin(), wanted.end(), ::isdigit);
        for (const auto& d : infos) {
            const bool match =
                numeric ? std::to_string(d.index) == wanted : d.name.find(wanted) != std::string::npos;
            if (!match) continue;
            if (!d.unsuitable.empty())
                throw Error("device " + std::to_string(d.index) + " '" + d.name +
                            "' cannot run gdpt: " + d.unsuitable);
            return d.index;
        }
        throw Error("--device '" + wanted + "' matches no Vulkan device (see `gdpt devices`)");
    }
    auto rank = [](const DeviceInfo& d) {
        if (!d.unsuitable.empty()) return 0;
        if (d.isCpu) return 4;
        if (d.type == "discrete-gpu") return 3;
        if (d.type == "integrated-gpu") return 2;
        return 1;
    };
    const auto best = std::max_element(infos.begin(), infos.end(),
                                       [&](const auto& a, const auto& b) { return rank(a) < rank(b); });
    if (rank(*best) == 0) throw Error("no usable Vulkan device: '" + best->name + "': " + best->unsuitable);
    return best->index;
}

}  // namespace

std::vector<DeviceInfo> Context::listDevices() {
    Handle<VkInstance> instance(createInstance(false, false),
                                [](VkInstance i) { vkDestroyInstance(i, nullptr); });
    std::vector<DeviceInfo> infos;
    const auto devices = physicalDevices(instance.get());
    for (std::uint32_t i = 0; i < devices.size(); ++i) infos.push_back(queryDevice(devices[i], i));
    return infos;
}

Context::Context(const ContextOptions& options)
    : validation_(options.validation),
      printValidation_(options.printValidation),
      stagedTransfers_(options.stagedTransfers) {
    if (validation_ && !layerAvailable(kValidationLayer))
        throw Error(
            "validation requested but VK_LAYER_KHRONOS_validation is not installed "
            "(apt-get install vulkan-validationlayers)");
    const bool debugUtils = instanceExtensionAvailable(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    const std::size_t memoryFilesBefore = memoryFileCount();
    instance_ = Handle<VkInstance>(createInstance(validation_, debugUtils),
                                   [](VkInstance i) { vkDestroyInstance(i, nullptr); });
    VkInstance inst = instance_.get();

    if (debugUtils) {
        setObjectName_ = reinterpret_cast<PFN_vkSetDebugUtilsObjectNameEXT>(
            vkGetInstanceProcAddr(inst, "vkSetDebugUtilsObjectNameEXT"));
    }
    if (validation_ && debugUtils) {
        auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(inst, "vkCreateDebugUtilsMessengerEXT"));
        auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(inst, "vkDestroyDebugUtilsMessengerEXT"));
        VkDebugUtilsMessengerCreateInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
        info.messageSeverity =
            VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
        info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                           VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                           VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
        info.pfnUserCallback = &Context::messengerCallback;
        info.pUserData = this;
        VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
        if (create && destroy) {
            VK_CHECK(create(inst, &info, nullptr, &messenger));
            messenger_ = Handle<VkDebugUtilsMessengerEXT>(
                messenger, [inst, destroy](VkDebugUtilsMessengerEXT m) { destroy(inst, m, nullptr); });
        }
    }

    const auto devices = physicalDevices(inst);
    std::vector<DeviceInfo> infos;
    for (std::uint32_t i = 0; i < devices.size(); ++i) infos.push_back(queryDevice(devices[i], i));
    const std::uint32_t chosen = chooseDevice(infos, options.device);
    physical_ = devices[chosen];
    info_ = infos[chosen];
    vkGetPhysicalDeviceMemoryProperties(physical_, &memory_);

    std::uint32_t qCount = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(physical_, &qCount, nullptr);
    std::vector<VkQueueFamilyProperties> families(qCount);
    vkGetPhysicalDeviceQueueFamilyProperties(physical_, &qCount, families.data());
    for (std::uint32_t i = 0; i < qCount; ++i) {
        if (families[i].queueFlags & VK_QUEUE_COMPUTE_BIT) {
            queueFamily_ = i;
            break;
        }
    }
    const float priority = 1.0f;
    VkDeviceQueueCreateInfo queueInfo{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    queueInfo.queueFamilyIndex = queueFamily_;
    queueInfo.queueCount = 1;
    queueInfo.pQueuePriorities = &priority;

    VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
    f12.scalarBlockLayout = VK_TRUE;
    f12.bufferDeviceAddress = VK_TRUE;  // Poisson fields beyond maxStorageBufferRange
    VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
    features.pNext = &f12;
    VkDeviceCreateInfo deviceInfo{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    deviceInfo.pNext = &features;
    deviceInfo.queueCreateInfoCount = 1;
    deviceInfo.pQueueCreateInfos = &queueInfo;
    VkDevice device = VK_NULL_HANDLE;
    // Lavapipe crashes where it runs out of address space starting its threads or compiling a
    // kernel (util/address_space_limit.h): before the device, room for both; after it, for a kernel.
    if (info_.isCpu) addressSpaceLimit_ = addressSpaceLimit();
    if (auto problem = addressSpaceProblem(cpuDeviceStartBytes(cpuDeviceThreads()))) throw Error(*problem);
    VK_CHECK(vkCreateDevice(physical_, &deviceInfo, nullptr, &device));
    device_ = Handle<VkDevice>(device, [](VkDevice d) {
        vkDeviceWaitIdle(d);
        vkDestroyDevice(d, nullptr);
    });
    vkGetDeviceQueue(device, queueFamily_, 0, &queue_);
    // Before any allocation: a file-size limit would crash a driver that keeps device memory in
    // a memory file (util/file_size_limit.h).
    const std::size_t memoryFilesAfter = memoryFileCount();
    if (auto problem = memoryFileLimitProblem(
            info_.name, info_.isCpu,
            memoryFilesAfter > memoryFilesBefore ? memoryFilesAfter - memoryFilesBefore : 0, fileSizeLimit(),
            info_.deviceLocalHeapBytes))
        throw Error(*problem);
    if (auto problem = addressSpaceProblem(0)) throw Error(*problem);
    if (options.keepPipelines) pipelineCache_ = std::make_unique<PipelineCache>();
}

Context::~Context() = default;  // pipelineCache_ before device_

std::optional<std::string> Context::addressSpaceProblem(std::uint64_t aboutToTake) const {
    if (!addressSpaceLimit_) return std::nullopt;
    return addressSpaceLimitProblem(info_.name, true, addressSpaceLimit_, addressSpaceInUse() + aboutToTake,
                                    kCpuDeviceHeadroomBytes);
}

VkBool32 Context::messengerCallback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                    VkDebugUtilsMessageTypeFlagsEXT /*types*/,
                                    const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
    auto* self = static_cast<Context*>(user);
    const bool error = severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    if (error) ++self->validationErrors_;
    if (self->printValidation_)
        std::fprintf(stderr, "gdpt: validation %s: %s\n", error ? "error" : "warning",
                     data && data->pMessage ? data->pMessage : "(no message)");
    return VK_FALSE;
}

bool Context::hasMemoryType(std::uint32_t typeBits, VkMemoryPropertyFlags required) const {
    for (std::uint32_t i = 0; i < memory_.memoryTypeCount; ++i)
        if ((typeBits & (1u << i)) && (memory_.memoryTypes[i].propertyFlags & required) == required)
            return true;
    return false;
}

VkMemoryPropertyFlags Context::memoryTypeFlags(std::uint32_t index) const {
    GDPT_CHECK(index < memory_.memoryTypeCount);
    return memory_.memoryTypes[index].propertyFlags;
}

std::uint32_t Context::findMemoryType(std::uint32_t typeBits, VkMemoryPropertyFlags required) const {
    for (std::uint32_t i = 0; i < memory_.memoryTypeCount; ++i)
        if ((typeBits & (1u << i)) && (memory_.memoryTypes[i].propertyFlags & required) == required) return i;
    throw Error("no Vulkan memory type with flags " + std::to_string(required) + " on '" + info_.name + "'");
}

void Context::setName(VkObjectType type, std::uint64_t handle, const std::string& name) const {
    if (!setObjectName_ || handle == 0) return;
    VkDebugUtilsObjectNameInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT};
    info.objectType = type;
    info.objectHandle = handle;
    info.pObjectName = name.c_str();
    setObjectName_(device_.get(), &info);
}

namespace {
// Throws naming the limit when `bytes` exceeds it.
void checkLimit(std::uint64_t bytes, std::uint64_t limit, const char* kind, const char* limitName,
                const std::string& device, const std::string& what, const char* advice) {
    if (bytes > limit)
        throw Error(what + " needs " + kind + " of " + std::to_string(bytes >> 20) +
                    " MiB, more than the device limit " + limitName + " = " + std::to_string(limit >> 20) +
                    " MiB on '" + device + "'; " + advice);
}
}  // namespace

void Context::checkAllocationSize(std::uint64_t bytes, const std::string& what) const {
    checkLimit(bytes, info_.maxMemoryAllocationSize, "a buffer", "maxMemoryAllocationSize", info_.name, what,
               "use a smaller image");
}

void Context::checkStorageBufferSize(std::uint64_t bytes, const std::string& what) const {
    checkLimit(bytes, info_.maxStorageBufferRange, "a storage buffer", "maxStorageBufferRange", info_.name,
               what, "use a smaller scene or image");
}

void Context::checkTexelBufferSize(std::uint64_t texels, const std::string& what) const {
    if (texels > info_.maxTexelBufferElements)
        throw Error(what + " needs a texel buffer of " + std::to_string(texels) +
                    " texels, more than the device limit maxTexelBufferElements = " +
                    std::to_string(info_.maxTexelBufferElements) + " on '" + info_.name +
                    "'; use a smaller scene");
}

void Context::noteAllocation(std::uint64_t bytes) const {
    const std::uint64_t now = deviceBytesNow_.fetch_add(bytes) + bytes;
    std::uint64_t peak = deviceBytesPeak_.load();
    while (now > peak && !deviceBytesPeak_.compare_exchange_weak(peak, now)) {
    }
}

void Context::noteFree(std::uint64_t bytes) const {
    deviceBytesNow_.fetch_sub(bytes);
}

}  // namespace gdpt::vk
