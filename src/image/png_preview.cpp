// png_preview.cpp — sRGB PNG previews via stb_image_write, LDR input via stb_image.
// libstb.so (Debian libstb-dev) carries the stb implementations: no IMPLEMENTATION macros.
#include "image/png_preview.h"

#include <stb/stb_image.h>
#include <stb/stb_image_write.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <vector>

#include "image/atomic_write.h"
#include "image/exr_io.h"
#include "util/decode_failure.h"
#include "util/error.h"
#include "util/output_files.h"

namespace gdpt {

double linearToSrgb(double linear) {
    // IEC 61966-2-1: linear segment below 0.0031308, power 1/2.4 segment above.
    if (linear <= 0.0031308) return 12.92 * linear;
    return 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
}

double srgbToLinear(double encoded) {
    if (encoded <= 0.04045) return encoded / 12.92;
    return std::pow((encoded + 0.055) / 1.055, 2.4);
}

std::uint8_t previewCode(float linear, const PreviewOptions& options) {
    double v = static_cast<double>(linear) * static_cast<double>(options.exposure);
    if (!(v > 0.0)) return 0;  // negative, zero and NaN
    if (options.toneMap == ToneMap::Reinhard) v = std::isinf(v) ? 1.0 : v / (1.0 + v);
    v = std::min(v, 1.0);
    return static_cast<std::uint8_t>(std::lround(255.0 * linearToSrgb(v)));
}

namespace {

// The PNG file's bytes (stb_image_write encodes into memory; the caller writes them with
// every write checked, which stbi_write_png does not do).
std::vector<unsigned char> encodePng(const std::string& path, const Image& image,
                                     const PreviewOptions& options) {
    if (image.empty()) throw Error(path + ": cannot write an empty image");
    const int w = image.width();
    const int h = image.height();
    std::vector<std::uint8_t> rgb(image.pixelCount() * 3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c)
                rgb[image.index(x, y) * 3 + c] = previewCode(image.at(x, y, c), options);
    std::vector<unsigned char> png;
    const auto append = [](void* context, void* data, int size) {
        auto* out = static_cast<std::vector<unsigned char>*>(context);
        const auto* bytes = static_cast<const unsigned char*>(data);
        out->insert(out->end(), bytes, bytes + size);
    };
    if (stbi_write_png_to_func(append, &png, w, h, 3, rgb.data(), w * 3) == 0 || png.empty())
        throw Error(path + ": cannot encode the PNG");
    return png;
}

}  // namespace

void writePngPreview(const std::string& path, const Image& image, const PreviewOptions& options) {
    const std::vector<unsigned char> png = encodePng(path, image, options);
    writeFileAtomically(path,
                        [&](const std::string& tmpPath) { writeBytes(tmpPath, png.data(), png.size()); });
}

void writePngPreview(const StagedFile& file, const Image& image, const PreviewOptions& options) {
    const std::vector<unsigned char> png = encodePng(file.path(), image, options);
    writeStaged(file, [&](const std::string& tmpPath) { writeBytes(tmpPath, png.data(), png.size()); });
}

Image readPng(const std::string& path) {
    int w = 0, h = 0, components = 0;
    const bool sixteen = stbi_is_16_bit(path.c_str()) != 0;
    // Ask for 3 components: stb expands gray and drops alpha.
    std::unique_ptr<void, void (*)(void*)> pixels(
        sixteen ? static_cast<void*>(stbi_load_16(path.c_str(), &w, &h, &components, 3))
                : static_cast<void*>(stbi_load(path.c_str(), &w, &h, &components, 3)),
        stbi_image_free);
    if (!pixels) {
        const char* reason = stbi_failure_reason();
        std::vector<unsigned char> bytes;  // the reason looks at the file's bytes
        if (std::FILE* f = std::fopen(path.c_str(), "rb")) {
            unsigned char buf[65536];
            for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, f)) > 0;)
                bytes.insert(bytes.end(), buf, buf + n);
            std::fclose(f);
        }
        throw Error(path + ": cannot read image: " + decodeFailure(bytes.data(), bytes.size(), reason));
    }
    Image image(w, h);
    const double maxCode = sixteen ? 65535.0 : 255.0;
    // Precomputing a table would be faster for 8 bit; readImage is not on a hot path.
    for (std::size_t i = 0; i < image.pixelCount(); ++i)
        for (int c = 0; c < 3; ++c) {
            const double code = sixteen ? static_cast<const std::uint16_t*>(pixels.get())[i * 3 + c]
                                        : static_cast<const std::uint8_t*>(pixels.get())[i * 3 + c];
            image.plane(c)[i] = static_cast<float>(srgbToLinear(code / maxCode));
        }
    return image;
}

Image readImage(const std::string& path) {
    std::string ext = path.size() >= 4 ? path.substr(path.size() - 4) : "";
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
    if (ext != ".exr") return readPng(path);
    std::vector<NamedLayer> layers = readExr(path);  // sorted: "" first if present
    return std::move(layers.front().image);
}

}  // namespace gdpt
