// bench_util.h — small helpers shared by the subcommands: medians, comma-separated lists,
// and text output.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "image/atomic_write.h"
#include "util/error.h"
#include "util/output_files.h"

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

// "N" (square) or "WxH" of a --sizes list (1..16384 each); throws gdpt::UsageError.
inline std::pair<int, int> parseSize(const std::string& s) {
    int w = 0, h = 0;
    char sep = 0;
    std::istringstream in(s);
    if (!(in >> w)) throw UsageError("--sizes: bad size '" + s + "'");
    if (in >> sep) {
        if (sep != 'x' || !(in >> h)) throw UsageError("--sizes: bad size '" + s + "' (N or WxH)");
    } else {
        h = w;
    }
    if (w <= 0 || h <= 0 || w > 16384 || h > 16384) throw UsageError("--sizes: bad size '" + s + "'");
    return {w, h};
}

// A command's text output (-o, --json): stdout for "-", nothing for "", else a file staged in
// `outputs` when the command starts (so that a bad path, or one that is an input, fails
// before the work; util/output_files.h) and moved into place when `outputs` commits.
class TextOutput {
public:
    TextOutput(OutputSet& outputs, const std::string& path, const std::string& what)
        : toStdout_(path == "-"), file_(path.empty() || path == "-" ? nullptr : &outputs.add(path, what)) {}
    [[nodiscard]] bool wanted() const { return toStdout_ || file_ != nullptr; }
    void write(const std::string& text) const {
        if (file_)
            writeStagedText(*file_, text);
        else if (toStdout_)
            std::fputs(text.c_str(), stdout);
    }

private:
    bool toStdout_;
    const StagedFile* file_;
};

}  // namespace gdpt
