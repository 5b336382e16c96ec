// `gdpt render --checkpoint/--resume` end to end: an interrupted render leaves a checkpoint
// from which a resumed render reaches exactly (bit for bit) the image of a render that was
// never interrupted, for PT and G-PT; a checkpoint of another render, a corrupt one and a
// plain EXR are refused with one line naming the file (exit 1) and no output.
//
// Why bit-identity must hold: sample s of pixel p always uses the random stream (p, s, seed),
// and with --spp the batch schedule (1, 2, 4, ... 16 spp per batch here) is a function of
// the samples done; a checkpoint is written at a batch boundary with the next batch size,
// so the resumed run merges the same batches in the same order into the same float32
// statistics (restored bit for bit from FLOAT EXR channels).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli_runner.h"
#include "image/exr_io.h"
#include "render/passes/edge_options.h"
#include "same_bits.h"

namespace gdpt {
namespace {

namespace fs = std::filesystem;
using test::RunResult;

const std::string kScene = std::string(GDPT_SOURCE_DIR) + "/scenes/cornell_box.gltf";
// 16x16: the largest batch is 16 spp for PT and G-PT alike (commands.cpp batchLimit).
const std::string kSize = " --width 16 --height 16 ";

class CheckpointCli : public test::TempDirTest, public ::testing::WithParamInterface<std::string> {
protected:
    std::string render(const std::string& extra) const {
        return "render " + kScene + kSize + " --method " + GetParam() + " --seed 7 --quiet --validate " +
               extra;
    }
};

std::uint64_t pathsCompleted(const std::string& jsonPath) {
    std::ifstream in(jsonPath);
    return nlohmann::json::parse(in)["paths_completed"].get<std::uint64_t>();
}

// Paths per camera sample of a render's --json: one per pixel, and G-PT's edge pixels
// (render/passes/edge_pass.h) `factor` more each.
std::uint64_t pathsPerSample(const std::string& jsonPath, std::uint64_t pixels) {
    std::ifstream in(jsonPath);
    const auto j = nlohmann::json::parse(in);
    if (j.contains("edge_samples"))
        pixels += j["edge_samples"]["factor"].get<std::uint64_t>() *
                  j["edge_samples"]["pixels"].get<std::uint64_t>();
    return pixels;
}

// A finished 15 spp render (batches 1+2+4+8, none truncated) continued to 63 spp equals a
// 63 spp render; the resumed run traced only the 48 new samples per pixel, so the state
// was used rather than re-rendered.
TEST_P(CheckpointCli, ResumedRenderEqualsUninterruptedRender) {
    ASSERT_EQ(test::runGdpt(render("--spp 15 --checkpoint " + path("c.exr") + " -o " + path("a.exr"))).code,
              0);
    ASSERT_TRUE(fs::exists(path("c.exr")));
    EXPECT_EQ(readExrAttributes(path("c.exr")).at("gdpt.spp"), "15");
    const RunResult resumed = test::runGdpt(
        render("--spp 63 --resume " + path("c.exr") + " -o " + path("r.exr") + " --json " + path("r.json")));
    ASSERT_EQ(resumed.code, 0) << resumed.output;
    ASSERT_EQ(test::runGdpt(render("--spp 63 -o " + path("u.exr"))).code, 0);
    test::expectSameExrLayers(path("r.exr"), path("u.exr"));
    EXPECT_EQ(pathsCompleted(path("r.json")), 48u * pathsPerSample(path("r.json"), 16u * 16u));
}

// SIGINT during a long render (polled until the first periodic checkpoint exists, so the
// signal handler is installed) exits 130 and leaves a checkpoint with D spp and no output;
// resuming to D + 32 spp equals an uninterrupted D + 32 spp render.
TEST_P(CheckpointCli, InterruptedRenderResumesToTheUninterruptedResult) {
    const std::string ckpt = path("i.exr");
    const std::string cmd =
        std::string(GDPT_BINARY) + " " +
        render("--spp 1000000 --checkpoint " + ckpt + " --checkpoint-every 0.2 -o " + path("never.exr")) +
        " 2>/dev/null & pid=$!; for k in $(seq 1200); do [ -e " + ckpt +
        " ] && break; sleep 0.05; done; sleep 0.3; kill -INT $pid; wait $pid; echo $?";
    FILE* pipe = popen(cmd.c_str(), "r");
    ASSERT_NE(pipe, nullptr);
    int rc = -1;
    ASSERT_EQ(std::fscanf(pipe, "%d", &rc), 1);
    pclose(pipe);
    ASSERT_EQ(rc, 130);
    EXPECT_FALSE(fs::exists(path("never.exr")));
    EXPECT_TRUE(temporaryFiles().empty());
    const ExrAttributes a = readExrAttributes(ckpt);
    const unsigned long done = std::stoul(a.at("gdpt.spp"));
    ASSERT_GT(done, 0u);
    ASSERT_LT(done, 1000000u) << "the render finished before the interrupt";
    EXPECT_EQ(a.at("gdpt.id.method"), GetParam());
    // The checkpoint is a valid EXR whose default channels are the image so far.
    EXPECT_EQ(readExrLayer(ckpt).width(), 16);

    const std::string total = std::to_string(done + 32);
    const RunResult resumed =
        test::runGdpt(render("--spp " + total + " --resume " + ckpt + " -o " + path("r.exr")));
    ASSERT_EQ(resumed.code, 0) << resumed.output;
    ASSERT_EQ(test::runGdpt(render("--spp " + total + " -o " + path("u.exr"))).code, 0);
    test::expectSameExrLayers(path("r.exr"), path("u.exr"));
}

INSTANTIATE_TEST_SUITE_P(Methods, CheckpointCli, ::testing::Values("pt", "gpt"));

class CheckpointRefusal : public test::TempDirTest {
protected:
    void SetUp() override {
        TempDirTest::SetUp();
        const RunResult r =
            test::runGdpt("render " + kScene + kSize + "--method pt --spp 3 --seed 7 --quiet --checkpoint " +
                          path("c.exr") + " -o " + path("a.exr"));
        ASSERT_EQ(r.code, 0) << r.output;
    }
    // Resuming with `flags` (default: the checkpoint's own settings) fails with exit 1, one
    // line naming `file` and containing `why`, and no output file.
    // A 2-spp G-PT checkpoint written with `written` must not continue with `resumed`.
    void expectGptOptionRefused(const std::string& written, const std::string& resumed,
                                const std::string& why) {
        const std::string c = path("g.exr");
        const RunResult r =
            test::runGdpt("render " + kScene + kSize + "--spp 2 --seed 7 --method gpt " + written +
                          " --quiet --checkpoint " + c + " -o " + path("g_out.exr"));
        ASSERT_EQ(r.code, 0) << r.output;
        expectRefused(c, kSize + "--spp 4 --seed 7 --method gpt " + resumed, why);
    }

