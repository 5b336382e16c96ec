// video_preview.h — an H.264 video of a rendered sequence's PNG frames, made by ffmpeg when it
// is installed (Debian package ffmpeg; gdpt works without it). The video is a preview, like
// the PNGs: tone-mapped 8-bit frames; the EXRs are the result.
#pragma once

#include <optional>
#include <string>

namespace gdpt {

// The path of the ffmpeg executable on $PATH, if there is one.
[[nodiscard]] std::optional<std::string> findFfmpeg();

// Encodes the frames `pngPattern` (printf-style frame number, frames first .. first+count-1)
// at `fps` into `videoPath` (MP4, H.264, yuv420p, odd sizes padded by a pixel), written whole
// or not at all (util/output_files.h). Returns "" on success, else why not (ffmpeg's exit
// status); ffmpeg's own messages go to stderr.
[[nodiscard]] std::string encodeVideo(const std::string& ffmpeg, const std::string& pngPattern, int first,
                                      int count, double fps, const std::string& videoPath);

}  // namespace gdpt
