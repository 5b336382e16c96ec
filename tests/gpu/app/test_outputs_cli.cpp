// How gdpt's commands treat their output files: paths checked before any work, no output
// overwriting an input or another output, every write checked (a full disk is an error and
// leaves nothing), unique temporary files so that concurrent runs to one -o never mix bytes,
// and the outputs of one command written together or not at all.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "cli_runner.h"
#include "image/exr_io.h"
#include "image/png_preview.h"

namespace gdpt {
namespace {

namespace fs = std::filesystem;
using test::RunResult;

const std::string kScene = std::string(GDPT_SOURCE_DIR) + "/scenes/cornell_box.gltf";
const std::string kSmall = " --width 16 --height 16 --spp 2 --quiet ";

class OutputsCli : public test::TempDirTest {
protected:
    static bool says(const RunResult& r, const std::string& text) {
        return r.output.find(text) != std::string::npos;
    }
};

// Class: outputs overwriting an input or each other. Each is refused before rendering, and
// the file that would have been overwritten is unchanged.
TEST_F(OutputsCli, OutputsThatWouldOverwriteAnInputOrEachOtherAreRefused) {
    // The EXR and its PNG preview at one path (the PNG used to overwrite the EXR).
    RunResult r = test::runGdpt("render " + kScene + kSmall + "-o " + path("x.png"));
    EXPECT_EQ(r.code, 1) << r.output;
    EXPECT_TRUE(says(r, "PNG preview")) << r.output;
    EXPECT_TRUE(listing().empty());

    // The scene itself.
    fs::copy_file(kScene, path("s.gltf"));  // its buffers are data: URIs
    const std::string scene = test::readText(path("s.gltf"));
    r = test::runGdpt("render " + path("s.gltf") + kSmall + "-o " + path("s.gltf"));
    EXPECT_EQ(r.code, 1) << r.output;
    EXPECT_TRUE(says(r, "is the scene")) << r.output;
    EXPECT_TRUE(test::readText(path("s.gltf")) == scene);
    // The JSON summary onto the EXR.
    r = test::runGdpt("render " + kScene + kSmall + "-o " + path("a.exr") + " --json " + path("a.exr"));
    EXPECT_EQ(r.code, 1) << r.output;
    EXPECT_FALSE(fs::exists(path("a.exr")));

    // solve: its output onto its input layers.
    ASSERT_EQ(test::runGdpt("render " + kScene + kSmall + "--method gpt -o " + path("g.exr")).code, 0);
    const std::string layers = test::readText(path("g.exr"));
    r = test::runGdpt("solve " + path("g.exr") + " --quiet -o " + path("g.exr"));
    EXPECT_EQ(r.code, 1) << r.output;
    EXPECT_TRUE(says(r, "is the input")) << r.output;
    EXPECT_TRUE(test::readText(path("g.exr")) == layers);
    // clone: its output onto its target.
    r = test::runGdpt("clone --source " + path("g.png") + " --target " + path("g.png") + " --mask " +
                      path("g.png") + " --quiet -o " + path("g.png"));
    EXPECT_EQ(r.code, 1) << r.output;
    EXPECT_TRUE(says(r, "would be overwritten")) << r.output;
}

// Class: output paths checked only after the render, without the OS's reason; outputs left
// behind by a failed command. A bad path fails before the scene is even loaded (no device
// line), names the path and the reason, and leaves none of the command's other outputs.
TEST_F(OutputsCli, BadOutputPathsFailBeforeRenderingAndLeaveNothing) {
    const std::string noQuiet = " --width 16 --height 16 --spp 2 ";
    RunResult r = test::runGdpt("render " + kScene + noQuiet + "-o " + path("nodir/out.exr"));
    EXPECT_EQ(r.code, 1);
    EXPECT_TRUE(says(r, "nodir/out.exr") && says(r, "No such file or directory")) << r.output;
    EXPECT_FALSE(says(r, "gdpt: device")) << "the render ran before the path was checked:\n" << r.output;

    r = test::runGdpt("render " + kScene + noQuiet + "-o " + path("out.exr") + " --json " +
                      path("nodir/s.json"));
    EXPECT_EQ(r.code, 1);
    EXPECT_TRUE(says(r, "nodir/s.json")) << r.output;
    EXPECT_FALSE(says(r, "gdpt: device")) << r.output;
    EXPECT_TRUE(listing().empty()) << "out.exr / out.png left behind";

    fs::create_directories(path("out.png"));
    r = test::runGdpt("render " + kScene + noQuiet + "-o " + path("out.exr"));
    EXPECT_EQ(r.code, 1);
    EXPECT_TRUE(says(r, "out.png") && says(r, "is a directory")) << r.output;
    EXPECT_EQ(listing(), std::vector<std::string>{"out.png"});
    EXPECT_TRUE(listing("out.png").empty());
}

// Class: unchecked writes. A full disk (a file-size limit: every write past it fails, as on a
// full disk) is an error naming the OS's reason, and no output — whole or truncated — and no
// temporary file is left. A device that keeps its memory in a memory file (lavapipe of Mesa 25)
// falls under the same limit, and its driver was killed by SIGBUS at the first allocation past
// it (exit 135): gdpt refuses it before any work instead, naming the limit
// (util/file_size_limit.h). Either way: exit 1, the reason, no output.
TEST_F(OutputsCli, AFullDiskIsAnErrorAndLeavesNoOutput) {
    // sh (dash) counts ulimit -f in 512-byte blocks, bash in 1024: 1 or 2 KiB holds none of a
    // G-PT EXR (13 layers).
    const std::string cmd = "sh -c 'ulimit -f 2; exec " + test::gdptBinary() + " render " + kScene +
                            " --width 16 --height 16 --spp 2 --method gpt --quiet -o " + path("out.exr") +
                            "' 2>&1";
    FILE* pipe = popen(cmd.c_str(), "r");
    ASSERT_NE(pipe, nullptr);
    std::string output;
    char buf[512];
    while (std::fgets(buf, sizeof buf, pipe)) output += buf;
    const int status = pclose(pipe);
    ASSERT_TRUE(WIFEXITED(status)) << "killed by a signal (SIGXFSZ?): " << output;
    EXPECT_EQ(WEXITSTATUS(status), 1) << output;
    const bool writeFailed = output.find("File too large") != std::string::npos;
    const bool deviceRefused = output.find("file-size limit (ulimit -f)") != std::string::npos &&
                               output.find("memory file") != std::string::npos;
    EXPECT_TRUE(writeFailed || deviceRefused) << output;
    EXPECT_EQ(output.find("wrote"), std::string::npos) << output;
    EXPECT_TRUE(listing().empty());
}

// Class: concurrent runs to one -o shared a temporary file (corrupt EXRs, the EXR of one run
// beside the PNG of another, the loser failing on rename). Four renders with four seeds
// write one -o at the same time; each succeeds, and what is left is one run's EXR, PNG and
// JSON, whole and matching (compared with the same seeds rendered alone).
TEST_F(OutputsCli, ConcurrentRendersToOneOutputNeverMix) {
    const std::string args = " --width 32 --height 32 --spp 4 --method pt --quiet ";
    const int runs = 4;
    for (int seed = 1; seed <= runs; ++seed) {
        const std::string base = path("alone" + std::to_string(seed));
        ASSERT_EQ(test::runGdpt("render " + kScene + args + "--seed " + std::to_string(seed) + " -o " + base +
                                ".exr")
                      .code,
                  0);
    }
    for (int round = 0; round < 3; ++round) {
        std::string cmd;
        for (int seed = 1; seed <= runs; ++seed)
            cmd += test::gdptBinary() + " render " + kScene + args + "--seed " + std::to_string(seed) +
                   " -o " + path("out.exr") + " --json " + path("out.json") + " & ";
        cmd += "fails=0; for j in $(jobs -p); do wait $j || fails=$((fails+1)); done; echo $fails";
        FILE* pipe = popen(("bash -c '" + cmd + "' 2>&1").c_str(), "r");
        ASSERT_NE(pipe, nullptr);
        std::string output;
        char buf[512];
        while (std::fgets(buf, sizeof buf, pipe)) output += buf;
        pclose(pipe);
        EXPECT_EQ(output, "0\n") << "a concurrent render failed: " << output;

        const nlohmann::json j = nlohmann::json::parse(test::readText(path("out.json")));
        const std::string seed = std::to_string(j.at("seed").get<int>());
        // (compared as booleans: a failure would print megabytes of EXR)
        EXPECT_TRUE(test::readText(path("out.exr")) == test::readText(path("alone" + seed + ".exr")))
            << "EXR not seed " << seed << "'s";
        EXPECT_TRUE(test::readText(path("out.png")) == test::readText(path("alone" + seed + ".png")))
            << "PNG not seed " << seed << "'s";
        for (const std::string& name : listing()) EXPECT_NE(name[0], '.') << "temporary file left: " << name;
    }
}

// Class: converge wrote a 0-byte plot and said "wrote". A reference with no finite pixel
// and an empty method list are refused before any render, and the output directory gets no
// file at all.
TEST_F(OutputsCli, ConvergeRefusesWhatCannotBeMeasuredAndWritesNothing) {
    Image nan(16, 16);
    for (int c = 0; c < 3; ++c)
        for (float& v : nan.plane(c)) v = std::nanf("");
    writeExr(path("nan.exr"), nan);
    const std::string out = path("conv");
    RunResult r = test::runGdpt("converge " + kScene + " --reference " + path("nan.exr") +
                                " --width 16 --height 16 --times 0.2 --repeats 1 --methods pt -o " + out);
    EXPECT_EQ(r.code, 1) << r.output;
    EXPECT_TRUE(says(r, "nan.exr") && says(r, "no finite")) << r.output;
    EXPECT_FALSE(says(r, "wrote")) << r.output;
    EXPECT_TRUE(listing("conv").empty());

    r = test::runGdpt("converge " + kScene + " --reference " + path("nan.exr") + " --methods '' -o " + out);
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_TRUE(listing("conv").empty());

    // A method of sequences is refused before any render.
    r = test::runGdpt("converge " + kScene + " --reference " + path("nan.exr") + " --methods pt,tgpt -o " +
                      out);
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_TRUE(says(r, "tgpt renders sequences")) << r.output;
    EXPECT_TRUE(listing("conv").empty());
}

// Class: --time 0 silently rendered 64 spp; --alpha 0 with an L1 reconstruction failed with
// exit 1 without naming the flag. Both are usage errors (2) that name the flag.
TEST_F(OutputsCli, ImpossibleBudgetsAndWeightsAreUsageErrors) {
    RunResult r = test::runGdpt("render " + kScene + kSmall + "--time 0 -o " + path("t.exr"));
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_TRUE(says(r, "--time")) << r.output;
    r = test::runGdpt("render " + kScene + kSmall + "--method gpt --alpha 0 -o " + path("a.exr"));
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_TRUE(says(r, "--alpha")) << r.output;
    // alpha 0 is a valid L2 problem (gradients only, up to a constant that the solver fixes).
    r = test::runGdpt("render " + kScene + kSmall + "--method gpt --recon l2 --alpha 0 -o " + path("a.exr"));
    EXPECT_EQ(r.code, 0) << r.output;
    EXPECT_TRUE(listing() == (std::vector<std::string>{"a.exr", "a.png"}));
}

}  // namespace
}  // namespace gdpt
