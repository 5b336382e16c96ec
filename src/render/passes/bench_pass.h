// bench_pass.h — ray-throughput measurement pass (bench_rays.comp): primary rays or
// incoherent 4-segment diffuse paths, counting rays. Used by `gdpt bench` only.
#pragma once

#include <cstdint>

#include "render/passes/pt_pass.h"
#include "vk/buffer.h"
#include "vk/kernel.h"

namespace gdpt {

class SceneGpu;

class BenchRaysPass {
public:
    BenchRaysPass(const vk::Context& ctx, const SceneGpu& scene, WorkgroupSize wg = {});
    // Traces spp samples per pixel; incoherent = 4 diffuse segments per path. Returns
    // (rays traced, seconds of GPU time measured by timestamps, or wall time without them).
    struct Result {
        std::uint64_t rays = 0;
        double seconds = 0.0;     // wall time of the submission
        double cpuSeconds = 0.0;  // process CPU time (user + system) spent meanwhile: on a
                                  // CPU device this is the work done, insensitive to load
    };
    Result run(std::uint32_t spp, bool incoherent, std::uint32_t seed);

private:
    const vk::Context& ctx_;
    std::uint32_t width_, height_;
    vk::Kernel kernel_;
    vk::Buffer counters_;
};

}  // namespace gdpt
