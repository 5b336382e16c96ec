// test_png_preview.cpp — sRGB preview codes, PNG write/read round trip, tmp+rename.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>

#include "image/png_preview.h"
#include "temp_dir.h"
#include "util/error.h"

namespace gdpt {
namespace {

using PngPreview = test::TempDirTest;

TEST(PreviewCode, KnownValues) {
    EXPECT_EQ(previewCode(0.0f), 0);
    EXPECT_EQ(previewCode(1.0f), 255);
    // sRGB OETF: 1.055 * 0.5^(1/2.4) - 0.055 = 0.735357 -> 255 * 0.735357 = 187.52 -> 188.
    EXPECT_EQ(previewCode(0.5f), 188);
    // Linear segment: 0.001 * 12.92 * 255 = 3.29 -> 3.
    EXPECT_EQ(previewCode(0.001f), 3);
    EXPECT_EQ(previewCode(4.0f), 255);                                    // clamped
    EXPECT_EQ(previewCode(-1.0f), 0);                                     // negative
    EXPECT_EQ(previewCode(std::numeric_limits<float>::quiet_NaN()), 0);   // NaN
    EXPECT_EQ(previewCode(std::numeric_limits<float>::infinity()), 255);  // +inf
    EXPECT_EQ(previewCode(0.25f, {2.0f, ToneMap::Clamp}), 188);           // exposure
    EXPECT_EQ(previewCode(1.0f, {1.0f, ToneMap::Reinhard}), 188);         // 1/(1+1)
    EXPECT_EQ(previewCode(std::numeric_limits<float>::infinity(), {1.0f, ToneMap::Reinhard}), 255);
}

TEST(Srgb, CurvesAreInverse) {
    for (double v = 0.0; v <= 1.0; v += 1.0 / 64.0) EXPECT_NEAR(srgbToLinear(linearToSrgb(v)), v, 1e-12);
    EXPECT_NEAR(linearToSrgb(0.0031308), 0.04045, 1e-6);  // continuity at the knee
}

TEST_F(PngPreview, WriteThenReadGivesLinearOfTheCodes) {
    Image image(4, 1);
    const float values[4] = {0.0f, 1.0f, 0.5f, 2.0f};
    for (int x = 0; x < 4; ++x)
        for (int c = 0; c < 3; ++c) image.at(x, 0, c) = values[x] * (c == 1 ? 0.5f : 1.0f);
    const std::string file = path("preview.png");
    writePngPreview(file, image);
    EXPECT_TRUE(temporaryFiles().empty());
    const Image back = readPng(file);
    ASSERT_EQ(back.width(), 4);
    ASSERT_EQ(back.height(), 1);
    const double expected[4] = {0.0, 1.0, srgbToLinear(188.0 / 255.0), 1.0};
    for (int x = 0; x < 4; ++x) {
        EXPECT_NEAR(back.at(x, 0, 0), expected[x], 1e-6) << x;
        EXPECT_NEAR(back.at(x, 0, 2), expected[x], 1e-6) << x;
    }
    // Green was halved: 0.25 -> code round(255 * 0.537099) = 137.
    EXPECT_NEAR(back.at(2, 0, 1), srgbToLinear(137.0 / 255.0), 1e-6);
    // readImage dispatches non-EXR files to the stb reader.
    EXPECT_EQ(readImage(file).at(2, 0, 0), back.at(2, 0, 0));
}

TEST_F(PngPreview, FailuresThrowAndLeaveNoFile) {
    const std::string impossible = path("missing_dir/p.png");
    EXPECT_THROW(writePngPreview(impossible, Image(2, 2)), Error);
    EXPECT_TRUE(temporaryFiles().empty());
    EXPECT_THROW(writePngPreview(path("empty.png"), Image()), Error);
    try {
        readPng(path("absent.png"));
        ADD_FAILURE();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("absent.png"), std::string::npos);
    }
}

}  // namespace
}  // namespace gdpt
