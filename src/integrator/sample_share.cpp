#include "integrator/sample_share.h"

#include <cctype>

#include "util/error.h"

namespace gdpt {
namespace {

// A whole number of at most 9 digits, or -1.
long parseSmall(const std::string& text) {
    if (text.empty() || text.size() > 9) return -1;
    long value = 0;
    for (char c : text) {
        if (!std::isdigit(static_cast<unsigned char>(c))) return -1;
        value = value * 10 + (c - '0');
    }
    return value;
}

}  // namespace

SampleShare parseSampleShare(const std::string& text, const std::string& what) {
    const auto slash = text.find('/');
    const long index = slash == std::string::npos ? -1 : parseSmall(text.substr(0, slash));
    const long count = slash == std::string::npos ? -1 : parseSmall(text.substr(slash + 1));
    if (index < 0 || count < 1)
        throw UsageError(what + " '" + text + "' must be I/N: part I (counted from 0) of N parts, e.g. 0/4");
    if (count > long(kMaxShares))
        throw UsageError(what + " '" + text + "': at most " + std::to_string(kMaxShares) + " parts");
    if (index >= count)
        throw UsageError(what + " '" + text + "': the part I must be below N (parts are numbered 0 to " +
                         std::to_string(count - 1) + ")");
    return {static_cast<std::uint32_t>(index), static_cast<std::uint32_t>(count)};
}

}  // namespace gdpt
