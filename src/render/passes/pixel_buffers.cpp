// pixel_buffers.cpp — see pixel_buffers.h.
#include "render/passes/pixel_buffers.h"

#include <algorithm>
#include <cmath>

#include "util/error.h"
#include "util/memory.h"
#include "vk/context.h"

namespace gdpt {

Extent largestFittingImage(std::uint32_t width, std::uint32_t height, std::uint64_t maxPixels) {
    const std::uint64_t pixels = std::uint64_t{width} * height;
    if (pixels <= maxPixels) return {width, height};
    // Scale both sides by sqrt(maxPixels / pixels), then shrink the longer side until it fits.
    const double s = std::sqrt(double(maxPixels) / double(pixels));
    auto w = static_cast<std::uint32_t>(std::max(1.0, std::floor(width * s)));
    auto h = static_cast<std::uint32_t>(std::max(1.0, std::floor(height * s)));
    while (std::uint64_t{w} * h > maxPixels && (w > 1 || h > 1)) {
        const bool tooWide = std::uint64_t{w} * height >= std::uint64_t{h} * width;
        if ((tooWide && w > 1) || h == 1)
            --w;
        else
            --h;
    }
    return {w, h};
}

void checkPixelBuffers(const vk::Context& ctx, std::uint32_t width, std::uint32_t height,
                       const std::vector<PixelBuffer>& buffers) {
    const std::uint64_t pixels = std::uint64_t{width} * height;
    const std::string image = " of a " + std::to_string(width) + "x" + std::to_string(height) + " image";
    // The most pixels every buffer allows (each is one allocation, reached by its address).
    const std::uint64_t perBuffer = ctx.info().maxMemoryAllocationSize;
    std::uint64_t maxPixels = ~std::uint64_t{0};
    for (const PixelBuffer& b : buffers) maxPixels = std::min(maxPixels, perBuffer / b.bytesPerPixel);
    for (const PixelBuffer& b : buffers) {
        try {
            ctx.checkAllocationSize(pixels * b.bytesPerPixel, b.name + image);
        } catch (const Error& e) {
            // Say what would fit: the largest image of the same shape.
            const Extent fit = largestFittingImage(width, height, maxPixels);
            throw Error(std::string(e.what()) + " (the largest image of this shape that fits is " +
                        std::to_string(fit.width) + "x" + std::to_string(fit.height) + ")");
        }
    }
}

std::uint64_t imageBytesPerMegapixel(const std::string& method) {
    if (method == "pt") return std::uint64_t{170} << 20;
    if (method == "gpt") return std::uint64_t{850} << 20;
    return 0;
}

std::string imageMemoryRefusal(const std::string& method, std::uint32_t width, std::uint32_t height,
                               std::uint64_t memory) {
    const std::uint64_t perMegapixel = imageBytesPerMegapixel(method);
    if (perMegapixel == 0 || memory == 0) return "";
    // Whole pixels that fit: memory / bytes per pixel, with bytes per pixel = perMegapixel / 1e6.
    const auto maxPixels = static_cast<std::uint64_t>(double(memory) / double(perMegapixel) * 1e6);
    const std::uint64_t pixels = std::uint64_t{width} * height;
    if (pixels <= maxPixels) return "";
    const Extent fit = largestFittingImage(width, height, maxPixels);
    const double needed = double(pixels) * 1e-6 * double(perMegapixel);
    return "a " + std::to_string(width) + "x" + std::to_string(height) + " " +
           (method == "gpt" ? "G-PT" : "PT") + " render needs about " +
           memoryText(static_cast<std::uint64_t>(needed)) + " of memory (" + memoryText(perMegapixel) +
           " per megapixel), more than " + availableMemoryText(memory) +
           ": the largest image of this shape that fits is " + std::to_string(fit.width) + "x" +
           std::to_string(fit.height);
}

}  // namespace gdpt
