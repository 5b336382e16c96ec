// pipeline_cache.h — compute pipelines kept for a context's life and shared by every Kernel of
// the same description (SPIR-V, bindings, push constants, specialisation constants), when the
// context is made with ContextOptions::keepPipelines. A sequence of frames then compiles each
// kernel variant once instead of once per frame: lavapipe spends 0.3-0.5 s of a 256x256 G-PT
// frame's set-up in vkCreateComputePipelines (docs/animation.md). Lavapipe's own
// VkPipelineCache does not keep compiled code in Mesa 22.3, so the cache is gdpt's.
#pragma once

#include <vulkan/vulkan.h>

#include <functional>
#include <future>
#include <map>
#include <mutex>
#include <string>

namespace gdpt::vk {

class PipelineCache {
public:
    PipelineCache() = default;
    // Waits for the creations still running, then releases every pipeline (before the device
    // goes: the context declares the cache after its device).
    ~PipelineCache();
    PipelineCache(const PipelineCache&) = delete;
    PipelineCache& operator=(const PipelineCache&) = delete;

    // How to create a pipeline: the creation (started, e.g. on a worker thread) and what
    // destroys the pipeline and whatever its creation used when the cache goes (not called if
    // the creation failed).
    struct Creation {
        std::shared_future<VkPipeline> pipeline;
        std::function<void(VkPipeline)> release;
    };
    // The pipeline of `key`: the one created before (a hit), else the one `create` starts
    // (called under the cache's lock, so it must only start the work).
    [[nodiscard]] std::shared_future<VkPipeline> get(const std::string& key,
                                                     const std::function<Creation()>& create);
    [[nodiscard]] std::size_t size() const;
    // Kernels that found their pipeline here instead of creating it.
    [[nodiscard]] std::size_t hits() const;

private:
    mutable std::mutex mutex_;
    std::map<std::string, Creation> entries_;
    std::size_t hits_ = 0;
};

}  // namespace gdpt::vk
