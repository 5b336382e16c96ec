// finite_check.h — finding values an image layer must not hold: NaN or ±Inf in any channel,
// and (for a variance) negative values. The commands use the scans to say what they found in
// which layer or file and what they did with it, and checkFinite as the last guard before
// writing: a non-finite value never reaches an output file silently.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "image/exr_io.h"
#include "image/image.h"

namespace gdpt {

// The pixels of an image that some test flagged (in any channel).
struct PixelScan {
    std::size_t pixels = 0;  // flagged pixels
    std::size_t total = 0;   // pixels scanned
    int firstX = -1;         // the first flagged pixel in row-major order (-1: none)
    int firstY = -1;
    [[nodiscard]] bool any() const { return pixels > 0; }
    [[nodiscard]] bool all() const { return total > 0 && pixels == total; }
    // "3 of 64 pixels (the first at (5, 0))".
    [[nodiscard]] std::string describe() const;
};

// Pixels with a NaN or infinite value in some channel.
PixelScan scanNonFinite(const Image& image);
// Pixels with a finite negative value in some channel (an invalid variance).
PixelScan scanNegative(const Image& image);

// Throws gdpt::Error naming `path`, the first layer with a non-finite value (the default
// layer "" as "the image"), how many pixels and the first of them, so that nothing is written.
void checkFinite(const std::vector<NamedLayer>& layers, const std::string& path);

}  // namespace gdpt
