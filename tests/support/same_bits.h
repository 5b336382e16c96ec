// same_bits.h — gtest assertions that two images, two EXR files, or two G-PT renders' sampler
// buffers, are the same bit for bit (for variants that must not change an estimator: specialisation
// constants, the two SPIR-V forms, split loops).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "image/exr_io.h"
#include "image/image.h"
#include "integrator/gpt_sampler.h"

namespace gdpt::test {

inline void expectSameBits(const Image& a, const Image& b, const std::string& what) {
    ASSERT_EQ(a.pixelCount(), b.pixelCount()) << what;
    for (int c = 0; c < 3; ++c)
        for (std::size_t i = 0; i < a.pixelCount(); ++i)
            ASSERT_EQ(a.plane(c)[i], b.plane(c)[i]) << what << ", pixel " << i << ", channel " << c;
}

// Two images of the same estimator whose arithmetic was rounded differently (a GPU driver may
// contract a*b+c into one fused operation in one compilation and not in another): every value
// within kRoundingRelative of the other (the floating-point error of a few thousand operations
// of a path, at u = 2^-24 each, relative to the larger magnitude or to the image's mean
// magnitude for values near zero), except for at most kRoundingFlips of the values, whose path
// a rounding difference may have sent another way (a grazing ray, a roulette threshold).
inline constexpr double kRoundingRelative = 1e-4;
inline constexpr double kRoundingFlips = 0.01;
inline void expectSameUpToRounding(const Image& a, const Image& b, const std::string& what) {
    ASSERT_EQ(a.pixelCount(), b.pixelCount()) << what;
    double meanAbs = 0.0;
    for (int c = 0; c < 3; ++c)
        for (float v : a.plane(c)) meanAbs += std::abs(double(v));
    meanAbs /= 3.0 * double(a.pixelCount());
    std::size_t off = 0;
    for (int c = 0; c < 3; ++c)
        for (std::size_t i = 0; i < a.pixelCount(); ++i) {
            const double x = a.plane(c)[i], y = b.plane(c)[i];
            const double scale = std::max({std::abs(x), std::abs(y), 1e-3 * meanAbs});
            if (!(std::abs(x - y) <= kRoundingRelative * scale)) ++off;
        }
    EXPECT_LE(double(off), kRoundingFlips * 3.0 * double(a.pixelCount()))
        << what << ": " << off << " of " << 3 * a.pixelCount() << " values differ by more than rounding";
}

// Every buffer G-PT's sampler writes: primal, gradients, direct; the same bits, or (bits =
// false) the same up to rounding.
inline void expectSameGptBits(const RenderResultGpt& a, const RenderResultGpt& b, const std::string& what,
                              bool bits = true) {
    const auto same = bits ? expectSameBits : expectSameUpToRounding;
    same(a.primal, b.primal, what + " primal");
    same(a.dx, b.dx, what + " dx");
    same(a.dy, b.dy, what + " dy");
    same(a.direct, b.direct, what + " direct");
}

// Every layer of two EXR files has the same name and the same bits (memcmp: -0 and +0, and NaN
// payloads, count as different).
inline void expectSameExrLayers(const std::string& a, const std::string& b) {
    const auto la = readExr(a), lb = readExr(b);
    ASSERT_EQ(la.size(), lb.size()) << a << " and " << b;
    for (std::size_t i = 0; i < la.size(); ++i) {
        EXPECT_EQ(la[i].name, lb[i].name);
        ASSERT_TRUE(la[i].image.sameSize(lb[i].image)) << la[i].name;
        for (int c = 0; c < 3; ++c)
            EXPECT_EQ(std::memcmp(la[i].image.plane(c).data(), lb[i].image.plane(c).data(),
                                  la[i].image.pixelCount() * sizeof(float)),
                      0)
                << a << " and " << b << ": layer '" << la[i].name << "' channel " << c;
    }
}

}  // namespace gdpt::test
