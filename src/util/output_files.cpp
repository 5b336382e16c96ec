// output_files.cpp — staged, checked, unique and grouped output files (POSIX).
#include "util/output_files.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <set>

#include "util/error.h"
#include "util/interrupt.h"

namespace gdpt {
namespace {

namespace fs = std::filesystem;

std::string osReason(int err) {
    return std::strerror(err);
}

std::string directoryOf(const std::string& path) {
    const fs::path parent = fs::path(path).parent_path();
    return parent.empty() ? "." : parent.string();
}

// The permissions a file created with open(0666) would get: mkstemp makes 0600 files.
mode_t defaultFileMode() {
    static const mode_t mode = [] {
        const mode_t mask = ::umask(0);
        ::umask(mask);
        return static_cast<mode_t>(0666 & ~mask);
    }();
    return mode;
}

// An exclusive flock on a directory, held while a group of files is renamed into it.
class DirectoryLock {
public:
    explicit DirectoryLock(const std::string& dir)
        : fd_(::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC)) {
        if (fd_ < 0) return;  // the renames will report what is wrong with the directory
        while (::flock(fd_, LOCK_EX) != 0 && errno == EINTR) {
        }
    }
    ~DirectoryLock() {
        if (fd_ >= 0) ::close(fd_);  // closing releases the lock
    }
    DirectoryLock(const DirectoryLock&) = delete;
    DirectoryLock& operator=(const DirectoryLock&) = delete;

private:
    int fd_;
};

// A unique new file `<dir>/.<name>.<tag>XXXXXX`; returns its path. Throws with the reason.
std::string makeUniqueFile(const std::string& target, const char* tag) {
    const fs::path p(target);
    std::string pattern =
        (fs::path(directoryOf(target)) / ("." + p.filename().string() + "." + tag + "XXXXXX")).string();
    const int fd = ::mkostemp(pattern.data(), O_CLOEXEC);
    if (fd < 0)
        throw Error(target + ": cannot create a file in " + directoryOf(target) + ": " + osReason(errno));
    ::fchmod(fd, defaultFileMode());
    ::close(fd);
    return pattern;
}

}  // namespace

bool sameFile(const std::string& a, const std::string& b) {
    struct stat sa {};
    struct stat sb {};
    if (::stat(a.c_str(), &sa) == 0 && ::stat(b.c_str(), &sb) == 0)
        return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
    std::error_code ea;
    std::error_code eb;
    const fs::path ca = fs::weakly_canonical(fs::absolute(a), ea);
    const fs::path cb = fs::weakly_canonical(fs::absolute(b), eb);
    if (ea || eb) return fs::absolute(a).lexically_normal() == fs::absolute(b).lexically_normal();
    return ca == cb;
}

void writeBytes(const std::string& path, const void* bytes, std::size_t size) {
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd < 0) throw Error("cannot open " + path + " for writing: " + osReason(errno));
    const char* p = static_cast<const char*>(bytes);
    std::size_t left = size;
    while (left > 0) {
        const ssize_t n = ::write(fd, p, left);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            const int err = n < 0 ? errno : EIO;
            ::close(fd);
            throw Error("cannot write " + path + ": " + osReason(err));
        }
        p += n;
        left -= static_cast<std::size_t>(n);
    }
    if (::fsync(fd) != 0 && errno != EINVAL) {
        const int err = errno;
        ::close(fd);
        throw Error("cannot write " + path + ": " + osReason(err));
    }
    if (::close(fd) != 0) throw Error("cannot close " + path + ": " + osReason(errno));
}

StagedFile::StagedFile(std::string path) : path_(std::move(path)) {
    if (path_.empty()) throw Error("an output path is empty");
    struct stat st {};
    if (::stat(path_.c_str(), &st) == 0) {
        if (S_ISDIR(st.st_mode)) throw Error(path_ + ": cannot write: it is a directory");
        if (!S_ISREG(st.st_mode)) throw Error(path_ + ": cannot write: it exists and is not a regular file");
    }
    tmpPath_ = makeUniqueFile(path_, "gdpt-");
}

StagedFile::~StagedFile() {
    discard();
}

