// finite_check.cpp — see finite_check.h.
#include "image/finite_check.h"

#include <cmath>

#include "util/error.h"

namespace gdpt {
namespace {

template <typename Flag>
PixelScan scan(const Image& image, Flag flagged) {
    PixelScan s;
    s.total = image.pixelCount();
    for (int y = 0; y < image.height(); ++y)
        for (int x = 0; x < image.width(); ++x) {
            bool bad = false;
            for (int c = 0; c < 3; ++c) bad = bad || flagged(image.at(x, y, c));
            if (!bad) continue;
            if (s.pixels++ == 0) {
                s.firstX = x;
                s.firstY = y;
            }
        }
    return s;
}

}  // namespace

std::string PixelScan::describe() const {
    std::string text = std::to_string(pixels) + " of " + std::to_string(total) + " pixels";
    if (pixels > 0)
        text += " (the first at (" + std::to_string(firstX) + ", " + std::to_string(firstY) + "))";
    return text;
}

PixelScan scanNonFinite(const Image& image) {
    return scan(image, [](float v) { return !std::isfinite(v); });
}

PixelScan scanNegative(const Image& image) {
    return scan(image, [](float v) { return std::isfinite(v) && v < 0.0f; });
}

void checkFinite(const std::vector<NamedLayer>& layers, const std::string& path) {
    for (const NamedLayer& layer : layers) {
        const PixelScan s = scanNonFinite(layer.image);
        if (s.any())
            throw Error(path + ": not written: " +
                        (layer.name.empty() ? std::string("the image") : "layer '" + layer.name + "'") +
                        " has NaN or infinite values in " + s.describe() +
                        " (an input out of float32's range, or a bug in gdpt)");
    }
}

}  // namespace gdpt
