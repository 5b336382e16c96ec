// video_preview.cpp — see video_preview.h.
#include "app/video_preview.h"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "util/error.h"
#include "util/output_files.h"

extern char** environ;

namespace gdpt {

std::optional<std::string> findFfmpeg() {
    const char* path = std::getenv("PATH");
    if (!path) return std::nullopt;
    std::string dirs(path);
    std::size_t start = 0;
    while (start <= dirs.size()) {
        const std::size_t end = std::min(dirs.find(':', start), dirs.size());
        const std::string dir = dirs.substr(start, end - start);
        const std::string candidate = (dir.empty() ? "." : dir) + "/ffmpeg";
        if (access(candidate.c_str(), X_OK) == 0) return candidate;
        start = end + 1;
    }
    return std::nullopt;
}

std::string encodeVideo(const std::string& ffmpeg, const std::string& pngPattern, int first, int count,
                        double fps, const std::string& videoPath) {
    StagedFile video(videoPath);
    char rate[32];
    std::snprintf(rate, sizeof rate, "%.9g", fps);
    // -nostdin: never wait for a keypress; the output format is named because the staged
    // file's temporary name has no extension.
    std::vector<std::string> args = {ffmpeg,
                                     "-nostdin",
                                     "-y",
                                     "-loglevel",
                                     "error",
                                     "-framerate",
                                     rate,
                                     "-start_number",
                                     std::to_string(first),
                                     "-i",
                                     pngPattern,
                                     "-frames:v",
                                     std::to_string(count),
                                     "-vf",
                                     "pad=ceil(iw/2)*2:ceil(ih/2)*2",
                                     "-c:v",
                                     "libx264",
                                     "-pix_fmt",
                                     "yuv420p",
                                     "-f",
                                     "mp4",
                                     video.tmpPath()};
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    pid_t pid = 0;
    if (const int err = posix_spawn(&pid, ffmpeg.c_str(), nullptr, nullptr, argv.data(), environ); err != 0)
        return "cannot run " + ffmpeg + ": " + std::strerror(err);
    int status = 0;
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR) return "waiting for ffmpeg failed: " + std::string(std::strerror(errno));
    if (WIFSIGNALED(status)) return "ffmpeg was stopped by signal " + std::to_string(WTERMSIG(status));
    if (WEXITSTATUS(status) != 0) return "ffmpeg exited with status " + std::to_string(WEXITSTATUS(status));
    try {
        video.commit();
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

}  // namespace gdpt
