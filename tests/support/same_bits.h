// same_bits.h — gtest assertions that two images, or two G-PT renders' sampler buffers, are
// the same bit for bit (for variants that must not change an estimator: specialisation
// constants, the two SPIR-V forms, split loops).
#pragma once

#include <gtest/gtest.h>

#include <string>

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

}  // namespace gdpt::test
