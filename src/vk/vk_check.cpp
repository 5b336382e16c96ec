#include "vk/vk_check.h"

namespace gdpt {

const char* vkResultName(VkResult result) {
    switch (result) {
#define GDPT_CASE(x) \
    case x:          \
        return #x;
        GDPT_CASE(VK_SUCCESS)
        GDPT_CASE(VK_NOT_READY)
        GDPT_CASE(VK_TIMEOUT)
        GDPT_CASE(VK_EVENT_SET)
        GDPT_CASE(VK_EVENT_RESET)
        GDPT_CASE(VK_INCOMPLETE)
        GDPT_CASE(VK_ERROR_OUT_OF_HOST_MEMORY)
        GDPT_CASE(VK_ERROR_OUT_OF_DEVICE_MEMORY)
        GDPT_CASE(VK_ERROR_INITIALIZATION_FAILED)
        GDPT_CASE(VK_ERROR_DEVICE_LOST)
        GDPT_CASE(VK_ERROR_MEMORY_MAP_FAILED)
        GDPT_CASE(VK_ERROR_LAYER_NOT_PRESENT)
        GDPT_CASE(VK_ERROR_EXTENSION_NOT_PRESENT)
        GDPT_CASE(VK_ERROR_FEATURE_NOT_PRESENT)
        GDPT_CASE(VK_ERROR_INCOMPATIBLE_DRIVER)
        GDPT_CASE(VK_ERROR_TOO_MANY_OBJECTS)
        GDPT_CASE(VK_ERROR_FORMAT_NOT_SUPPORTED)
        GDPT_CASE(VK_ERROR_FRAGMENTED_POOL)
        GDPT_CASE(VK_ERROR_UNKNOWN)
        GDPT_CASE(VK_ERROR_OUT_OF_POOL_MEMORY)
        GDPT_CASE(VK_ERROR_INVALID_EXTERNAL_HANDLE)
        GDPT_CASE(VK_ERROR_FRAGMENTATION)
        GDPT_CASE(VK_ERROR_INVALID_OPAQUE_CAPTURE_ADDRESS)
#undef GDPT_CASE
        default:
            return "VK_RESULT_UNKNOWN";
    }
}

void throwVulkanError(VkResult result, const char* expr, const char* file, int line) {
    std::string msg = std::string("Vulkan call failed with ") + vkResultName(result) + ": " + expr + " (" +
                      file + ":" + std::to_string(line) + ")";
    if (result == VK_ERROR_OUT_OF_DEVICE_MEMORY || result == VK_ERROR_OUT_OF_HOST_MEMORY)
        msg += "; the device ran out of memory (try a smaller image or scene)";
    throw VulkanError(result, msg);
}

}  // namespace gdpt
