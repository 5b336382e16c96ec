// Staged output files (util/output_files.h) and the image writers on top of them: outputs
// appear whole or not at all, with unique temporary names, checked writes, refusal of
// outputs that would overwrite an input or each other, and group commits.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>

#include "image/atomic_write.h"
#include "image/exr_io.h"
#include "image/png_preview.h"
#include "temp_dir.h"
#include "util/error.h"
#include "util/interrupt.h"
#include "util/output_files.h"

namespace gdpt {
namespace {

namespace fs = std::filesystem;

class OutputFiles : public test::TempDirTest {
protected:
    static void put(const std::string& p, const std::string& text) {
        std::ofstream(p, std::ios::binary) << text;
    }
};

// Expects `f` to throw gdpt::Error whose message contains every one of `parts`.
void expectError(const std::function<void()>& f, const std::vector<std::string>& parts) {
    try {
        f();
        ADD_FAILURE() << "no error";
    } catch (const Error& e) {
        for (const std::string& p : parts)
            EXPECT_NE(std::string(e.what()).find(p), std::string::npos) << e.what();
    }
}

TEST_F(OutputFiles, UncommittedFileLeavesNothingBehind) {
    {
        StagedFile f(path("a.txt"));
        writeBytes(f.tmpPath(), "abc", 3);
        EXPECT_EQ(listing().size(), 1u);  // the temporary file, under another name
        EXPECT_FALSE(fs::exists(path("a.txt")));
    }
    EXPECT_TRUE(listing().empty());
}

TEST_F(OutputFiles, CommitPutsTheWholeFileInPlace) {
    put(path("a.txt"), "old");
    StagedFile f(path("a.txt"));
    writeBytes(f.tmpPath(), "new text", 8);
    EXPECT_EQ(test::readText(path("a.txt")), "old");  // untouched until the commit
    f.commit();
    EXPECT_EQ(test::readText(path("a.txt")), "new text");
    EXPECT_EQ(listing(), std::vector<std::string>{"a.txt"});
}

// Two writers of one target (two runs with the same -o) never share a temporary file.
TEST_F(OutputFiles, ConcurrentWritersOfOneTargetGetDistinctTemporaryFiles) {
    StagedFile a(path("out.exr"));
    StagedFile b(path("out.exr"));
    EXPECT_NE(a.tmpPath(), b.tmpPath());
    writeBytes(a.tmpPath(), "AAAA", 4);
    writeBytes(b.tmpPath(), "BB", 2);
    a.commit();
    EXPECT_EQ(test::readText(path("out.exr")), "AAAA");
    b.commit();
    EXPECT_EQ(test::readText(path("out.exr")), "BB");
    EXPECT_EQ(listing(), std::vector<std::string>{"out.exr"});
}

// A bad output path is found when the output is staged (before any work), with the reason.
TEST_F(OutputFiles, BadPathsAreRefusedUpFrontWithTheReason) {
    expectError([&] { StagedFile f(path("nodir/out.exr")); }, {"nodir/out.exr", "No such file or directory"});
    fs::create_directories(path("out.png"));
    expectError([&] { StagedFile f(path("out.png")); }, {"out.png", "is a directory"});
    expectError([] { StagedFile f("/dev/null"); }, {"/dev/null", "not a regular file"});
    if (::geteuid() != 0) {  // root may write anywhere
        fs::create_directories(path("ro"));
        fs::permissions(path("ro"), fs::perms::owner_read | fs::perms::owner_exec);
        expectError([&] { StagedFile f(path("ro/x.exr")); }, {"ro/x.exr", "Permission denied"});
    }
}

TEST_F(OutputFiles, AnOutputMayNotBeAnInputOrAnotherOutput) {
    put(path("scene.gltf"), "{}");
    fs::create_directories(path("sub"));
    OutputSet outputs({{"scene", path("scene.gltf")}, {"unused", ""}});
    // The same file under another spelling, and through a symbolic link.
    expectError([&] { outputs.add(path("sub/../scene.gltf"), "-o"); }, {"-o", "is the scene", "overwritten"});
    fs::create_symlink(path("scene.gltf"), path("link.gltf"));
    expectError([&] { outputs.add(path("link.gltf"), "-o"); }, {"is the scene"});
    outputs.add(path("x.png"), "-o");
    // Not existing yet, and spelt differently: still one file.
    expectError([&] { outputs.add(path("sub/../x.png"), "PNG preview of -o"); },
                {"PNG preview of -o", "is also the -o", "cannot share"});
    // A checkpoint may continue the file it resumes from, but not overwrite an output.
    outputs.checkSeparate(path("scene.gltf"), "--checkpoint", {path("scene.gltf")});
    expectError([&] { outputs.checkSeparate(path("x.png"), "--checkpoint"); },
                {"--checkpoint", "is also the -o"});
    EXPECT_TRUE(fs::exists(path("scene.gltf")));
    EXPECT_EQ(test::readText(path("scene.gltf")), "{}");
}

// The outputs of one command appear together or not at all: if one cannot be moved into
// place, the others are rolled back (a previous file restored, a new one removed).
TEST_F(OutputFiles, AGroupCommitsTogetherOrNotAtAll) {
    put(path("a.exr"), "previous a");
    {
        OutputSet outputs;
        StagedFile& a = outputs.add(path("a.exr"), "-o");
        StagedFile& b = outputs.add(path("b.png"), "PNG");
        StagedFile& c = outputs.add(path("c.json"), "--json");
        writeBytes(a.tmpPath(), "new a", 5);
        writeBytes(b.tmpPath(), "new b", 5);
        writeBytes(c.tmpPath(), "new c", 5);
        // c.json becomes a non-empty directory after it was checked: its rename fails.
        fs::create_directories(path("c.json/inside"));
        expectError([&] { outputs.commit(); }, {"c.json"});
    }
    EXPECT_EQ(test::readText(path("a.exr")), "previous a");
    EXPECT_FALSE(fs::exists(path("b.png")));
    EXPECT_EQ(listing(), (std::vector<std::string>{"a.exr", "c.json"}));

    fs::remove_all(path("c.json"));
    OutputSet outputs;
    writeBytes(outputs.add(path("a.exr"), "-o").tmpPath(), "A", 1);
    writeBytes(outputs.add(path("b.png"), "PNG").tmpPath(), "B", 1);
    outputs.commit();
    EXPECT_EQ(test::readText(path("a.exr")), "A");
    EXPECT_EQ(test::readText(path("b.png")), "B");
    EXPECT_EQ(listing(), (std::vector<std::string>{"a.exr", "b.png"}));
}

// Runs `write` in a child process whose files may not grow past `limitBytes` (RLIMIT_FSIZE,
// the way a full disk looks to a writer: every write past it fails). Returns the child's
// exit code: 0 if write() returned normally, 1 if it threw gdpt::Error, 2 otherwise.
int underFileSizeLimit(rlim_t limitBytes, const std::function<void()>& write) {
    const pid_t pid = ::fork();
    if (pid == 0) {
        std::signal(SIGXFSZ, SIG_IGN);  // as gdpt does (util/interrupt.h): an error, not a kill
        rlimit limit{limitBytes, limitBytes};
        ::setrlimit(RLIMIT_FSIZE, &limit);
        try {
            write();
        } catch (const Error&) {
            ::_exit(1);
        } catch (...) {
            ::_exit(2);
        }
        ::_exit(0);
    }
    int status = 0;
    ::waitpid(pid, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : 100 + WTERMSIG(status);
}

Image noise(int w, int h) {
    Image image(w, h);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c) image.at(x, y, c) = u(rng);
    return image;
}

// A full disk: every writer fails with an error and leaves no file (stb_image_write's own
// file writer ignores failed writes and reports success with a truncated PNG).
TEST_F(OutputFiles, AFullDiskFailsTheWriteAndLeavesNothing) {
    const Image image = noise(64, 64);  // 12 KiB of noise: PNG and EXR are both > 4 KiB
    EXPECT_EQ(underFileSizeLimit(4096, [&] { writePngPreview(path("p.png"), image); }), 1);
    EXPECT_EQ(underFileSizeLimit(4096, [&] { writeExr(path("e.exr"), image); }), 1);
    EXPECT_EQ(
        underFileSizeLimit(4096, [&] { writeTextFileAtomically(path("t.json"), std::string(5000, 'x')); }),
        1);
    EXPECT_TRUE(listing().empty());
    // The same writes succeed without the limit (the limit is what failed them).
    EXPECT_EQ(underFileSizeLimit(RLIM_INFINITY, [&] { writePngPreview(path("p.png"), image); }), 0);
    EXPECT_EQ(readPng(path("p.png")).width(), 64);
}

}  // namespace
}  // namespace gdpt

