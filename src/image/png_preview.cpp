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

namespace {

// The format a file's first bytes announce (for messages): "PNG", "JPEG" or "image".
std::string formatOf(const std::string& path) {
    unsigned char head[8] = {};
    std::FILE* f = std::fopen(path.c_str(), "rb");
    const std::size_t n = f ? std::fread(head, 1, sizeof head, f) : 0;
    if (f) std::fclose(f);
    if (n == 8 && std::memcmp(head, "\x89PNG\r\n\x1a\n", 8) == 0) return "PNG";
    if (n >= 3 && head[0] == 0xff && head[1] == 0xd8 && head[2] == 0xff) return "JPEG";
    return "image";
}

// Whether a PNG file ends before its IEND chunk: walks the chunks (4-byte big-endian data
// length, 4-byte type, data, 4-byte CRC; PNG specification, ISO/IEC 15948 §5.3) from the
// 8-byte signature. stb_image reads past the end as zeros, so a cut file otherwise fails
// with whatever those zeros mean ("first not IHDR", a garbage chunk type).
bool pngEndsEarly(const std::string& path) {
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) return false;
    std::vector<unsigned char> bytes;
    unsigned char buf[65536];
    for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, f)) > 0;) bytes.insert(bytes.end(), buf, buf + n);
    std::fclose(f);
    std::uint64_t pos = 8;
    while (pos + 8 <= bytes.size()) {
        const unsigned char* c = bytes.data() + pos;
        const std::uint64_t length = (std::uint64_t{c[0]} << 24) | (std::uint64_t{c[1]} << 16) |
                                     (std::uint64_t{c[2]} << 8) | std::uint64_t{c[3]};
        if (std::memcmp(c + 4, "IEND", 4) == 0) return false;
        pos += 12 + length;
    }
    return true;
}

// A one-line, plain-text reason for a failed stb_image decode. stb's reasons are terse codes
// ("outofdata"), and its reason for an unknown PNG chunk starts with the chunk's four type
// bytes, raw: a corrupt file printed binary bytes, or only what preceded a zero byte ("IDA",
// or nothing at all). So the codes that matter are translated, and a reason that is not
// plain lower-case text is not shown.
std::string decodeFailure(const std::string& path, const char* stbReason) {
    const std::string reason = stbReason ? stbReason : "";
    const std::string format = formatOf(path);
    if (reason == "can't fopen") return "cannot open the file";
    if (reason == "unknown image type")
        return format == "image" ? "not an image format gdpt reads (PNG, JPEG, BMP, TGA, ...)"
                                 : "corrupt " + format + " header";
    if (reason == "outofdata" || reason == "unexpected end" || reason == "read past buffer" ||
        (format == "PNG" && pngEndsEarly(path)))
        return "the " + format + " data is truncated (the file ends early)";
    if (reason == "outofmem") return "out of memory while decoding";
    if (reason.find("too large") != std::string::npos) return "the image is too large";
    // Plain text: ASCII letters, digits, spaces and a little punctuation; at least 5
    // characters (a chunk-type fragment is shorter) and not the unknown-chunk text.
    bool plain = reason.size() >= 5 && reason.find("chunk not known") == std::string::npos;
    for (char ch : reason)
        plain =
            plain && (std::isalnum(static_cast<unsigned char>(ch)) || ch == ' ' || ch == '-' || ch == '/');
    return "corrupt " + format + " data" + (plain ? " (" + reason + ")" : std::string());
}

}  // namespace

Image readPng(const std::string& path) {
    int w = 0, h = 0, components = 0;
    const bool sixteen = stbi_is_16_bit(path.c_str()) != 0;
    // Ask for 3 components: stb expands gray and drops alpha.
    std::unique_ptr<void, void (*)(void*)> pixels(
        sixteen ? static_cast<void*>(stbi_load_16(path.c_str(), &w, &h, &components, 3))
                : static_cast<void*>(stbi_load(path.c_str(), &w, &h, &components, 3)),
        stbi_image_free);
    if (!pixels) throw Error(path + ": cannot read image: " + decodeFailure(path, stbi_failure_reason()));
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
