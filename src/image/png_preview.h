// png_preview.h — 8-bit sRGB PNG previews of linear HDR images, and reading of LDR images
// (PNG, JPEG, ... via stb_image) back into linear float for gradient-domain editing.
#pragma once

#include <cstdint>
#include <string>

#include "image/image.h"

namespace gdpt {

enum class ToneMap {
    Clamp,     // v -> min(v, 1)
    Reinhard,  // v -> v / (1 + v), per channel (Reinhard et al. 2002, eq. 3 applied per channel)
};

struct PreviewOptions {
    float exposure = 1.0f;  // linear scale applied before tone mapping (2^stops)
    ToneMap toneMap = ToneMap::Clamp;
};

// sRGB OETF (IEC 61966-2-1): linear [0,1] -> encoded [0,1].
[[nodiscard]] double linearToSrgb(double linear);
// Inverse sRGB OETF: encoded [0,1] -> linear.
[[nodiscard]] double srgbToLinear(double encoded);

// One linear value -> 8-bit sRGB code: exposure, tone map, clamp to [0,1], OETF, round to
// nearest. NaN and negative values map to 0, +inf to 255 (Clamp) or 255 (Reinhard limit).
[[nodiscard]] std::uint8_t previewCode(float linear, const PreviewOptions& options = {});

class StagedFile;

// Writes an RGB8 PNG preview of `image` (staged in a unique temporary file and renamed into
// place; every write checked). Throws gdpt::Error naming the file and the OS's reason.
void writePngPreview(const std::string& path, const Image& image, const PreviewOptions& options = {});

// Writes the preview into a staged file of an OutputSet (util/output_files.h); the caller commits.
void writePngPreview(const StagedFile& file, const Image& image, const PreviewOptions& options = {});

// Reads an 8- or 16-bit PNG (gray, gray+alpha, RGB or RGBA; alpha dropped) and converts it
// to linear float with the exact inverse sRGB OETF. Throws gdpt::Error naming the file, with
// a one-line plain-text reason ("the PNG data is truncated (the file ends early)", "corrupt
// PNG data (bad zlib header)", ...).
Image readPng(const std::string& path);

// Reads any supported image: .exr (its default layer, or its first layer if it has no
// unnamed one) or anything stb_image decodes (PNG, JPEG, BMP, TGA, ...; treated as sRGB).
Image readImage(const std::string& path);

}  // namespace gdpt
