// Frame ranges and output patterns of `gdpt render --frames` (util/frame_pattern.h).
#include <gtest/gtest.h>

#include <functional>

#include "util/error.h"
#include "util/frame_pattern.h"

namespace gdpt {
namespace {

std::string usageError(const std::function<void()>& f) {
    try {
        f();
        return "";
    } catch (const UsageError& e) {
        return e.what();
    }
}

TEST(FramePattern, RangesParse) {
    const FrameRange r = parseFrameRange("3:10", "--frames");
    EXPECT_EQ(r.first, 3);
    EXPECT_EQ(r.last, 10);
    EXPECT_EQ(r.count(), 8);
    EXPECT_EQ(parseFrameRange("7", "--frames").count(), 1);
    EXPECT_EQ(parseFrameRange("0:0", "--frames").first, 0);
    for (const char* bad : {"", ":", "3:", ":4", "-1:3", "a:b", "1:2:3", "1.5:3", "99999999:1", " 1:2"})
        EXPECT_NE(usageError([&] { (void)parseFrameRange(bad, "--frames"); }).find("--frames"),
                  std::string::npos)
            << bad;
    EXPECT_NE(
        usageError([] { (void)parseFrameRange("5:2", "--frames"); }).find("the last frame comes before"),
        std::string::npos);
}

TEST(FramePattern, PathsFormatTheFrameNumber) {
    EXPECT_TRUE(hasFrameNumber("out/f_%04d.exr", "-o"));
    EXPECT_EQ(framePath("out/f_%04d.exr", 7), "out/f_0007.exr");
    EXPECT_EQ(framePath("out/f_%04d.exr", 123456), "out/f_123456.exr");
    EXPECT_EQ(framePath("%d.exr", 42), "42.exr");
    EXPECT_EQ(framePath("100%%_%02d.exr", 3), "100%_03.exr");
    EXPECT_FALSE(hasFrameNumber("100%%.exr", "-o"));
    EXPECT_EQ(framePath("100%%.exr", 3), "100%.exr");
    EXPECT_FALSE(hasFrameNumber("plain.exr", "-o"));
    EXPECT_EQ(framePath("plain.exr", 3), "plain.exr");
}

TEST(FramePattern, VideoBesideTheFrames) {
    EXPECT_EQ(sequenceVideoPath("out/frame_%04d.exr", ".mp4"), "out/frame.mp4");
    EXPECT_EQ(sequenceVideoPath("out/%04d.exr", ".mp4"), "out/sequence.mp4");
    EXPECT_EQ(sequenceVideoPath("shot%d_final.exr", ".mp4"), "shot_final.mp4");
    EXPECT_EQ(sequenceVideoPath("a.b/f-%03d", ".mp4"), "a.b/f.mp4");
}

TEST(FramePattern, BadPatternsAreRefused) {
    for (const char* bad :
         {"f_%s.exr", "f_%4d.exr", "f_%0d.exr", "f_%.exr", "f_%", "f_%x.exr", "f_%010d.exr"})
        EXPECT_NE(
            usageError([&] { (void)hasFrameNumber(bad, "-o"); }).find("'%' must start the frame number"),
            std::string::npos)
            << bad;
    EXPECT_NE(usageError([] { (void)hasFrameNumber("%04d/f_%04d.exr", "-o"); }).find("2 frame numbers"),
              std::string::npos);
}

}  // namespace
}  // namespace gdpt
