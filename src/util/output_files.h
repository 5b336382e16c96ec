// output_files.h — how gdpt writes files: every output is staged in a unique temporary file
// beside its target and renamed into place only when it is whole, and the outputs of one
// command are checked before the work starts and committed together.
//
//   OutputSet outputs({{"scene", scenePath}});      // files the command reads
//   StagedFile& exr = outputs.add(exrPath, "-o");  // checked now: a long render never fails
//   StagedFile& png = outputs.add(pngPath, "PNG preview");  // at the end on a bad path
//   ... work ...
//   writeSomething(exr.tmpPath()); writeOther(png.tmpPath());
//   outputs.commit();  // all renamed into place, or none (the destructor removes the temps)
//
// Temporary names come from mkstemp, so concurrent runs writing the same target never share
// a file; a group commit holds an exclusive lock (flock) on each target directory, so two
// runs' outputs are never interleaved (out.exr of one run beside out.png of the other).
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace gdpt {

// One output file, staged. The constructor checks `path` (its directory exists and is
// writable; the path is not a directory or another non-regular file) by creating the
// temporary file, and throws gdpt::Error naming `path` with the OS's reason otherwise.
// Destroying an uncommitted StagedFile removes the temporary file.
class StagedFile {
public:
    explicit StagedFile(std::string path);
    ~StagedFile();
    StagedFile(const StagedFile&) = delete;
    StagedFile& operator=(const StagedFile&) = delete;

    [[nodiscard]] const std::string& path() const { return path_; }
    // Where the writer puts the bytes (it may reopen and truncate it).
    [[nodiscard]] const std::string& tmpPath() const { return tmpPath_; }

    // fsyncs the temporary file and renames it onto path(). Throws gdpt::Error (the
    // temporary file is then removed). For several files use OutputSet::commit.
    void commit();

private:
    friend class OutputSet;
    void sync() const;  // fsync the temporary file; throws on error
    void discard();     // remove the temporary file (idempotent)
    std::string path_;
    std::string tmpPath_;
    bool committed_ = false;
    int signalSlot_ = -1;  // removeOnSignal's slot (util/interrupt.h), for an OutputSet's files
};

// Writes `bytes` to `path` (opened with O_TRUNC), checking every write, fsync and close;
// throws gdpt::Error with the OS's reason (e.g. "No space left on device").
void writeBytes(const std::string& path, const void* bytes, std::size_t size);

// The outputs of one command. Inputs are the files the command reads: an output may not be
// any of them, nor another output (compared by file identity where the file exists, else by
// canonical path), so `-o scene.gltf` or an EXR and its PNG preview at one path are refused
// before any work is done.
class OutputSet {
public:
    // (what, path) of each input, e.g. {"scene", "s.gltf"}; empty paths are skipped.
    explicit OutputSet(std::vector<std::pair<std::string, std::string>> inputs = {});
    ~OutputSet();
    OutputSet(const OutputSet&) = delete;
    OutputSet& operator=(const OutputSet&) = delete;

    // Checks `path` against the inputs and the outputs added so far and stages it; `what`
    // names it in errors ("-o", "--json", "PNG preview"). Throws gdpt::Error.
    StagedFile& add(const std::string& path, const std::string& what);

    // Checks that `path` (written by the command on its own schedule, e.g. a checkpoint) is
    // not an input other than those in `mayBe` and not one of the staged outputs.
    void checkSeparate(const std::string& path, const std::string& what,
                       const std::vector<std::string>& mayBeInputs = {}) const;

    // fsyncs every staged file and renames them into place under an exclusive lock of their
    // directories. If one rename fails, those already renamed are rolled back (the previous
    // file restored, or the new one removed), so the outputs appear together or not at all.
    void commit();

private:
    void checkDistinct(const std::string& path, const std::string& what,
                       const std::vector<std::string>& allowedInputs) const;
    std::vector<std::pair<std::string, std::string>> inputs_;
    std::vector<std::pair<std::string, std::unique_ptr<StagedFile>>> outputs_;  // (what, file)
};

// True if a and b name the same file: the same device and inode where both exist, else the
// same canonical absolute path.
[[nodiscard]] bool sameFile(const std::string& a, const std::string& b);

}  // namespace gdpt
