// atomic_write.h — "write to name.tmp, rename() on success", so that an
// interrupted or failed write never leaves a half-written output under the final name.
#pragma once

#include <functional>
#include <string>

namespace gdpt {

// Calls write(tmpPath) with tmpPath = path + ".tmp"; if it returns normally, renames the
// temporary file onto `path` (atomic on POSIX within one file system). If write() throws,
// or the rename fails, the temporary file is removed and a gdpt::Error naming `path` is
// thrown (gdpt::Error messages from write() are kept and prefixed with the path).
void writeFileAtomically(const std::string& path,
                         const std::function<void(const std::string& tmpPath)>& write);

// writeFileAtomically for a text file: `path` ends up holding exactly `text`, or is left
// untouched and a gdpt::Error naming it is thrown.
void writeTextFileAtomically(const std::string& path, const std::string& text);

}  // namespace gdpt
