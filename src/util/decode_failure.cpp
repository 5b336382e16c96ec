// decode_failure.cpp — see decode_failure.h.
#include "util/decode_failure.h"

#include <cctype>
#include <cstdint>
#include <cstring>

namespace gdpt {
namespace {

// The format the first bytes announce (for messages): "PNG", "JPEG" or "image".
std::string formatOf(const unsigned char* bytes, std::size_t n) {
    if (n >= 8 && std::memcmp(bytes, "\x89PNG\r\n\x1a\n", 8) == 0) return "PNG";
    if (n >= 3 && bytes[0] == 0xff && bytes[1] == 0xd8 && bytes[2] == 0xff) return "JPEG";
    return "image";
}

// Whether PNG data ends before its IEND chunk: walks the chunks (4-byte big-endian data
// length, 4-byte type, data, 4-byte CRC; PNG specification, ISO/IEC 15948 §5.3) from the
// 8-byte signature. stb_image reads past the end as zeros, so a cut file otherwise fails
// with whatever those zeros mean ("first not IHDR", a garbage chunk type).
bool pngEndsEarly(const unsigned char* bytes, std::size_t size) {
    std::uint64_t pos = 8;
    while (pos + 8 <= size) {
        const unsigned char* c = bytes + pos;
        const std::uint64_t length = (std::uint64_t{c[0]} << 24) | (std::uint64_t{c[1]} << 16) |
                                     (std::uint64_t{c[2]} << 8) | std::uint64_t{c[3]};
        if (std::memcmp(c + 4, "IEND", 4) == 0) return false;
        pos += 12 + length;
    }
    return true;
}

}  // namespace

// The codes that matter are translated, and a reason that is not plain lower-case text is
// not shown.
std::string decodeFailure(const unsigned char* bytes, std::size_t size, const char* stbReason) {
    const std::string reason = stbReason ? stbReason : "";
    const std::string format = formatOf(bytes, size);
    if (reason == "can't fopen") return "cannot open the file";
    if (reason == "unknown image type")
        return format == "image" ? "not an image format gdpt reads (PNG, JPEG, BMP, TGA, ...)"
                                 : "corrupt " + format + " header";
    if (reason == "outofdata" || reason == "unexpected end" || reason == "read past buffer" ||
        (format == "PNG" && pngEndsEarly(bytes, size)))
        return "the " + format + " data is truncated (the file ends early)";
    if (reason == "outofmem") return "out of memory while decoding";
    if (reason.find("too large") != std::string::npos) return "the image is too large";
    // Plain text: ASCII letters, digits, spaces and a little punctuation; at least 5
    // characters (a chunk-type fragment is shorter) and not the unknown-chunk text.
    bool plain = reason.size() >= 5 && reason.find("chunk not known") == std::string::npos;
    for (char ch : reason)
        plain =
            plain && (std::isalnum(static_cast<unsigned char>(ch)) || ch == ' ' || ch == '-' || ch == '/');
    return "corrupt " + format + " data" + (plain ? " (" + reason + ")" : std::string());
}

}  // namespace gdpt
