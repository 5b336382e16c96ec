// frame_pattern.cpp — see frame_pattern.h.
#include "util/frame_pattern.h"

#include <cstdio>

#include "util/error.h"

namespace gdpt {
namespace {

constexpr int kMaxFrame = 9'999'999;

int parseFrame(const std::string& text, const std::string& whole, const std::string& flag) {
    if (text.empty() || text.size() > 7 || text.find_first_not_of("0123456789") != std::string::npos)
        throw UsageError(flag + " " + whole + ": expected A:B, frame numbers from 0 to " +
                         std::to_string(kMaxFrame) + " (e.g. 0:47), or one frame N");
    return std::stoi(text);
}

// Calls onNumber(position, length, width) for the frame number and onLiteral(position) for
// each "%%"; throws for anything else after a %.
template <typename Number, typename Literal>
void scan(const std::string& p, const std::string& flag, Number&& onNumber, Literal&& onLiteral) {
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p[i] != '%') continue;
        if (i + 1 < p.size() && p[i + 1] == '%') {
            onLiteral(i);
            ++i;
            continue;
        }
        std::size_t j = i + 1;
        int width = 0;
        if (j < p.size() && p[j] == '0') {
            ++j;
            if (j < p.size() && p[j] >= '1' && p[j] <= '9') width = p[j++] - '0';
        }
        const bool zeroWithoutWidth = j == i + 2 && width == 0;
        if (j >= p.size() || p[j] != 'd' || zeroWithoutWidth)
            throw UsageError(flag + " " + p +
                             ": '%' must start the frame number (%d or %0Nd, e.g. %04d) or be written %%");
        onNumber(i, j + 1 - i, width);
        i = j;
    }
}

}  // namespace

FrameRange parseFrameRange(const std::string& text, const std::string& flag) {
    FrameRange r;
    const std::size_t colon = text.find(':');
    if (colon == std::string::npos) {
        r.first = r.last = parseFrame(text, text, flag);
        return r;
    }
    r.first = parseFrame(text.substr(0, colon), text, flag);
    r.last = parseFrame(text.substr(colon + 1), text, flag);
    if (r.last < r.first) throw UsageError(flag + " " + text + ": the last frame comes before the first");
    return r;
}

bool hasFrameNumber(const std::string& pattern, const std::string& flag) {
    int numbers = 0;
    scan(
        pattern, flag, [&](std::size_t, std::size_t, int) { ++numbers; }, [](std::size_t) {});
    if (numbers > 1)
        throw UsageError(flag + " " + pattern + ": the pattern has " + std::to_string(numbers) +
                         " frame numbers; it takes one (%d or %0Nd)");
    return numbers == 1;
}

std::string framePath(const std::string& pattern, int frame) {
    std::string out;
    std::size_t copied = 0;
    scan(
        pattern, "",
        [&](std::size_t at, std::size_t length, int width) {
            char number[32];
            std::snprintf(number, sizeof number, "%0*d", width, frame);
            out += pattern.substr(copied, at - copied) + number;
            copied = at + length;
        },
        [&](std::size_t at) {
            out += pattern.substr(copied, at - copied) + "%";
            copied = at + 2;
        });
    return out + pattern.substr(copied);
}

std::string sequenceVideoPath(const std::string& pattern, const std::string& extension) {
    const std::size_t slash = pattern.rfind('/');
    const std::string dir = slash == std::string::npos ? "" : pattern.substr(0, slash + 1);
    std::string name = slash == std::string::npos ? pattern : pattern.substr(slash + 1);
    const std::size_t dot = name.rfind('.');
    if (dot != std::string::npos && dot > 0) name = name.substr(0, dot);
    std::string stem;
    std::size_t copied = 0;
    scan(
        name, "",
        [&](std::size_t at, std::size_t length, int) {
            stem += name.substr(copied, at - copied);
            copied = at + length;
        },
        [&](std::size_t at) {
            stem += name.substr(copied, at - copied) + "%";
            copied = at + 2;
        });
    stem += name.substr(copied);
    while (!stem.empty() &&
           (stem.back() == '_' || stem.back() == '-' || stem.back() == '.' || stem.back() == ' '))
        stem.pop_back();
    return dir + (stem.empty() ? "sequence" : stem) + extension;
}

}  // namespace gdpt
