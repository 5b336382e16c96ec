// vk_check.h — VK_CHECK: every Vulkan call goes through it. A failure throws
// gdpt::VulkanError carrying the VkResult name, the expression and file:line; it is
// never assert-only, so release builds report Vulkan failures too.
#pragma once

#include <vulkan/vulkan.h>

#include <string>

#include "util/error.h"

namespace gdpt {

// Name of a VkResult ("VK_ERROR_DEVICE_LOST"); vk_enum_string_helper.h is not packaged.
const char* vkResultName(VkResult result);

class VulkanError : public Error {
public:
    VulkanError(VkResult result, const std::string& message) : Error(message), result_(result) {}
    [[nodiscard]] VkResult result() const { return result_; }

private:
    VkResult result_;
};

[[noreturn]] void throwVulkanError(VkResult result, const char* expr, const char* file, int line);

}  // namespace gdpt

#define VK_CHECK(expr)                                                                                   \
    do {                                                                                                 \
        const VkResult gdptResult_ = (expr);                                                             \
        if (gdptResult_ != VK_SUCCESS) ::gdpt::throwVulkanError(gdptResult_, #expr, __FILE__, __LINE__); \
    } while (0)