void StagedFile::sync() const {
    const int fd = ::open(tmpPath_.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) throw Error(path_ + ": cannot write: " + tmpPath_ + ": " + osReason(errno));
    const int rc = ::fsync(fd);
    const int err = errno;
    ::close(fd);
    if (rc != 0 && err != EINVAL) throw Error(path_ + ": cannot write: " + osReason(err));
}

void StagedFile::discard() {
    keepOnSignal(signalSlot_);
    signalSlot_ = -1;
    if (!committed_ && !tmpPath_.empty()) ::unlink(tmpPath_.c_str());
    tmpPath_.clear();
}

void StagedFile::commit() {
    GDPT_CHECK(!committed_ && !tmpPath_.empty());
    sync();
    if (::rename(tmpPath_.c_str(), path_.c_str()) != 0)
        throw Error(path_ + ": cannot move " + tmpPath_ + " into place: " + osReason(errno));
    committed_ = true;
    keepOnSignal(signalSlot_);
    signalSlot_ = -1;
}

OutputSet::OutputSet(std::vector<std::pair<std::string, std::string>> inputs) {
    for (auto& in : inputs)
        if (!in.second.empty()) inputs_.push_back(std::move(in));
}

OutputSet::~OutputSet() = default;

void OutputSet::checkDistinct(const std::string& path, const std::string& what,
                              const std::vector<std::string>& allowedInputs) const {
    for (const auto& input : inputs_) {
        const std::string& inWhat = input.first;
        const std::string& inPath = input.second;
        const bool allowed =
            std::find(allowedInputs.begin(), allowedInputs.end(), inPath) != allowedInputs.end();
        if (!allowed && sameFile(path, inPath))
            throw Error(what + " " + path + " is the " + inWhat + " " + inPath +
                        ", which would be overwritten: choose another output path");
    }
    for (const auto& [outWhat, out] : outputs_)
        if (sameFile(path, out->path()))
            throw Error(what + " " + path + " is also the " + outWhat + " " + out->path() +
                        ": two outputs cannot share a file");
}

StagedFile& OutputSet::add(const std::string& path, const std::string& what) {
    checkDistinct(path, what, {});
    outputs_.emplace_back(what, std::make_unique<StagedFile>(path));
    StagedFile& file = *outputs_.back().second;
    // A command's outputs are written only if it is not interrupted: a signal removes them.
    file.signalSlot_ = removeOnSignal(file.tmpPath_);
    return file;
}

void OutputSet::checkSeparate(const std::string& path, const std::string& what,
                              const std::vector<std::string>& mayBeInputs) const {
    checkDistinct(path, what, mayBeInputs);
}

void OutputSet::commit() {
    for (const auto& o : outputs_) o.second->sync();
    std::set<std::string> dirs;
    for (const auto& o : outputs_)
        dirs.insert(fs::weakly_canonical(fs::absolute(directoryOf(o.second->path()))).string());
    std::vector<std::unique_ptr<DirectoryLock>> locks;  // in sorted order: no deadlock between runs
    for (const std::string& d : dirs) locks.push_back(std::make_unique<DirectoryLock>(d));

    // Keep each existing target under a unique name so that a failed group can restore it.
    struct Done {
        StagedFile* file;
        std::string backup;  // empty: there was no previous file
    };
    std::vector<Done> done;
    auto rollBack = [&] {
        for (auto it = done.rbegin(); it != done.rend(); ++it) {
            if (it->backup.empty())
                ::unlink(it->file->path().c_str());
            else
                ::rename(it->backup.c_str(), it->file->path().c_str());
        }
    };
    for (const auto& o : outputs_) {
        StagedFile& f = *o.second;
        std::string backup;
        if (::access(f.path().c_str(), F_OK) == 0) {
            backup = f.tmpPath() + ".old";
            if (::link(f.path().c_str(), backup.c_str()) != 0) backup.clear();  // no rollback possible
        }
        if (::rename(f.tmpPath().c_str(), f.path().c_str()) != 0) {
            const int err = errno;
            if (!backup.empty()) ::unlink(backup.c_str());
            rollBack();
            throw Error(f.path() + ": cannot move " + f.tmpPath() + " into place: " + osReason(err));
        }
        f.committed_ = true;
        keepOnSignal(f.signalSlot_);
        f.signalSlot_ = -1;
        done.push_back({&f, backup});
    }
    for (const Done& d : done)
        if (!d.backup.empty()) ::unlink(d.backup.c_str());
}

}  // namespace gdpt
