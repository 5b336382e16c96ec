// image.h — gdpt's in-memory image: planar float32 RGB (one contiguous plane per channel).
// Planar storage is what the Poisson solver (one scalar problem per channel) and the GPU
// buffers want; pixel (x, y) is at index y * width + x, row 0 at the top.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

namespace gdpt {

class Image {
public:
    static constexpr int kChannels = 3;

    Image() = default;
    // A width x height image with every channel value set to `fill`. Throws gdpt::Error on
    // negative sizes.
    Image(int width, int height, float fill = 0.0f);

    [[nodiscard]] int width() const { return width_; }
    [[nodiscard]] int height() const { return height_; }
    [[nodiscard]] std::size_t pixelCount() const {
        return static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_);
    }
    [[nodiscard]] bool empty() const { return pixelCount() == 0; }
    [[nodiscard]] bool sameSize(const Image& other) const {
        return width_ == other.width_ && height_ == other.height_;
    }

    [[nodiscard]] std::size_t index(int x, int y) const {
        return static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x);
    }
    // Unchecked element access (c = 0 red, 1 green, 2 blue).
    [[nodiscard]] float& at(int x, int y, int c) { return planes_[c][index(x, y)]; }
    [[nodiscard]] float at(int x, int y, int c) const { return planes_[c][index(x, y)]; }

    // The whole plane of one channel, width*height floats.
    [[nodiscard]] std::vector<float>& plane(int c) { return planes_[c]; }
    [[nodiscard]] const std::vector<float>& plane(int c) const { return planes_[c]; }

    // Mean of each channel over all pixels (double accumulation).
    [[nodiscard]] std::array<double, 3> meanRgb() const;

private:
    int width_ = 0;
    int height_ = 0;
    std::array<std::vector<float>, kChannels> planes_;
};

// a + b per pixel and channel (e.g. reconstruction + very-direct image). Throws gdpt::Error
// if the sizes differ.
[[nodiscard]] Image addImages(Image a, const Image& b);

}  // namespace gdpt
