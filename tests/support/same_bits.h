// same_bits.h — gtest assertions that two images, two EXR files, or two G-PT renders' sampler
// buffers, are the same bit for bit (for variants that must not change an estimator: specialisation
// constants, the two SPIR-V forms, split loops).
#pragma once

#include <gtest/gtest.h>

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

// Every buffer G-PT's sampler writes: primal, gradients, direct.
inline void expectSameGptBits(const RenderResultGpt& a, const RenderResultGpt& b, const std::string& what) {
    expectSameBits(a.primal, b.primal, what + " primal");
    expectSameBits(a.dx, b.dx, what + " dx");
    expectSameBits(a.dy, b.dy, what + " dy");
    expectSameBits(a.direct, b.direct, what + " direct");
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
