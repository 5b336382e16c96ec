// frame_pattern.h — the frames of a sequence on the command line: a range "A:B" (or one frame
// "N") and an output path pattern with a printf-style frame number ("out/frame_%04d.exr"),
// the convention ffmpeg and most compositors read.
#pragma once

#include <string>

namespace gdpt {

struct FrameRange {
    int first = 0;
    int last = 0;  // inclusive
    [[nodiscard]] int count() const { return last - first + 1; }
};

// Parses "A:B" (0 <= A <= B <= 9999999) or "N" (= N:N); throws gdpt::UsageError naming `flag`.
FrameRange parseFrameRange(const std::string& text, const std::string& flag);

// Whether `pattern` has a frame number: exactly one %d or %0Nd (N from 1 to 9); "%%" is a
// literal %. Throws gdpt::UsageError naming `flag` for any other use of % (a second number,
// %s, a width without the 0, ...).
bool hasFrameNumber(const std::string& pattern, const std::string& flag);

// The pattern with its frame number formatted (and "%%" as "%"); the pattern as it is if it
// has no frame number. The pattern must pass hasFrameNumber.
std::string framePath(const std::string& pattern, int frame);

// The seed of frame `frame` of a sequence rendered with `seed`: seed + frame * 0x9E3779B9
// (mod 2^32; the golden-ratio increment), so that frame 0 is the single image of that seed and
// every frame's noise is independent of its neighbours', as independent renders of the frames
// would be (temporal methods correlate frames on purpose, and say so).
[[nodiscard]] constexpr unsigned sequenceFrameSeed(unsigned seed, int frame) {
    return seed + static_cast<unsigned>(frame) * 0x9E3779B9u;
}

// The sequence's video beside its frames: the pattern without its frame number (and the
// separator before it) and with `extension`: "out/frame_%04d.exr" -> "out/frame.mp4";
// "out/%04d.exr" -> "out/sequence.mp4".
std::string sequenceVideoPath(const std::string& pattern, const std::string& extension);

}  // namespace gdpt
