// decode_failure.h — plain one-line reasons for stb_image's decode failures, shared by the
// image reader (PNG/JPEG files) and the glTF loader (embedded textures). stb's reasons are
// terse codes ("outofdata"), and for an unknown PNG chunk it returns the chunk's raw type
// bytes, so printing them as they are shows binary bytes or nothing at all.
#pragma once

#include <cstddef>
#include <string>

namespace gdpt {

// The reason to print for a failed decode of `bytes` (the whole encoded image), given stb's
// stbi_failure_reason() (may be null). E.g. "the PNG data is truncated (the file ends
// early)", "corrupt JPEG header", "not an image format gdpt reads (PNG, JPEG, BMP, TGA, ...)".
[[nodiscard]] std::string decodeFailure(const unsigned char* bytes, std::size_t size, const char* stbReason);

}  // namespace gdpt
