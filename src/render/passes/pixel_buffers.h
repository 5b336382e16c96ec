// pixel_buffers.h — the device limits a sampling pass's per-pixel buffers must fit, checked
// before the pass creates any of them: an image too large for the device then fails with a
// message naming the buffer, its size and the limit (as the Poisson solver's fields do),
// instead of a failed vkCreateBuffer or vkAllocateMemory halfway through the set-up.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace gdpt {

namespace vk {
class Context;
}

// One buffer with `bytesPerPixel` bytes for every pixel; `name` as in "the path-tracing
// statistics".
struct PixelBuffer {
    std::string name;
    std::uint64_t bytesPerPixel;
};

struct Extent {
    std::uint32_t width = 0, height = 0;
};

// The largest image with the aspect ratio of width x height (as near as whole pixels allow)
// that has at most maxPixels pixels; width x height itself if it fits.
[[nodiscard]] Extent largestFittingImage(std::uint32_t width, std::uint32_t height, std::uint64_t maxPixels);

// Throws gdpt::Error for the first buffer of a width x height image that exceeds
// maxMemoryAllocationSize (each is one allocation). maxStorageBufferRange does not apply: the
// kernels reach these buffers through device addresses (shaders/lib/pixel_buffers.glsl). The
// heap is not checked: the per-buffer limit binds first on the devices seen (lavapipe
// overcommits its heap), and a sum would have to include the Poisson solver's fields and the
// scene to mean anything. The message names the largest image of the same shape that every
// buffer allows.
void checkPixelBuffers(const vk::Context& ctx, std::uint32_t width, std::uint32_t height,
                       const std::vector<PixelBuffer>& buffers);

// The same as a member initialised before a pass's buffers, so that the check runs first.
struct PixelBuffersChecked {
    PixelBuffersChecked(const vk::Context& ctx, std::uint32_t width, std::uint32_t height,
                        const std::vector<PixelBuffer>& buffers) {
        checkPixelBuffers(ctx, width, height, buffers);
    }
};

}  // namespace gdpt