namespace gdpt {
namespace {

// SIGTERM, then SIGKILL moments later (what mpirun and batch schedulers send): the first
// signal removes a command's staged outputs at once, so the kill leaves no temporary file.
// The child ends with _exit right after the signal, skipping every destructor, as SIGKILL would.
class SignalledOutputs : public test::TempDirTest {};

TEST_F(SignalledOutputs, AKillRightAfterTheFirstSignalLeavesNoTemporaryFile) {
    for (const bool signalled : {false, true}) {
        const pid_t pid = ::fork();
        if (pid == 0) {
            installInterruptHandlers();
            OutputSet outputs(std::vector<std::pair<std::string, std::string>>{});
            StagedFile& exr = outputs.add(path("out.exr"), "-o");
            (void)outputs.add(path("out.png"), "PNG preview");
            writeBytes(exr.tmpPath(), "partial", 7);
            if (signalled) std::raise(SIGTERM);
            ::_exit(0);
        }
        int status = 0;
        ::waitpid(pid, &status, 0);
        ASSERT_TRUE(WIFEXITED(status));
        if (signalled) {
            EXPECT_TRUE(listing().empty()) << listing().size() << " files left, e.g. " << listing().front();
        } else {
            // The control: killed without a signal first, the temporary files stay (only the
            // command's own cleanup or a signal removes them).
            EXPECT_EQ(temporaryFiles().size(), 2u);
            for (const std::string& name : listing()) std::filesystem::remove(path(name));
        }
    }
}

}  // namespace
}  // namespace gdpt
