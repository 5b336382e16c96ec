#include "vk/timing.h"

#include "vk/context.h"
#include "vk/vk_check.h"

namespace gdpt::vk {

GpuTimer::GpuTimer(const Context& ctx, std::uint32_t maxScopesPerSubmit)
    : ctx_(ctx), capacity_(2 * maxScopesPerSubmit) {
    std::uint32_t count = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(ctx.physicalDevice(), &count, nullptr);
    std::vector<VkQueueFamilyProperties> families(count);
    vkGetPhysicalDeviceQueueFamilyProperties(ctx.physicalDevice(), &count, families.data());
    const std::uint32_t bits = families[ctx.queueFamily()].timestampValidBits;
    if (bits == 0 || ctx.info().timestampPeriodNs <= 0.0f) return;
    validMask_ = bits >= 64 ? ~0ull : ((1ull << bits) - 1);
    periodNs_ = ctx.info().timestampPeriodNs;
    VkQueryPoolCreateInfo info{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    info.queryType = VK_QUERY_TYPE_TIMESTAMP;
    info.queryCount = capacity_;
    VkQueryPool pool = VK_NULL_HANDLE;
    VkDevice device = ctx.device();
    VK_CHECK(vkCreateQueryPool(device, &info, nullptr, &pool));
    pool_ = Handle<VkQueryPool>(pool, [device](VkQueryPool p) { vkDestroyQueryPool(device, p, nullptr); });
    enabled_ = true;
}

void GpuTimer::reset(VkCommandBuffer cmd) {
    names_.clear();
    used_ = 0;
    if (enabled_) vkCmdResetQueryPool(cmd, pool_.get(), 0, capacity_);
}

void GpuTimer::begin(VkCommandBuffer cmd, const std::string& name) {
    if (!enabled_ || used_ + 2 > capacity_) return;
    names_.push_back(name);
    vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, pool_.get(), used_++);
}

void GpuTimer::end(VkCommandBuffer cmd) {
    if (!enabled_ || used_ % 2 == 0) return;  // begin() was skipped (pool full)
    vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, pool_.get(), used_++);
}

void GpuTimer::collect() {
    if (!enabled_ || used_ == 0) return;
    std::vector<std::uint64_t> stamps(used_);
    VK_CHECK(vkGetQueryPoolResults(ctx_.device(), pool_.get(), 0, used_,
                                   stamps.size() * sizeof(std::uint64_t), stamps.data(),
                                   sizeof(std::uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
    for (std::size_t i = 0; i + 1 < stamps.size(); i += 2) {
        const std::uint64_t t0 = stamps[i] & validMask_;
        const std::uint64_t t1 = stamps[i + 1] & validMask_;
        auto& k = totals_[names_[i / 2]];
        k.count += 1;
        k.totalMs += static_cast<double>((t1 - t0) & validMask_) * periodNs_ * 1e-6;
    }
    names_.clear();
    used_ = 0;
}

double GpuTimer::totalMs() const {
    double sum = 0.0;
    for (const auto& [name, t] : totals_) sum += t.totalMs;
    return sum;
}

}  // namespace gdpt::vk
