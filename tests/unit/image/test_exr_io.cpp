// test_exr_io.cpp — EXR round trips, foreign (HALF/UINT, offset window) files, corrupt files,
// and the tmp+rename guarantee.
#include <Imath/half.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfOutputFile.h>
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include "image/exr_io.h"
#include "temp_dir.h"
#include "util/error.h"

namespace gdpt {
namespace {

using ExrIo = test::TempDirTest;

Image randomImage(int w, int h, unsigned seed) {
    std::mt19937 rng(seed);
    // Log-uniform magnitudes over many decades with random signs: any lossy conversion
    // (half, rounding) would change the bits.
    std::uniform_real_distribution<float> exponent(-30.0f, 30.0f);
    std::bernoulli_distribution negative(0.3);
    Image image(w, h);
    for (int c = 0; c < 3; ++c)
        for (float& v : image.plane(c)) v = (negative(rng) ? -1.0f : 1.0f) * std::exp2(exponent(rng));
    return image;
}

bool bitEqual(const Image& a, const Image& b) {
    if (!a.sameSize(b)) return false;
    for (int c = 0; c < 3; ++c)
        if (std::memcmp(a.plane(c).data(), b.plane(c).data(), a.pixelCount() * sizeof(float))) return false;
    return true;
}

TEST_F(ExrIo, RoundTripOfSeveralLayersIsBitExact) {
    const std::vector<NamedLayer> layers = {
        {"", randomImage(7, 5, 1)}, {"dx", randomImage(7, 5, 2)}, {"dy", randomImage(7, 5, 3)}};
    const std::string file = path("layers.exr");
    writeExr(file, layers);
    EXPECT_TRUE(temporaryFiles().empty());
    const std::vector<NamedLayer> back = readExr(file);
    ASSERT_EQ(back.size(), 3u);
    EXPECT_EQ(back[0].name, "");
    EXPECT_EQ(back[1].name, "dx");
    EXPECT_EQ(back[2].name, "dy");
    for (std::size_t i = 0; i < 3; ++i) EXPECT_TRUE(bitEqual(back[i].image, layers[i].image)) << i;
    EXPECT_TRUE(bitEqual(readExrLayer(file, "dy"), layers[2].image));
    EXPECT_THROW(readExrLayer(file, "missing"), Error);
}

// String attributes survive a round trip (values with spaces, commas and an empty one) and
// a file written without any has none of gdpt's.
TEST_F(ExrIo, StringAttributesRoundTrip) {
    const ExrAttributes attributes = {
        {"gdpt.a", "1"}, {"gdpt.env", "0.5,0.25,1"}, {"gdpt.empty", ""}, {"gdpt.text", "two words"}};
    const std::string file = path("attr.exr");
    writeExr(file, {{"", randomImage(3, 2, 4)}}, attributes);
    ExrAttributes back = readExrAttributes(file);
    for (const auto& [name, value] : attributes) {
        ASSERT_TRUE(back.count(name)) << name;
        EXPECT_EQ(back[name], value) << name;
    }
    writeExr(path("plain.exr"), randomImage(3, 2, 5));
    for (const auto& [name, value] : readExrAttributes(path("plain.exr")))
        EXPECT_NE(name.rfind("gdpt.", 0), 0u) << name;
    EXPECT_THROW(readExrAttributes(path("missing.exr")), Error);
}

TEST_F(ExrIo, WriterRejectsMismatchedLayers) {
    EXPECT_THROW(writeExr(path("a.exr"), {{"", Image(2, 2)}, {"x", Image(3, 2)}}), Error);
    EXPECT_THROW(writeExr(path("b.exr"), {{"x", Image(2, 2)}, {"x", Image(2, 2)}}), Error);
    EXPECT_THROW(writeExr(path("c.exr"), std::vector<NamedLayer>{}), Error);
    EXPECT_TRUE(std::filesystem::is_empty(dir_));
}

// Writes, with OpenEXR directly, a file with HALF R,G,B, a UINT "id.R" channel, a
// luminance-only layer "lum.Y", and a data window starting at (-2, 3).
TEST_F(ExrIo, ReadsHalfUintLuminanceAndOffsetDataWindow) {
    const int w = 4, h = 3;
    const Imath::Box2i dataWindow({-2, 3}, {-2 + w - 1, 3 + h - 1});
    Imf::Header header(dataWindow, dataWindow);
    for (const char* name : {"R", "G", "B"}) header.channels().insert(name, Imf::Channel(Imf::HALF));
    header.channels().insert("id.R", Imf::Channel(Imf::UINT));
    header.channels().insert("lum.Y", Imf::Channel(Imf::FLOAT));
    std::vector<half> r(w * h), g(w * h), b(w * h);
    std::vector<unsigned> id(w * h);
    std::vector<float> lum(w * h);
    for (int i = 0; i < w * h; ++i) {
        // Exactly representable in half: k/8 and small integers.
        r[i] = half(static_cast<float>(i) / 8.0f);
        g[i] = half(-static_cast<float>(i));
        b[i] = half(1024.0f + static_cast<float>(i));
        id[i] = 1000u + static_cast<unsigned>(i);
        lum[i] = 0.1f * static_cast<float>(i);
    }
    Imf::FrameBuffer fb;
    auto slice = [&](Imf::PixelType type, void* data, std::size_t size) {
        return Imf::Slice::Make(type, data, dataWindow, size, size * w);
    };
    fb.insert("R", slice(Imf::HALF, r.data(), sizeof(half)));
    fb.insert("G", slice(Imf::HALF, g.data(), sizeof(half)));
    fb.insert("B", slice(Imf::HALF, b.data(), sizeof(half)));
    fb.insert("id.R", slice(Imf::UINT, id.data(), sizeof(unsigned)));
    fb.insert("lum.Y", slice(Imf::FLOAT, lum.data(), sizeof(float)));
    const std::string file = path("foreign.exr");
    {
        Imf::OutputFile out(file.c_str(), header);
        out.setFrameBuffer(fb);
        out.writePixels(h);
    }
    const std::vector<NamedLayer> layers = readExr(file);
    ASSERT_EQ(layers.size(), 3u);
    const Image& rgb = layers[0].image;
    const Image& ids = layers[1].image;
    const Image& gray = layers[2].image;
    EXPECT_EQ(layers[1].name, "id");
    EXPECT_EQ(layers[2].name, "lum");
    ASSERT_EQ(rgb.width(), w);
    ASSERT_EQ(rgb.height(), h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const int i = y * w + x;
            EXPECT_EQ(rgb.at(x, y, 0), static_cast<float>(i) / 8.0f);
            EXPECT_EQ(rgb.at(x, y, 1), -static_cast<float>(i));
            EXPECT_EQ(rgb.at(x, y, 2), 1024.0f + static_cast<float>(i));
            EXPECT_EQ(ids.at(x, y, 0), 1000.0f + static_cast<float>(i));
            EXPECT_EQ(ids.at(x, y, 1), 0.0f);  // missing G, B read as 0
            for (int c = 0; c < 3; ++c) EXPECT_EQ(gray.at(x, y, c), lum[i]);
        }
}

TEST_F(ExrIo, TruncatedFileThrowsErrorNamingTheFile) {
    const std::string good = path("good.exr");
    writeExr(good, randomImage(64, 64, 4));
    std::ifstream in(good, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    ASSERT_GT(bytes.size(), 400u);
    // Cut at several places: inside the header, inside the offset table, inside the data.
    for (std::size_t keep :
         {std::size_t{0}, std::size_t{10}, std::size_t{200}, bytes.size() / 2, bytes.size() - 1}) {
        const std::string bad = path("truncated_" + std::to_string(keep) + ".exr");
        std::ofstream(bad, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(keep));
        try {
            readExr(bad);
            ADD_FAILURE() << "no error for a file truncated to " << keep << " bytes";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
        }
    }
}

TEST_F(ExrIo, CorruptBytesThrowErrorNotCrash) {
    const std::string good = path("good.exr");
    writeExr(good, randomImage(32, 32, 5));
    std::ifstream in(good, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::mt19937 rng(6);
    int errors = 0;
    for (int trial = 0; trial < 20; ++trial) {
        std::string copy = bytes;
        // Overwrite a run of bytes after the magic number with garbage.
        std::uniform_int_distribution<std::size_t> pos(4, copy.size() - 17);
        const std::size_t at = pos(rng);
        for (std::size_t k = 0; k < 16; ++k) copy[at + k] = static_cast<char>(rng());
        const std::string bad = path("corrupt.exr");
        std::ofstream(bad, std::ios::binary | std::ios::trunc)
            .write(copy.data(), static_cast<std::streamsize>(copy.size()));
        try {
            readExr(bad);  // some corruptions are harmless (pixel data): fine either way
        } catch (const Error& e) {
            ++errors;
            EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
        }
    }
    EXPECT_THROW(readExr(path("does_not_exist.exr")), Error);
    std::ofstream(path("text.exr")) << "not an exr file at all";
    EXPECT_THROW(readExr(path("text.exr")), Error);
    (void)errors;
}

TEST_F(ExrIo, FailedWriteLeavesNoFile) {
    const std::string impossible = path("no_such_dir/out.exr");
    EXPECT_THROW(writeExr(impossible, randomImage(4, 4, 7)), Error);
    EXPECT_FALSE(std::filesystem::exists(impossible));
    EXPECT_TRUE(temporaryFiles().empty());
    // Target is a directory: refused before anything is written.
    std::filesystem::create_directories(path("is_a_dir.exr"));
    EXPECT_THROW(writeExr(path("is_a_dir.exr"), randomImage(4, 4, 8)), Error);
    EXPECT_TRUE(temporaryFiles().empty());
}

}  // namespace
}  // namespace gdpt
