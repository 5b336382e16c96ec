// pipeline_cache.cpp — see pipeline_cache.h.
#include "vk/pipeline_cache.h"

namespace gdpt::vk {

PipelineCache::~PipelineCache() {
    for (auto& [key, entry] : entries_) {
        try {
            const VkPipeline pipeline = entry.pipeline.get();
            if (entry.release) entry.release(pipeline);
        } catch (...) {
            // A failed creation left nothing to destroy; its error went to the kernels.
        }
    }
}

std::shared_future<VkPipeline> PipelineCache::get(const std::string& key,
                                                  const std::function<Creation()>& create) {
    const std::lock_guard<std::mutex> lock(mutex_);
    const auto it = entries_.find(key);
    if (it != entries_.end()) {
        ++hits_;
        return it->second.pipeline;
    }
    return entries_.emplace(key, create()).first->second.pipeline;
}

std::size_t PipelineCache::size() const {
    const std::lock_guard<std::mutex> lock(mutex_);
    return entries_.size();
}

std::size_t PipelineCache::hits() const {
    const std::lock_guard<std::mutex> lock(mutex_);
    return hits_;
}

}  // namespace gdpt::vk