    void expectRefused(const std::string& file, const std::string& flags, const std::string& why) {
        const std::string out = path("out.exr");
        const RunResult r =
            test::runGdpt("render " + kScene + " --quiet --resume " + file + " -o " + out + " " + flags);
        EXPECT_EQ(r.code, 1) << flags << ": " << r.output;
        EXPECT_NE(r.output.find(file), std::string::npos) << r.output;
        EXPECT_NE(r.output.find(why), std::string::npos) << "expected '" << why << "' in: " << r.output;
        EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << "one line: " << r.output;
        EXPECT_FALSE(fs::exists(out));
    }
};

TEST_F(CheckpointRefusal, CheckpointOfAnotherRenderIsRefused) {
    const std::string c = path("c.exr");
    // The checkpoint is PT's (SetUp); gpt is the default method.
    const std::string same = kSize + "--method pt --spp 8 --seed 7";
    expectRefused(c, kSize + "--method pt --spp 8 --seed 8", "seed");
    expectRefused(c, " --width 16 --height 15 --method pt --spp 8 --seed 7", "height");
    expectRefused(c, kSize + "--spp 8 --seed 7", "method");
    expectRefused(c, same + " --max-depth 3", "max_depth");
    expectRefused(c, same + " --env 0.5", "env");
    expectRefused(c, kSize + "--method pt --spp 2 --seed 7", "more than --spp 2");
    // Another scene: the same file name and geometry, a slightly wider camera.
    const std::string other = path("cornell_box.gltf");
    std::ifstream in(kScene);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string fov = "\"yfov\": 0.34";
    const auto pos = text.find(fov);
    ASSERT_NE(pos, std::string::npos) << "the scene's camera has yfov 0.34...";
    text.replace(pos, fov.size(), "\"yfov\": 0.35");
    std::ofstream(other) << text;
    const RunResult r =
        test::runGdpt("render " + other + " --quiet --resume " + c + " -o " + path("out.exr") + same);
    EXPECT_EQ(r.code, 1) << r.output;
    EXPECT_NE(r.output.find("scene_fingerprint"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(path("out.exr")));
}

// G-PT records its edge samples per camera sample (render/passes/edge_pass.h): a checkpoint
// continues only with the same factor.
TEST_F(CheckpointRefusal, GptCheckpointWithOtherEdgeSamplesIsRefused) {
    expectGptOptionRefused("--edge-samples 2", "--edge-samples 3", "edge_samples");
}

// Demodulation keeps other statistics (gpt_pass.h); the Cornell box has no texture, so auto
// is off there and on differs.
TEST_F(CheckpointRefusal, GptCheckpointWithOtherDemodulationIsRefused) {
    expectGptOptionRefused("--demodulate on", "--demodulate off", "demodulate");
}

TEST_F(CheckpointRefusal, CorruptOrForeignCheckpointIsRefused) {
    const std::string flags = kSize + "--spp 8 --seed 7";
    // Truncated.
    std::ifstream in(path("c.exr"), std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream(path("cut.exr"), std::ios::binary) << bytes.substr(0, bytes.size() / 2);
    expectRefused(path("cut.exr"), flags, "cannot read EXR");
    // A valid EXR that is not a checkpoint (the render's output).
    expectRefused(path("a.exr"), flags, "not a gdpt checkpoint");
    // A checkpoint whose header claims fewer samples than its counts hold.
    ExrAttributes attributes = readExrAttributes(path("c.exr"));
    attributes["gdpt.spp"] = "2";
    writeExr(path("lie.exr"), readExr(path("c.exr")), attributes);
    expectRefused(path("lie.exr"), flags, "sample count");
    // A missing state layer.
    auto layers = readExr(path("c.exr"));
    layers.erase(std::remove_if(layers.begin(), layers.end(),
                                [](const NamedLayer& l) { return l.name == "state0.m2"; }),
                 layers.end());
    writeExr(path("nolayer.exr"), layers, readExrAttributes(path("c.exr")));
    expectRefused(path("nolayer.exr"), flags, "state0.m2");
}

// Rewrites checkpoint `from` into `to` with `edit` applied to layer `name`'s pixel (x, y) in
// all three channels, and `attributes` changed as given.
void editCheckpoint(const std::string& from, const std::string& to, const std::string& name, int x, int y,
                    float value, const ExrAttributes& changed = {}) {
    auto layers = readExr(from);
    for (NamedLayer& l : layers)
        if (l.name == name)
            for (int c = 0; c < 3; ++c) l.image.at(x, y, c) = value;
    ExrAttributes attributes = readExrAttributes(from);
    for (const auto& [key, text] : changed) attributes[key] = text;
    writeExr(to, layers, attributes);
}

// Guards the class "checkpoint statistics are validated on resume": a checkpoint whose
// sample counts do not fit its header (sampler_state.h: path statistics hold gdpt.spp
// samples in every pixel, emitter supersampling's 0 or gdpt.spp), or whose M2 is negative,
// would resume into an image labelled with one spp that holds another. Each is refused with
// one line naming the file, the layer and the first bad pixel.
TEST_F(CheckpointRefusal, CheckpointWithInconsistentStatisticsIsRefused) {
    const std::string c = path("c.exr");  // PT, 3 spp (SetUp)
    const std::string flags = kSize + "--method pt --spp 64 --seed 7";
    editCheckpoint(c, path("zero.exr"), "state0.count", 5, 2, 0.0f);
    expectRefused(path("zero.exr"), flags, "state0.count (path samples): pixel (5, 2) has sample count 0");
    editCheckpoint(c, path("fewer.exr"), "state0.count", 1, 0, 2.0f);
    expectRefused(path("fewer.exr"), flags, "pixel (1, 0) has sample count 2, expected 3 (gdpt.spp)");
    // The header claims more samples than every pixel holds.
    editCheckpoint(c, path("more.exr"), "", 0, 0, 0.0f, {{"gdpt.spp", "32"}});
    expectRefused(path("more.exr"), flags, "pixel (0, 0) has sample count 3, expected 32 (gdpt.spp)");
    editCheckpoint(c, path("visible.exr"), "state1.count", 3, 4, 1.0f);
    expectRefused(path("visible.exr"), flags, "state1.count (visible emission): pixel (3, 4)");
    editCheckpoint(c, path("m2.exr"), "state0.m2", 6, 1, -0.5f);
    expectRefused(path("m2.exr"), flags, "state0.m2 (path samples): pixel (6, 1) has M2 -0.5");
    // A missing buffer (the header and the layers agree on one): named by its first layer.
    auto layers = readExr(c);
    layers.erase(std::remove_if(layers.begin(), layers.end(),
                                [](const NamedLayer& l) { return l.name.rfind("state1.", 0) == 0; }),
                 layers.end());
    ExrAttributes attributes = readExrAttributes(c);
    attributes["gdpt.buffers"] = "1";
    writeExr(path("one.exr"), layers, attributes);
    expectRefused(path("one.exr"), flags, "layer 'state1.mean' (visible emission) is missing");
}

// The same for G-PT: every path statistic of a pixel (central, neighbours, gradients,
// direct) merged the same samples, so one differing count is a corrupt checkpoint.
TEST_F(CheckpointRefusal, GptCheckpointWithInconsistentCountsIsRefused) {
    const std::string c = path("g.exr");
    // No edge samples: every pixel's counts are then gdpt.spp (the edge samples' own checks are
    // the next test's).
    const RunResult r = test::runGdpt("render " + kScene + kSize + "--spp 2 --seed 7 --method gpt --quiet " +
                                      "--edge-samples 0 --checkpoint " + c + " -o " + path("g_out.exr"));
    ASSERT_EQ(r.code, 0) << r.output;
    editCheckpoint(c, path("g3.exr"), "state3.count", 2, 9, 4.0f);
    expectRefused(
        path("g3.exr"), kSize + "--spp 4 --seed 7 --method gpt --edge-samples 0",
        "state3.count (gpt neighbor left): pixel (2, 9) has sample count 4, but state0.count has 2");
}

// With --edge-samples auto the checkpoint records "auto" and its counts carry the factor the
// probe chose: it resumes, and a listed pixel whose count implies another factor, or one above
// the rule's largest, is refused.
TEST_F(CheckpointRefusal, GptCheckpointWithTheAutomaticEdgeFactorResumesAndIsChecked) {
    const std::string c = path("e.exr");
    const std::string size = " --width 64 --height 64 ";  // the Cornell box's rule gives 2 here
    const RunResult r =
        test::runGdpt("render " + kScene + size + "--spp 2 --seed 7 --method gpt --quiet " + "--checkpoint " +
                      c + " -o " + path("e_out.exr") + " --json " + path("e.json"));
    ASSERT_EQ(r.code, 0) << r.output;
    EXPECT_EQ(readExrAttributes(c).at("gdpt.id.edge_samples"), "auto");
    EXPECT_EQ(readExrAttributes(c).at("gdpt.id.edge_sample_pixels"), kEdgeSamplePixels);
    std::ifstream in(path("e.json"));
    const int factor = nlohmann::json::parse(in)["edge_samples"]["factor"].get<int>();
    ASSERT_EQ(factor, int(kAutoEdgeSamplesMax));
    const float listedCount = 2.0f * float(1 + factor);  // 2 spp x (1 + 2)
    // Two listed pixels of the checkpoint.
    std::vector<std::pair<int, int>> edges;
    for (const NamedLayer& l : readExr(c))
        if (l.name == "state0.count")
            for (int y = 0; y < l.image.height(); ++y)
                for (int x = 0; x < l.image.width(); ++x)
                    if (l.image.at(x, y, 0) == listedCount) edges.emplace_back(x, y);
    ASSERT_GE(edges.size(), 2u);
    const RunResult resumed =
        test::runGdpt("render " + kScene + size + "--spp 4 --seed 7 --method gpt --quiet " + "--resume " + c +
                      " -o " + path("r.exr"));
    EXPECT_EQ(resumed.code, 0) << resumed.output;
    // Another factor (1) in the second listed pixel than in the first.
    const auto [x, y] = edges[1];
    const std::string where = "pixel (" + std::to_string(x) + ", " + std::to_string(y) + ")";
    const std::string flags = size + "--spp 4 --seed 7 --method gpt";
    auto layers = readExr(c);
    for (NamedLayer& l : layers)
        if (l.name.size() > 6 && l.name.substr(l.name.size() - 6) == ".count" && l.name != "state1.count" &&
            l.image.at(x, y, 0) == listedCount)
            for (int ch = 0; ch < 3; ++ch) l.image.at(x, y, ch) = 4.0f;
    writeExr(path("mixed.exr"), layers, readExrAttributes(c));
    expectRefused(path("mixed.exr"), flags, where + " has sample count 4, expected 2 (gdpt.spp) or 6");
    // A factor the rule never gives (3), in every listed pixel: the first one is named.
    layers = readExr(c);
    for (NamedLayer& l : layers)
        if (l.name.size() > 6 && l.name.substr(l.name.size() - 6) == ".count")
            for (int yy = 0; yy < l.image.height(); ++yy)
                for (int xx = 0; xx < l.image.width(); ++xx)
                    if (l.image.at(xx, yy, 0) == listedCount)
                        for (int ch = 0; ch < 3; ++ch) l.image.at(xx, yy, ch) = 8.0f;
    writeExr(path("eight.exr"), layers, readExrAttributes(c));
    const auto [x0, y0] = edges[0];
    expectRefused(path("eight.exr"), flags,
                  "pixel (" + std::to_string(x0) + ", " + std::to_string(y0) + ") has sample count 8");
    // A checkpoint from before the neighbours were listed (no edge_sample_pixels) is refused.
    ExrAttributes older = readExrAttributes(c);
    older.erase("gdpt.id.edge_sample_pixels");
    writeExr(path("older.exr"), readExr(c), older);
    expectRefused(path("older.exr"), flags, "does not record edge_sample_pixels");
    // One from before the pairs' weights counted the two pixels' samples is refused too.
    EXPECT_EQ(readExrAttributes(c).at("gdpt.id.pair_weights"), kPairWeights);
    ExrAttributes equalWeights = readExrAttributes(c);
    equalWeights.erase("gdpt.id.pair_weights");
    writeExr(path("equal_weights.exr"), readExr(c), equalWeights);
    expectRefused(path("equal_weights.exr"), flags, "does not record pair_weights");
}

// Guards the class "a refused resume names the real difference": another method or size
// also changes the largest batch (max_batch_spp, a function of both), which sorts first; the
// message must name the method or the size. 128x128: PT's largest batch is 16, G-PT's 4, and
// PT's at 256x128 is 8.
TEST_F(CheckpointRefusal, MethodOrSizeMismatchIsNamedBeforeTheBatchSize) {
    const std::string c = path("big.exr");
    const std::string size = " --width 128 --height 128 ";
    const RunResult r = test::runGdpt("render " + kScene + size + "--method pt --spp 1 --seed 7 --quiet " +
                                      "--checkpoint " + c + " -o " + path("big_out.exr"));
    ASSERT_EQ(r.code, 0) << r.output;
    expectRefused(c, size + "--method gpt --spp 2 --seed 7",
                  "rendered with method pt, this render has method gpt");
    expectRefused(c, " --width 256 --height 128 --method pt --spp 2 --seed 7",
                  "rendered with width 128, this render has width 256");
}

TEST_F(CheckpointRefusal, HelpDocumentsTheFlagsAndCheckpointEveryNeedsCheckpoint) {
    const RunResult help = test::runGdpt("render --help");
    for (const char* flag : {"--checkpoint", "--checkpoint-every", "--resume"})
        EXPECT_NE(help.output.find(flag), std::string::npos) << flag;
    EXPECT_EQ(test::runGdpt("render " + kScene + " --checkpoint-every 5 -o " + path("x.exr")).code, 2);
}

}  // namespace
}  // namespace gdpt
