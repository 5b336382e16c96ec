// test_png_preview.cpp — sRGB preview codes, PNG write/read round trip, tmp+rename.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>

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

// Guards the class "an unreadable image gives a clean one-line reason": stb_image's reasons
// are codes ("outofdata"), and for an unknown PNG chunk it copies the chunk's raw type bytes
// into the text, so a corrupt PNG printed binary bytes, and one with a zero byte there an
// empty reason ("cannot decode ()"). Every cut of a valid PNG and every corrupted chunk type
// must give a message that names the file, is one line of printable ASCII, and has a
// reason; a cut inside the data says that the file is truncated.
TEST_F(PngPreview, UnreadablePngGivesACleanOneLineReason) {
    Image image(16, 16);
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x)
            for (int c = 0; c < 3; ++c) image.at(x, y, c) = float((x * 7 + y * 13 + c * 5) % 17) / 17.0f;
    writePngPreview(path("good.png"), image);
    std::ifstream in(path("good.png"), std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    ASSERT_GT(bytes.size(), 60u);
    const auto reasonOf = [&](const std::string& name, const std::string& content) {
        const std::string file = path(name);
        std::ofstream(file, std::ios::binary) << content;
        try {
            readPng(file);
        } catch (const Error& e) {
            const std::string m = e.what();
            const std::string prefix = file + ": cannot read image: ";
            EXPECT_EQ(m.rfind(prefix, 0), 0u) << m;
            for (char ch : m)
                EXPECT_TRUE(ch >= 0x20 && ch < 0x7f) << name << ": byte " << int(ch) << " in: " << m;
            const std::string reason = m.size() > prefix.size() ? m.substr(prefix.size()) : "";
            EXPECT_GE(reason.size(), 8u) << name << ": no reason in: " << m;
            EXPECT_EQ(reason.find("()"), std::string::npos) << m;
            return reason;
        }
        ADD_FAILURE() << name << " was read";
        return std::string();
    };
    // Cuts after the signature (inside IHDR, the data, before the end chunk) say so; a cut
    // inside the signature is not recognisably a PNG.
    for (std::size_t cut :
         {std::size_t{8}, std::size_t{20}, std::size_t{40}, bytes.size() / 2, bytes.size() - 13})
        EXPECT_NE(reasonOf("cut" + std::to_string(cut) + ".png", bytes.substr(0, cut)).find("truncated"),
                  std::string::npos)
            << "cut at " << cut;
    reasonOf("cut4.png", bytes.substr(0, 4));
    // Corrupt chunk types after IHDR (bytes 37..40 hold the second chunk's type): binary
    // bytes, a zero byte, lower-case (a critical chunk must be upper-case).
    for (const std::string& type : {std::string("\x97(\xe5"
                                                "D"),
                                    std::string("ID\0T", 4), std::string("idat")}) {
        std::string corrupt = bytes;
        corrupt.replace(37, 4, type);
        EXPECT_NE(reasonOf("chunk.png", corrupt).find("corrupt PNG data"), std::string::npos);
    }
    EXPECT_NE(reasonOf("text.png", "not an image at all\n").find("not an image format"), std::string::npos);
}

}  // namespace
}  // namespace gdpt
