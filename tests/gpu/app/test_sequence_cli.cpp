// `gdpt render --frames A:B`: every frame written (EXR + PNG) with its own seed and a JSON
// summary; a frame of an animated scene is, bit for bit, the render of the static scene of its
// pose (computed here by hand from the keys scenes/make_scenes.py writes), after other frames
// were rendered by the same process; an interrupt leaves exactly the complete frames; usage
// errors leave nothing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_runner.h"
#include "same_bits.h"
#include "temp_dir.h"

namespace gdpt {
namespace {

namespace fs = std::filesystem;
using test::runGdpt;
using test::RunResult;

const std::string kMovingBox = std::string(GDPT_SOURCE_DIR) + "/scenes/moving_box.gltf";
const std::string kCornell = std::string(GDPT_SOURCE_DIR) + "/scenes/cornell_box.gltf";

class SequenceCli : public test::TempDirTest {
protected:
    std::vector<std::string> files() const {
        std::vector<std::string> names;
        for (const auto& e : fs::directory_iterator(dir_)) names.push_back(e.path().filename().string());
        std::sort(names.begin(), names.end());
        return names;
    }
};

nlohmann::json readJson(const std::string& path) {
    std::ifstream in(path);
    return nlohmann::json::parse(in);
}

TEST_F(SequenceCli, EveryFrameIsWrittenWithItsSeedAndSummarised) {
    const RunResult r = runGdpt(
        "render " + kMovingBox + " --frames 2:4 --fps 2 --spp 2 --width 16 --height 16 " +
        "--method pt --seed 5 --no-video -o " + path("seq/f_%03d.exr") + " --json " + path("seq.json"));
    ASSERT_EQ(r.code, 0) << r.output;
    EXPECT_NE(r.output.find("frame 3 (2/3, t = 1.5 s): wrote"), std::string::npos) << r.output;
    for (int f = 2; f <= 4; ++f) {
        EXPECT_TRUE(fs::exists(path("seq/f_00" + std::to_string(f) + ".exr"))) << f;
        EXPECT_TRUE(fs::exists(path("seq/f_00" + std::to_string(f) + ".png"))) << f;
    }
    EXPECT_EQ(std::distance(fs::directory_iterator(path("seq")), fs::directory_iterator{}), 6);
    const nlohmann::json j = readJson(path("seq.json"));
    EXPECT_EQ(j["frames"]["count"], 3);
    EXPECT_EQ(j["animation"]["name"], "slide");
    EXPECT_DOUBLE_EQ(j["animation"]["duration"].get<double>(), 3.0);
    EXPECT_TRUE(j["video"].is_null());
    ASSERT_EQ(j["frame_summaries"].size(), 3u);
    for (int i = 0; i < 3; ++i) {
        const nlohmann::json& f = j["frame_summaries"][i];
        EXPECT_EQ(f["frame"], 2 + i);
        EXPECT_DOUBLE_EQ(f["time"].get<double>(), (2 + i) / 2.0);
        EXPECT_EQ(f["spp"], 2);
        EXPECT_EQ(f["seed"].get<unsigned>(), 5u + unsigned(2 + i) * 0x9E3779B9u);
        EXPECT_EQ(f["output"], path("seq/f_00" + std::to_string(2 + i) + ".exr"));
    }
    // The box moves: consecutive frames differ.
    EXPECT_NE(readExrLayer(path("seq/f_002.exr")).plane(0)[8 * 16 + 9],
              readExrLayer(path("seq/f_004.exr")).plane(0)[8 * 16 + 9]);
}

// moving_box's short box hangs under node "shortbox_motion" at the box's centre c; its keys are
// float32: translation c, (c - 0.35 x - 0.1 z), (c - 0.5 x + 0.15 z), ... at 0, 1, 2, 3 s;
// rotation about +Y by 0, 45 and 90 degrees at 0, 1.5 and 3 s. Frame 36 at 24 fps is t = 1.5:
// the translation halfway between keys 1 and 2, the rotation key 1 itself.
nlohmann::json staticPoseAt1_5(nlohmann::json scene) {
    scene.erase("animations");
    for (auto& node : scene["nodes"]) {
        if (node.value("name", "") != "shortbox_motion") continue;
        const auto c = node["translation"].get<std::vector<double>>();
        const auto f = [](double v) { return double(static_cast<float>(v)); };
        const double k1[3] = {f(c[0] - 0.35), f(c[1]), f(c[2] - 0.1)};
        const double k2[3] = {f(c[0] - 0.5), f(c[1]), f(c[2] + 0.15)};
        node["translation"] = {0.5 * k1[0] + 0.5 * k2[0], 0.5 * k1[1] + 0.5 * k2[1],
                               0.5 * k1[2] + 0.5 * k2[2]};
        const double half = 45.0 * (M_PI / 180.0) / 2.0;
        node["rotation"] = {0.0, f(std::sin(half)), 0.0, f(std::cos(half))};
        return scene;
    }
    ADD_FAILURE() << "no node shortbox_motion";
    return scene;
}

TEST_F(SequenceCli, AFrameIsTheStaticSceneOfItsPoseBitForBit) {
    std::ifstream in(kMovingBox);
    const nlohmann::json animated = nlohmann::json::parse(in);
    {
        std::ofstream out(path("still.gltf"));
        out << staticPoseAt1_5(animated).dump();
    }
    const std::string common = " --spp 3 --width 24 --height 20 --method gpt --recon l1 ";
    // Frames 35 and 36: the integrator renders frame 36 after another frame.
    const RunResult seq =
        runGdpt("render " + kMovingBox + " --frames 35:36 --no-video" + common + "-o " + path("f_%02d.exr"));
    ASSERT_EQ(seq.code, 0) << seq.output;
    const unsigned seed = 36u * 0x9E3779B9u;
    const RunResult still = runGdpt("render " + path("still.gltf") + common + "--seed " +
                                    std::to_string(seed) + " -o " + path("still.exr"));
    ASSERT_EQ(still.code, 0) << still.output;
    test::expectSameExrLayers(path("f_36.exr"), path("still.exr"));
    // Control: the neighbouring frame is a different pose, not the same bits.
    EXPECT_NE(readExrLayer(path("f_35.exr")).plane(1), readExrLayer(path("still.exr")).plane(1));
}

TEST_F(SequenceCli, AStillSceneRendersAsASequenceWithANote) {
    const RunResult r =
        runGdpt("render " + kCornell + " --frames 0:1 --spp 1 --width 8 --height 8 --method pt -o " +
                path("c_%d.exr"));
    ASSERT_EQ(r.code, 0) << r.output;
    EXPECT_NE(r.output.find("has no animations; every frame is the same still scene"), std::string::npos)
        << r.output;
    EXPECT_TRUE(fs::exists(path("c_0.exr")));
    EXPECT_TRUE(fs::exists(path("c_1.exr")));
    // Frame 0 is the single image of the same seed.
    ASSERT_EQ(
        runGdpt("render " + kCornell + " --spp 1 --width 8 --height 8 --method pt -o " + path("one.exr"))
            .code,
        0);
    test::expectSameExrLayers(path("c_0.exr"), path("one.exr"));
}

TEST_F(SequenceCli, AnInterruptLeavesTheCompleteFramesAndSaysWhereToContinue) {
    const std::string args = "render " + kMovingBox +
                             " --frames 0:3 --fps 1 --spp 2 --width 16 --height 16 --no-video " + "-o " +
                             path("f_%04d.exr") + " --json " + path("s.json");
    for (const char* at : {"sampling#2", "writing#2", "loading#3"}) {
        SCOPED_TRACE(at);
        fs::remove_all(dir_);
        fs::create_directories(dir_);
        const RunResult r = runGdpt(args, std::string("GDPT_TEST_SIGNAL_AT=") + at);
        EXPECT_EQ(r.code, 130) << r.output;
        EXPECT_NE(r.output.find("frame 1; frame 0 written (continue with --frames 1:3)"), std::string::npos)
            << r.output;
        EXPECT_EQ(files(), (std::vector<std::string>{"f_0000.exr", "f_0000.png"}));
    }
    // Continuing from the first missing frame completes the sequence.
    const RunResult rest =
        runGdpt("render " + kMovingBox + " --frames 1:3 --fps 1 --spp 2 --width 16 --height 16 " +
                "--no-video -o " + path("f_%04d.exr"));
    ASSERT_EQ(rest.code, 0) << rest.output;
    EXPECT_EQ(files().size(), 8u);
}

// A timed sequence compiles its kernels before the frames' shares are set: the first frame gets
// about the samples of the others (it used to compile G-PT's kernels inside its own share and
// got one or two samples per pixel).
TEST_F(SequenceCli, ATimedSequenceGivesTheFirstFrameItsShare) {
    const RunResult r = runGdpt("render " + kMovingBox +
                                " --method gpt --frames 0:3 --time 2 --width 16 --height 16 --no-video -o " +
                                path("f_%d.exr") + " --json " + path("s.json"));
    ASSERT_EQ(r.code, 0) << r.output;
    EXPECT_NE(r.output.find("kernels ready for the sequence"), std::string::npos) << r.output;
    const nlohmann::json j = readJson(path("s.json"));
    ASSERT_EQ(j["frame_summaries"].size(), 4u);
    std::uint32_t fewest = UINT32_MAX;
    for (int f = 1; f < 4; ++f)
        fewest = std::min(fewest, j["frame_summaries"][f]["spp"].get<std::uint32_t>());
    EXPECT_GE(2 * j["frame_summaries"][0]["spp"].get<std::uint32_t>(), fewest) << r.output;
    // An interrupt while the kernels compile leaves nothing and says where to continue.
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    const RunResult stopped = runGdpt(
        "render " + kMovingBox + " --method gpt --frames 0:3 --time 2 --width 16 --height 16 --no-video -o " +
            path("f_%d.exr"),
        "GDPT_TEST_SIGNAL_AT='compiling the kernels for'");
    EXPECT_EQ(stopped.code, 130) << stopped.output;
    EXPECT_NE(stopped.output.find("interrupted while compiling the kernels for frame 0; no frame written "
                                  "(continue with --frames 0:3)"),
              std::string::npos)
        << stopped.output;
    EXPECT_TRUE(files().empty());
}

TEST_F(SequenceCli, UsageErrorsLeaveNothing) {
    const std::string base = "render " + kMovingBox + " --spp 1 --width 8 --height 8 ";
    const struct {
        std::string flags, says;
    } cases[] = {
        {"--frames 0:3 -o " + path("plain.exr"), "4 frames need a frame number in the output name"},
        {"--frames 3:1 -o " + path("f_%d.exr"), "the last frame comes before the first"},
        {"--frames x -o " + path("f_%d.exr"), "--frames x: expected A:B"},
        {"--frames 0:1 -o " + path("f_%s.exr"), "'%' must start the frame number"},
        {"--frames 0:1 --animation walk -o " + path("f_%d.exr"), "has no such animation (it has 0 'slide')"},
        {"--frames 0:1 --animation 1 -o " + path("f_%d.exr"), "has no such animation"},
        {"--frames 0:1 --checkpoint " + path("c.exr") + " -o " + path("f_%d.exr"), "continues with --frames"},
        {"--frames 0:1 --shard 0/2 -o " + path("f_%d.exr"), "split a sequence by its frames"},
        {"--fps 30 -o " + path("x.exr"), "--fps requires --frames"},
        {"--frames 0:1 --fps 0 -o " + path("f_%d.exr"), "--fps"},
    };
    for (const auto& c : cases) {
        const RunResult r = runGdpt(base + c.flags);
        EXPECT_EQ(r.code, 2) << c.flags << "\n" << r.output;
        EXPECT_NE(r.output.find(c.says), std::string::npos) << c.flags << "\n" << r.output;
        EXPECT_TRUE(files().empty()) << c.flags << ": left " << files().front();
    }
}

TEST_F(SequenceCli, InfoListsTheAnimations) {
    const RunResult r = runGdpt("info " + kMovingBox);
    ASSERT_EQ(r.code, 0) << r.output;
    EXPECT_NE(r.output.find("animation 0 'slide': 3 s, 2 channels"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("node 'shortbox_motion' rotation (LINEAR, 3 keys, 0 to 3 s)"), std::string::npos)
        << r.output;
    const RunResult still =
        runGdpt("render " + kMovingBox + " --spp 1 --width 8 --height 8 -o " + path("x.exr"));
    ASSERT_EQ(still.code, 0) << still.output;
    EXPECT_NE(still.output.find("has 1 animation(s); the rest pose is rendered"), std::string::npos)
        << still.output;
}

// --method tgpt: windows of frames reconstructed together, each tied to the one before; its
// layers and JSON say so; the options it cannot honour are usage errors; a window larger than
// the machine's memory is refused before any sampling.
TEST_F(SequenceCli, TemporalGptRendersWindowsOfFrames) {
    const RunResult r =
        runGdpt("render " + kMovingBox + " --method tgpt --frames 0:4 --window 2 --spp 4 " +
                "--width 16 --height 12 --no-video -o " + path("t/f_%d.exr") + " --json " + path("t.json"));
    ASSERT_EQ(r.code, 0) << r.output;
    EXPECT_NE(r.output.find("space-time l1 reconstruction of frames 2-3"), std::string::npos) << r.output;
    const nlohmann::json j = readJson(path("t.json"));
    ASSERT_EQ(j["frame_summaries"].size(), 5u);
    const int firsts[] = {0, 0, 2, 2, 4};
    for (int f = 0; f < 5; ++f) {
        const nlohmann::json& s = j["frame_summaries"][f];
        EXPECT_EQ(s["tgpt"]["window_first"], firsts[f]) << f;
        EXPECT_EQ(s["tgpt"]["joined_previous_window"], f >= 2) << f;
        EXPECT_EQ(s["tgpt"]["temporal_to_previous"], f >= 1) << f;
        EXPECT_EQ(s["spp"], 4);
        EXPECT_EQ(s["reconstructions"][0]["method"], "spacetime_l1");
        EXPECT_EQ(s["tgpt"]["temporal_shift"], "motion") << f;
        // The motion map's pixels: none in the first frame, most of the 16x12 after.
        const int partnered = s["tgpt"]["motion_partnered"];
        if (f == 0)
            EXPECT_EQ(partnered, 0);
        else
            EXPECT_GT(partnered, 16 * 12 / 2) << f;
        EXPECT_LE(partnered, 16 * 12) << f;
    }
    const auto layers = readExr(path("t/f_3.exr"));
    std::vector<std::string> names;
    for (const auto& l : layers) names.push_back(l.name);
    for (const char* want : {"recon_spacetime_l1", "primal", "dx", "dy", "dt", "var_dt", "motion", "direct"})
        EXPECT_NE(std::find(names.begin(), names.end(), want), names.end()) << want;
    // The same-pixel replay: every pixel is its own partner, with no offset in the motion layer.
    const RunResult replay =
        runGdpt("render " + kMovingBox + " --method tgpt --temporal-shift replay --frames 0:1 --spp 2 " +
                "--width 16 --height 12 --no-video -o " + path("r/f_%d.exr") + " --json " + path("r.json"));
    ASSERT_EQ(replay.code, 0) << replay.output;
    EXPECT_EQ(readJson(path("r.json"))["frame_summaries"][1]["tgpt"]["temporal_shift"], "replay");
    const Image motion = readExrLayer(path("r/f_1.exr"), "motion");
    for (int c = 0; c < 3; ++c)
        for (float v : motion.plane(c)) ASSERT_EQ(v, c == 2 ? 1.0f : 0.0f);
    // Mixed rows (--gamma, 1 by default): reported, and they change the reconstruction of the
    // same samples.
    const RunResult mixed = runGdpt(
        "render " + kMovingBox + " --method tgpt --temporal-shift replay --frames 0:1 --spp 2 --gamma 0 " +
        "--width 16 --height 12 --no-video -o " + path("m/f_%d.exr") + " --json " + path("m.json"));
    ASSERT_EQ(mixed.code, 0) << mixed.output;
    EXPECT_EQ(readJson(path("m.json"))["frame_summaries"][1]["tgpt"]["gamma"], 0.0);
    EXPECT_EQ(readJson(path("r.json"))["frame_summaries"][1]["tgpt"]["gamma"], 1.0);
    EXPECT_EQ(readExrLayer(path("m/f_1.exr"), "primal").plane(0),
              readExrLayer(path("r/f_1.exr"), "primal").plane(0));
    EXPECT_NE(readExrLayer(path("m/f_1.exr"), "recon_spacetime_l1").plane(0),
              readExrLayer(path("r/f_1.exr"), "recon_spacetime_l1").plane(0));
    // The variance-weighted reconstruction: named, from the same samples, and another image; the
    // variance of dt from the halves' two groups of one sample (4 spp).
    const RunResult weighted =
        runGdpt("render " + kMovingBox + " --method tgpt --frames 0:1 --spp 4 --recon wl1 " +
                "--width 16 --height 12 --no-video -o " + path("w/f_%d.exr") + " --json " + path("w.json"));
    ASSERT_EQ(weighted.code, 0) << weighted.output;
    const nlohmann::json wj = readJson(path("w.json"))["frame_summaries"][1];
    EXPECT_EQ(wj["reconstructions"][0]["method"], "spacetime_wl1");
    EXPECT_EQ(wj["tgpt"]["dt_variance_groups"], 2);
    EXPECT_EQ(readJson(path("t.json"))["frame_summaries"][0]["tgpt"]["dt_variance_groups"], 0);
    EXPECT_EQ(readExrLayer(path("w/f_1.exr"), "primal").plane(0),
              readExrLayer(path("t/f_1.exr"), "primal").plane(0));
    EXPECT_NE(readExrLayer(path("w/f_1.exr"), "recon_spacetime_wl1").plane(0),
              readExrLayer(path("t/f_1.exr"), "recon_spacetime_l1").plane(0));
    const Image varDt = readExrLayer(path("w/f_1.exr"), "var_dt");
    double sum = 0.0;
    for (float v : varDt.plane(1)) {
        EXPECT_GE(v, 0.0f);
        sum += v;
    }
    EXPECT_GT(sum, 0.0);

    // diff-sequence along the motion: a sequence against itself has no error; against the
    // replay render, some; frames without a number or missing are refused.
    const std::string motionFlag = " --motion " + path("t/f_%d.exr");
    const RunResult self = runGdpt("diff-sequence " + path("t/f_%d.exr") + " " + path("t/f_%d.exr") +
                                   " --frames 0:4 --json " + path("d.json") + motionFlag);
    ASSERT_EQ(self.code, 0) << self.output;
    const nlohmann::json d = readJson(path("d.json"));
    EXPECT_EQ(d["mean_temporal_relmse_along_motion"], 0.0);
    EXPECT_EQ(d["per_frame"][3]["temporal_relmse_along_motion"], 0.0);
    const RunResult other = runGdpt("diff-sequence " + path("r/f_%d.exr") + " " + path("t/f_%d.exr") +
                                    " --frames 0:1 --json " + path("o.json") + motionFlag);
    ASSERT_EQ(other.code, 0) << other.output;
    EXPECT_GT(readJson(path("o.json"))["mean_temporal_relmse_along_motion"].get<double>(), 0.0);
    const RunResult noNumber = runGdpt("diff-sequence " + path("t/f_%d.exr") + " " + path("t/f_%d.exr") +
                                       " --frames 0:1 --motion " + path("t/f_1.exr"));
    EXPECT_EQ(noNumber.code, 2) << noNumber.output;
    const RunResult missing = runGdpt("diff-sequence " + path("t/f_%d.exr") + " " + path("t/f_%d.exr") +
                                      " --frames 0:1 --motion " + path("none/f_%d.exr"));
    EXPECT_EQ(missing.code, 1) << missing.output;
    EXPECT_NE(missing.output.find("no such frame"), std::string::npos) << missing.output;
}

// --temporal-shift reconnect: each frame one render of the frame's samples, dt from the
// reconnection pass with half as many per direction (joined across the window boundary too),
// along the same motion map as the motion shift's, with the pass's variance; no mixed rows.
TEST_F(SequenceCli, TemporalGptWithTheReconnectionShift) {
    const std::string common = " --frames 0:2 --window 2 --spp 4 --width 16 --height 12 --no-video ";
    const RunResult r = runGdpt("render " + kMovingBox + " --method tgpt --temporal-shift reconnect" +
                                common + "-o " + path("c/f_%d.exr") + " --json " + path("c.json"));
    ASSERT_EQ(r.code, 0) << r.output;
    const RunResult m =
        runGdpt("render " + kMovingBox + " --method tgpt" + common + "-o " + path("m/f_%d.exr"));
    ASSERT_EQ(m.code, 0) << m.output;
    const nlohmann::json j = readJson(path("c.json"));
    ASSERT_EQ(j["frame_summaries"].size(), 3u);
    for (int f = 0; f < 3; ++f) {
        const nlohmann::json& t = j["frame_summaries"][f]["tgpt"];
        EXPECT_EQ(t["temporal_shift"], "reconnect") << f;
        EXPECT_EQ(t["gamma"], 0.0) << f;
        EXPECT_EQ(j["frame_summaries"][f]["spp"], 4) << f;
        EXPECT_EQ(t["temporal_spp"], f == 0 ? 0 : 2) << f;
        EXPECT_EQ(t["temporal_to_previous"], f >= 1) << f;
        if (f > 0) {
            EXPECT_GT(t["temporal_pairs"].get<int>(), 16 * 12) << f;
        }
        const std::string name = "/f_" + std::to_string(f) + ".exr";
        const Image motion = readExrLayer(path("c" + name), "motion");
        const Image motionShift = readExrLayer(path("m" + name), "motion");
        EXPECT_EQ(motion.plane(0), motionShift.plane(0)) << f;
        if (f == 0) continue;
        double varDt = 0.0;
        const Image var = readExrLayer(path("c" + name), "var_dt");
        for (float v : var.plane(1)) {
            EXPECT_GE(v, 0.0f);
            varDt += v;
        }
        EXPECT_GT(varDt, 0.0) << f;
    }
    EXPECT_TRUE(j["frame_summaries"][2]["tgpt"]["joined_previous_window"]);

    // An interrupt during the pass stops the sequence with the frames before it written.
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    const RunResult stopped =
        runGdpt("render " + kMovingBox +
                    " --method tgpt --temporal-shift reconnect --frames 0:2 --window 1 --spp 2 " +
                    "--width 16 --height 12 --no-video -o " + path("f_%d.exr"),
                "GDPT_TEST_SIGNAL_AT='temporal reconnection'");
    EXPECT_EQ(stopped.code, 130) << stopped.output;
    EXPECT_NE(stopped.output.find("continue with --frames 1:2"), std::string::npos) << stopped.output;
    EXPECT_EQ(files(), (std::vector<std::string>{"f_0.exr", "f_0.png"}));
}

TEST_F(SequenceCli, TemporalGptRefusesWhatItCannotDo) {
    const std::string base = "render " + kMovingBox + " --method tgpt --spp 2 ";
    const struct {
        std::string flags, says;
        int code;
    } cases[] = {
        {"-o " + path("x.exr"), "--method tgpt renders a sequence", 2},
        {"--frames 0:1 --all-recon -o " + path("f_%d.exr"), "reconstructs with one --recon", 2},
        {"--frames 0:1 --demodulate on -o " + path("f_%d.exr"), "does not demodulate", 2},
        {"--frames 0:1 --window 0 -o " + path("f_%d.exr"), "--window", 2},
        {"--window 3 -o " + path("x.exr"), "--window requires --frames", 2},
        {"--frames 0:1 --temporal-shift sideways -o " + path("f_%d.exr"), "--temporal-shift", 2},
        {"--frames 0:1 --gamma -1 -o " + path("f_%d.exr"), "--gamma", 2},
        {"--frames 0:1 --temporal-shift reconnect --gamma 1 -o " + path("f_%d.exr"),
         "the reconnection shift renders each frame whole", 2},
        {"--frames 0:63 --window 64 --width 4096 --height 4096 -o " + path("f_%d.exr"),
         "needs about 690.0 GiB for its space-time reconstruction", 1},
    };
    for (const auto& c : cases) {
        const RunResult r = runGdpt(base + c.flags);
        EXPECT_EQ(r.code, c.code) << c.flags << "\n" << r.output;
        EXPECT_NE(r.output.find(c.says), std::string::npos) << c.flags << "\n" << r.output;
        EXPECT_TRUE(files().empty()) << c.flags << ": left " << files().front();
    }
}

// With ffmpeg installed (scripts/install-deps.sh installs it), a sequence gets an MP4 of its
// PNGs with one video frame per frame (counted by ffprobe); without ffmpeg on PATH, none,
// and the frames are written all the same.
TEST_F(SequenceCli, AVideoOfTheFramesWhenFfmpegIsInstalled) {
    if (test::runShell("command -v ffmpeg && command -v ffprobe").code != 0)
        GTEST_SKIP() << "ffmpeg is not installed (scripts/install-deps.sh installs it)";
    const std::string args = "render " + kMovingBox +
                             " --frames 0:4 --fps 12 --spp 1 --width 17 --height 9 " + "--method pt -o " +
                             path("v/clip_%04d.exr") + " --json " + path("v.json");
    const RunResult r = runGdpt(args);
    ASSERT_EQ(r.code, 0) << r.output;
    EXPECT_NE(r.output.find("video " + path("v/clip.mp4")), std::string::npos) << r.output;
    EXPECT_EQ(readJson(path("v.json"))["video"], path("v/clip.mp4"));
    const RunResult probe = test::runShell(
        "ffprobe -v error -count_frames -select_streams v:0 -show_entries "
        "stream=nb_read_frames,codec_name,width,height -of csv=p=0 " +
        path("v/clip.mp4"));
    ASSERT_EQ(probe.code, 0) << probe.output;
    EXPECT_EQ(probe.output, "h264,18,10,5\n");  // odd sizes padded to even
    // No ffmpeg on PATH: no video, the frames all the same.
    const RunResult none = runGdpt(args + " --quiet", "PATH=" + dir_.string());
    ASSERT_EQ(none.code, 0) << none.output;
    EXPECT_TRUE(readJson(path("v.json"))["video"].is_null());
    EXPECT_TRUE(fs::exists(path("v/clip_0004.png")));
}

}  // namespace
}  // namespace gdpt
