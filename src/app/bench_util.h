// bench_util.h — small helpers shared by the benchmark and render subcommands: medians,
// comma-separated lists, the deterministic batch size of a render, and text output.
#pragma once

#include <algorithm>
#include <cstdio>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "image/atomic_write.h"

namespace gdpt {

// Median of v (mean of the two middle values for an even count; 0 for none).
inline double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n == 0 ? 0.0 : (n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]));
}

// "a,b,,c" -> {"a", "b", "c"}.
inline std::vector<std::string> splitList(const std::string& text) {
    std::vector<std::string> out;
    std::stringstream in(text);
    std::string item;
    while (std::getline(in, item, ','))
        if (!item.empty()) out.push_back(item);
    return out;
}

// Largest batch (samples per pixel per submission) such that one batch is about 2^18
// pixel-samples of PT work (G-PT: 2^16, it costs more per sample). Depends only on the
// image size, so the batch schedule -- and hence the bits of the result -- is the same on
// every run, and a batch stays well under a second on lavapipe, so an interrupt is served
// promptly.
inline std::uint32_t batchLimit(int width, int height, bool gpt) {
    const std::uint64_t pixels = std::uint64_t(width) * std::uint64_t(height);
    const std::uint64_t budget = gpt ? (1u << 16) : (1u << 18);
    return static_cast<std::uint32_t>(std::clamp<std::uint64_t>(budget / pixels, 1, 16));
}

// A command's text output: stdout for "-", else the file, written atomically (tmp + rename).
inline void writeTextOutput(const std::string& path, const std::string& text) {
    if (path == "-")
        std::fputs(text.c_str(), stdout);
    else
        writeTextFileAtomically(path, text);
}

}  // namespace gdpt
