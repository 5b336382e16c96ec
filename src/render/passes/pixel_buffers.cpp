// pixel_buffers.cpp — see pixel_buffers.h.
#include "render/passes/pixel_buffers.h"

#include "vk/context.h"

namespace gdpt {

void checkPixelBuffers(const vk::Context& ctx, std::uint32_t width, std::uint32_t height,
                       const std::vector<PixelBuffer>& buffers) {
    const std::uint64_t pixels = std::uint64_t{width} * height;
    const std::string image = " of a " + std::to_string(width) + "x" + std::to_string(height) + " image";
    for (const PixelBuffer& b : buffers) {
        ctx.checkStorageBufferSize(pixels * b.bytesPerPixel, b.name + image);
        ctx.checkAllocationSize(pixels * b.bytesPerPixel, b.name + image);
    }
}

}  // namespace gdpt
