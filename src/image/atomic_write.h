// atomic_write.h — "write to a unique temporary file beside the target, rename() when it is
// whole" (util/output_files.h), so that an interrupted or failed write never leaves a
// half-written output under the final name and concurrent runs never share bytes.
#pragma once

#include <functional>
#include <string>

namespace gdpt {

class StagedFile;

// Calls write(file.tmpPath()); a failure becomes a gdpt::Error naming file.path(). The
// caller commits (StagedFile::commit or OutputSet::commit); the temporary file is removed if
// it never does.
void writeStaged(const StagedFile& file, const std::function<void(const std::string& tmpPath)>& write);

// writeStaged for text: the staged file holds exactly `text`.
void writeStagedText(const StagedFile& file, const std::string& text);

// Stages `path`, calls write(tmpPath) and renames the temporary file onto `path`. If
// write() throws, or the rename fails, the temporary file is removed and a gdpt::Error
// naming `path` is thrown (gdpt::Error messages from write() are kept).
void writeFileAtomically(const std::string& path,
                         const std::function<void(const std::string& tmpPath)>& write);

// writeFileAtomically for a text file: `path` ends up holding exactly `text`, or is left
// untouched and a gdpt::Error naming it is thrown.
void writeTextFileAtomically(const std::string& path, const std::string& text);

}  // namespace gdpt
