#include "util/cache_dir.h"

#include <cstdlib>

namespace gdpt {

std::filesystem::path cacheDirectory() {
    namespace fs = std::filesystem;
    if (const char* d = std::getenv("GDPT_CACHE_DIR"); d && *d) return fs::path(d);
    if (const char* d = std::getenv("XDG_CACHE_HOME"); d && *d) return fs::path(d) / "gdpt";
    if (const char* d = std::getenv("HOME"); d && *d) return fs::path(d) / ".cache" / "gdpt";
    return {};
}

}  // namespace gdpt
