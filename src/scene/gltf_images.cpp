// gltf_images.cpp — image decoding for the glTF loader and conversion to linear float
// textures.
//
// Debian's libtinygltf is built with its own stb_image loader, but we register this
// loader instead so that (a) the decoder and its failure messages are ours (the message
// names the image), (b) 16-bit PNGs keep their precision, and (c) absurd image sizes are
// refused before allocation. stb_image comes from libstb (<stb/stb_image.h>).
#include <stb/stb_image.h>

#include <array>
#include <cmath>
#include <cstring>
#include <limits>

#include "scene/gltf_internal.h"
#include "util/decode_failure.h"

namespace gdpt::gltf {
namespace {

// sRGB electro-optical transfer function (IEC 61966-2-1), as glTF 2.0 §3.9.2 requires
// for baseColorTexture and emissiveTexture.
float srgbToLinear(float c) {
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

}  // namespace

bool decodeImage(tinygltf::Image* image, int imageIndex, std::string* err, std::string* /*warn*/,
                 int /*reqWidth*/, int /*reqHeight*/, const unsigned char* bytes, int size, void* userData) {
    const std::string label = "image " + std::to_string(imageIndex) +
                              (image->name.empty() ? std::string() : " '" + image->name + "'");
    auto fail = [&](const std::string& why) {
        if (err) *err += label + ": " + why + "\n";
        return false;
    };
    // tinygltf 2.7.0 hands over &buffer.data[view.byteOffset] and view.byteLength for images
    // stored in a bufferView without checking them against the buffer (found by the
    // mutation test), so check here, before reading a byte. userData is the Model being
    // filled; its buffers and bufferViews are complete when images are decoded.
    auto* decode = static_cast<ImageDecodeContext*>(userData);
    const tinygltf::Model* model = decode ? decode->model : nullptr;
    if (model != nullptr && image->bufferView >= 0) {
        const auto view = static_cast<std::size_t>(image->bufferView);
        if (view >= model->bufferViews.size()) return fail("bufferView out of range");
        const tinygltf::BufferView& bv = model->bufferViews[view];
        if (bv.buffer < 0 || static_cast<std::size_t>(bv.buffer) >= model->buffers.size())
            return fail("bufferView " + std::to_string(view) + ": buffer out of range");
        const std::uint64_t end = std::uint64_t(bv.byteOffset) + std::uint64_t(bv.byteLength);
        if (end < bv.byteOffset || end > model->buffers[static_cast<std::size_t>(bv.buffer)].data.size() ||
            bv.byteLength > std::uint64_t(std::numeric_limits<int>::max()))
            return fail("bufferView " + std::to_string(view) + " lies outside its buffer");
    }
    if (bytes == nullptr || size <= 0) return fail("no image data");
    int w = 0, h = 0, comp = 0;
    if (!stbi_info_from_memory(bytes, size, &w, &h, &comp))
        return fail(
            "cannot decode: " + decodeFailure(bytes, static_cast<std::size_t>(size), stbi_failure_reason()) +
            "; glTF textures are PNG or JPEG");
    if (w <= 0 || h <= 0 || std::uint64_t(w) * std::uint64_t(h) > kMaxImagePixels)
        return fail("size " + std::to_string(w) + "x" + std::to_string(h) + " is out of range");

    const bool sixteen = stbi_is_16_bit_from_memory(bytes, size) != 0;
    const std::uint64_t needed =
        std::uint64_t(w) * std::uint64_t(h) * ((sixteen ? 8u : 4u) + sizeof(glm::vec4));
    if (decode && needed > decode->bytesLeft)
        return fail("its " + std::to_string(w) + "x" + std::to_string(h) + " pixels need " +
                    std::to_string(needed >> 20) + " MiB decoded, more than the " +
                    std::to_string(decode->bytesLeft >> 20) + " MiB of the memory budget left for images");
    if (decode) decode->bytesLeft -= needed;
    void* pixels = sixteen ? static_cast<void*>(stbi_load_16_from_memory(bytes, size, &w, &h, &comp, 4))
                           : static_cast<void*>(stbi_load_from_memory(bytes, size, &w, &h, &comp, 4));
    if (pixels == nullptr)
        return fail("cannot decode: " +
                    decodeFailure(bytes, static_cast<std::size_t>(size), stbi_failure_reason()));
    const std::size_t bytesPerChannel = sixteen ? 2 : 1;
    const std::size_t total = std::size_t(w) * std::size_t(h) * 4 * bytesPerChannel;
    image->width = w;
    image->height = h;
    image->component = 4;  // always expanded to RGBA
    image->bits = sixteen ? 16 : 8;
    image->pixel_type =
        sixteen ? TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT : TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
    image->image.resize(total);
    std::memcpy(image->image.data(), pixels, total);
    stbi_image_free(pixels);
    return true;
}

Texture imageToTexture(const tinygltf::Image& image, bool srgb) {
    Texture tex;
    tex.width = image.width;
    tex.height = image.height;
    const std::size_t n = std::size_t(image.width) * std::size_t(image.height);
    const int comp = image.component;
    const bool sixteen = image.bits == 16;
    const std::size_t bpc = sixteen ? 2 : 1;
    if (comp < 1 || comp > 4 || (image.bits != 8 && image.bits != 16) ||
        image.image.size() < n * std::size_t(comp) * bpc)
        throw Error("image '" + image.name + "' has an unexpected pixel layout");

    // 8-bit data goes through a 256-entry table; 16-bit data is converted per texel.
    std::array<float, 256> lut{};
    for (int i = 0; i < 256; ++i) {
        const float c = static_cast<float>(i) / 255.0f;
        lut[static_cast<std::size_t>(i)] = srgb ? srgbToLinear(c) : c;
    }
    auto channel = [&](std::size_t texel, int c) -> float {
        const std::size_t at = (texel * std::size_t(comp) + std::size_t(c)) * bpc;
        if (!sixteen) return static_cast<float>(image.image[at]) / 255.0f;
        std::uint16_t v;
        std::memcpy(&v, &image.image[at], 2);
        return static_cast<float>(v) / 65535.0f;
    };
    tex.texels.resize(n);
    // Row 0 of the decoded image is its top row, which is what Texture promises (glTF uv
    // (0,0) is the top-left corner, §3.8.4), so no flip is needed.
    for (std::size_t i = 0; i < n; ++i) {
        glm::vec4 v(0.0f, 0.0f, 0.0f, 1.0f);
        // Grey and grey+alpha images replicate the grey channel (stb's convention).
        for (int c = 0; c < 3; ++c) {
            const int src = comp >= 3 ? c : 0;
            if (!sixteen) {
                const std::size_t at = i * std::size_t(comp) + std::size_t(src);
                v[c] = lut[image.image[at]];
            } else {
                const float x = channel(i, src);
                v[c] = srgb ? srgbToLinear(x) : x;
            }
        }
        if (comp == 2 || comp == 4) v.a = channel(i, comp - 1);  // alpha is always linear
        tex.texels[i] = v;
    }
    return tex;
}

}  // namespace gdpt::gltf
