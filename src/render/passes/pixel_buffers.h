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
// device heap is not checked here (lavapipe overcommits it): the whole render, the Poisson
// solver's fields and the host's copies included, is checked against the machine's memory by
// imageMemoryRefusal. The message names the largest image of the same shape that every
// buffer allows.
void checkPixelBuffers(const vk::Context& ctx, std::uint32_t width, std::uint32_t height,
                       const std::vector<PixelBuffer>& buffers);

// Host memory a render takes per megapixel of its image, by method (on a CPU device the
// device's memory is the host's): PT 151-160 MiB, G-PT with its L1 reconstruction 810 MiB,
// measured at 3840x2160 and 7680x4320 (bench/RESULTS.md, "Large renders"), rounded up; 0 for a
// method not measured at such sizes (not checked).
[[nodiscard]] std::uint64_t imageBytesPerMegapixel(const std::string& method);

// Why a `method` render of width x height would not fit `memory` bytes, naming the largest
// image of the same shape that fits; "" if it fits (or is not checked).
[[nodiscard]] std::string imageMemoryRefusal(const std::string& method, std::uint32_t width,
                                             std::uint32_t height, std::uint64_t memory);

// The same as a member initialised before a pass's buffers, so that the check runs first.
struct PixelBuffersChecked {
    PixelBuffersChecked(const vk::Context& ctx, std::uint32_t width, std::uint32_t height,
                        const std::vector<PixelBuffer>& buffers) {
        checkPixelBuffers(ctx, width, height, buffers);
    }
};

}  // namespace gdpt
