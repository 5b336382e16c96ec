// image.cpp — planar float RGB image helpers.
#include "image/image.h"

#include <string>

#include "util/error.h"

namespace gdpt {

Image::Image(int width, int height, float fill) : width_(width), height_(height) {
    if (width < 0 || height < 0)
        throw Error("invalid image size " + std::to_string(width) + "x" + std::to_string(height));
    for (auto& p : planes_) p.assign(pixelCount(), fill);
}

std::array<double, 3> Image::meanRgb() const {
    std::array<double, 3> mean{0.0, 0.0, 0.0};
    if (empty()) return mean;
    for (int c = 0; c < kChannels; ++c) {
        double sum = 0.0;
        for (float v : planes_[c]) sum += v;
        mean[c] = sum / static_cast<double>(pixelCount());
    }
    return mean;
}

Image addImages(Image a, const Image& b) {
    if (!a.sameSize(b))
        throw Error("cannot add a " + std::to_string(b.width()) + "x" + std::to_string(b.height()) +
                    " image to a " + std::to_string(a.width()) + "x" + std::to_string(a.height()) + " one");
    for (int c = 0; c < Image::kChannels; ++c)
        for (std::size_t i = 0; i < a.pixelCount(); ++i) a.plane(c)[i] += b.plane(c)[i];
    return a;
}

}  // namespace gdpt
