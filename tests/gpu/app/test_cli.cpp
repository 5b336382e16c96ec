// The gdpt program as a user meets it: exit codes (0 ok, 1 input/runtime error, 2 usage),
// one clear error line naming the file, no output file left behind on failure, complete
// --help, and a small validated render that writes EXR + PNG + JSON.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>

#include "cli_runner.h"
#include "image/exr_io.h"
#include "image/metrics.h"
#include "render/passes/edge_options.h"

namespace gdpt {
namespace {

namespace fs = std::filesystem;

using test::RunResult;

RunResult run(const std::string& args) {
    return test::runGdpt(args);
}

// gdpt with environment assignments ("NAME=value ") before it, through the shell.
RunResult runWithEnv(const std::string& env, const std::string& args) {
    return test::runGdpt(args, env);
}

class Cli : public test::TempDirTest {};

const std::string kScene = std::string(GDPT_SOURCE_DIR) + "/scenes/cornell_box.gltf";

TEST_F(Cli, HelpDocumentsEveryRenderFlag) {
    const RunResult r = run("render --help");
    EXPECT_EQ(r.code, 0);
    for (const char* flag :
         {"--output", "--spp", "--time", "--width", "--height", "--max-depth", "--seed", "--env", "--device",
          "--camera", "--method", "--profile", "--json", "--quiet", "--validate"})
        EXPECT_NE(r.output.find(flag), std::string::npos) << flag;
    EXPECT_EQ(run("--help").code, 0);
}

TEST_F(Cli, UsageErrorsExitWithTwo) {
    EXPECT_EQ(run("render " + kScene + " --spp 0").code, 2);
    EXPECT_EQ(run("render " + kScene + " --width -3").code, 2);
    EXPECT_EQ(run("render " + kScene + " --env 1,2").code, 2);
    EXPECT_EQ(run("render").code, 2);
    EXPECT_EQ(run("frobnicate").code, 2);
}

// A missing or unreadable input is an input error (1), not a usage error: one line naming the
// file and the reason, whichever command and option names it.
TEST_F(Cli, MissingInputFilesAreErrorsNamingTheFile) {
    const std::string missing = path("missing.gltf");
    const std::string exr = path("missing.exr");
    for (const std::string& args :
         {"render " + missing, "info " + missing, "converge " + missing,
          "render " + kScene + " --resume " + exr, "converge " + kScene + " --reference " + exr,
          "diff " + exr + " " + exr, "solve " + exr,
          "clone --source " + exr + " --target " + exr + " --mask " + exr, "render " + dir_.string()}) {
        const RunResult r = run(args);
        EXPECT_EQ(r.code, 1) << args << ": " << r.output;
        EXPECT_EQ(r.output.rfind("gdpt: error: ", 0), 0u) << args << ": " << r.output;
        EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << "one line: " << r.output;
    }
    const RunResult r = run("render " + missing + " -o " + path("out.exr"));
    EXPECT_EQ(r.output, "gdpt: error: " + missing + ": no such file or directory\n");
    EXPECT_NE(run("render " + dir_.string()).output.find("is a directory"), std::string::npos);
    EXPECT_FALSE(fs::exists(path("out.exr")));
}

TEST_F(Cli, MalformedSceneIsAnErrorNamingTheFileAndWritesNothing) {
    const std::string bad = path("bad.gltf");
    std::ofstream(bad) << "{ \"asset\": { \"version\": \"2.0\" }, \"buffers\": [ { \"byteLength\": 12, ";
    const std::string out = path("out.exr");
    const RunResult r = run("render " + bad + " -o " + out + " --quiet");
    EXPECT_EQ(r.code, 1) << r.output;
    EXPECT_NE(r.output.find("bad.gltf"), std::string::npos) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << "one line: " << r.output;
    EXPECT_FALSE(fs::exists(out));
    EXPECT_FALSE(fs::exists(path("out.png")));
    EXPECT_TRUE(temporaryFiles().empty());
}

// A scene with nothing that emits light renders black: render and info say so (and what to
// try), a render with --env does not.
TEST_F(Cli, SceneWithoutLightWarnsThatTheImageWillBeBlack) {
    const std::string dark = path("dark.gltf");
    // One triangle (0,0,0), (1,0,0), (0,1,0), default material; the buffer as a data URI.
    std::ofstream(dark) << R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}], "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                       "min": [0, 0, 0], "max": [1, 1, 0]}],
        "bufferViews": [{"buffer": 0, "byteLength": 36}],
        "buffers": [{"byteLength": 36,
                     "uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}]})";
    const std::string warning =
        dark +
        ": no light source (no emissive surface, no punctual light, no --env): the image will be black; "
        "try --env 1,1,1";
    const std::string small = " --width 8 --height 8 --spp 1 -o " + path("out.exr");
    const RunResult r = run("render " + dark + small);
    EXPECT_EQ(r.code, 0) << r.output;
    EXPECT_NE(r.output.find("gdpt: warning: " + warning + "\n"), std::string::npos) << r.output;
    const RunResult lit = run("render " + dark + small + " --env 1,1,1");
    EXPECT_EQ(lit.code, 0) << lit.output;
    EXPECT_EQ(lit.output.find("no light source"), std::string::npos) << lit.output;
    const RunResult info = run("info " + dark);
    EXPECT_EQ(info.code, 0) << info.output;
    EXPECT_NE(info.output.find(warning), std::string::npos) << info.output;
    EXPECT_EQ(run("info " + kScene).output.find("no light source"), std::string::npos);
}

TEST_F(Cli, SmallValidatedRenderWritesExrPngAndJson) {
    const std::string out = path("cb.exr");
    const std::string json = path("cb.json");
    const RunResult r = run("render " + kScene + " -o " + out +
                            " --method pt --width 24 --height 16 --spp 4 --validate --quiet "
                            "--profile --json " +
                            json);
    ASSERT_EQ(r.code, 0) << r.output;
    ASSERT_TRUE(fs::exists(out));
    EXPECT_TRUE(fs::exists(path("cb.png")));
    const auto layers = readExr(out);
    ASSERT_GE(layers.size(), 2u);
    EXPECT_EQ(layers[0].name, "");
    EXPECT_EQ(layers[0].image.width(), 24);
    EXPECT_EQ(layers[0].image.height(), 16);
    std::ifstream in(json);
    const auto j = nlohmann::json::parse(in);
    EXPECT_EQ(j["spp"].get<int>(), 4);
    EXPECT_EQ(j["validation_errors"].get<int>(), 0);
    EXPECT_GT(j["rays_traced"].get<double>(), 0.0);
    EXPECT_TRUE(j["kernels"].contains("pt"));
    EXPECT_EQ(j["bvh_register_stack"].get<int>(), 8) << "cornell_box's tree needs 4 stack entries";
    EXPECT_EQ(j["light_selection"].get<std::string>(), "probe");
    // One emitter: nothing to probe, its one share is 1.
    EXPECT_FALSE(j["light_probe"].get<bool>());
    ASSERT_EQ(j["light_shares"].size(), 1u);
    EXPECT_NEAR(j["light_shares"][0]["probability"].get<double>(), 1.0, 1e-9);
    EXPECT_NE(r.output.find("pt"), std::string::npos) << "--profile prints the kernel table";
    // The wait for the background-created pipelines is part of the set-up it reports.
    const auto& t = j["time_s"];
    EXPECT_GE(t["pipeline_wait"].get<double>(), 0.0);
    EXPECT_LE(t["pipeline_wait"].get<double>(),
              t["upload"].get<double>() + t["bvh_build"].get<double>() + 1e-6);
    EXPECT_LE(t["upload"].get<double>() + t["sampling"].get<double>(), t["total"].get<double>());
}

// --light-selection: each rule renders and is reported; any other value is refused before
// anything is written.
TEST_F(Cli, LightSelectionIsChosenAndReported) {
    for (const char* rule : {"power", "uniform", "probe"}) {
        const std::string json = path(std::string(rule) + ".json");
        const RunResult r =
            run("render " + kScene + " --method pt --width 8 --height 8 --spp 1 --quiet -o " +
                path(std::string(rule) + ".exr") + " --light-selection " + rule + " --json " + json);
        ASSERT_EQ(r.code, 0) << r.output;
        std::ifstream in(json);
        EXPECT_EQ(nlohmann::json::parse(in)["light_selection"].get<std::string>(), rule);
    }
    // The open scene has two emitters (sky, lamp): the default rule probes them and reports
    // their shares, the lamp's above `mixed`'s quarter (bench/RESULTS.md, "The probe rule").
    const std::string open = std::string(GDPT_SOURCE_DIR) + "/scenes/open_scene.gltf";
    const RunResult probed =
        run("render " + open + " --method pt --width 32 --height 32 --spp 1 --quiet -o " + path("open.exr") +
            " --json " + path("open.json"));
    ASSERT_EQ(probed.code, 0) << probed.output;
    std::ifstream openJson(path("open.json"));
    const auto j = nlohmann::json::parse(openJson);
    EXPECT_EQ(j["light_selection"].get<std::string>(), "probe");
    EXPECT_TRUE(j["light_probe"].get<bool>());
    ASSERT_EQ(j["light_shares"].size(), 2u);
    const double a = j["light_shares"][0]["probability"].get<double>();
    const double b = j["light_shares"][1]["probability"].get<double>();
    EXPECT_NEAR(a + b, 1.0, 1e-9);
    EXPECT_GT(std::min(a, b), 0.3);

    const RunResult bad =
        run("render " + kScene + " --spp 1 -o " + path("bad.exr") + " --light-selection area");
    EXPECT_NE(bad.code, 0);
    EXPECT_NE(bad.output.find("--light-selection"), std::string::npos) << bad.output;
    EXPECT_FALSE(fs::exists(path("bad.exr")));
}

// A timed G-PT render reserves its reconstruction time: the first run of a configuration
// measures it (calibration solve) and remembers the real reconstruction's time in the cache
// ($GDPT_CACHE_DIR/recon_times.json); the next run reserves exactly the remembered value.
// The same for the time after sampling without the reconstruction (finish_reserved).
TEST_F(Cli, TimedGptRenderReservesTheRememberedReconstructionTime) {
    const std::string env = "GDPT_CACHE_DIR=" + path("cache") + " ";
    const std::string cmd = "render " + kScene + " --method gpt -o " + path("g.exr") +
                            " --width 16 --height 16 --time 1 --quiet --validate --json " + path("g.json");
    auto readJson = [&](const std::string& file) {
        std::ifstream in(file);
        return nlohmann::json::parse(in);
    };
    RunResult r = run(cmd);  // whatever cache the environment names: must work either way
    ASSERT_EQ(r.code, 0) << r.output;
    const std::string cached = path("cache/recon_times.json");
    r = runWithEnv(env, cmd);
    ASSERT_EQ(r.code, 0) << r.output;
    EXPECT_GT(readJson(path("g.json"))["time_s"]["reconstruction_reserved"].get<double>(), 0.0);
    ASSERT_TRUE(fs::exists(cached));
    nlohmann::json entries = readJson(cached);
    // The reconstruction's entry and the finish's (readback, layers, writing: finish_reserved),
    // each for the configuration and for it with this scene ("|scene <path>").
    ASSERT_EQ(entries.size(), 4u) << entries.dump();
    std::string key;
    std::string finishKey;
    for (const auto& [k, v] : entries.items())
        if (k.find("|scene ") == std::string::npos) (k.rfind("finish|", 0) == 0 ? finishKey : key) = k;
    ASSERT_FALSE(key.empty()) << entries.dump();
    ASSERT_FALSE(finishKey.empty()) << entries.dump();
    EXPECT_NE(finishKey.find("gpt"), std::string::npos) << finishKey;
    EXPECT_NE(key.find("16x16"), std::string::npos) << key;
    EXPECT_NE(key.find("l1"), std::string::npos) << key;
    const std::string sceneKey = key + "|scene " + kScene, sceneFinishKey = finishKey + "|scene " + kScene;
    ASSERT_TRUE(entries.contains(sceneKey)) << entries.dump();
    ASSERT_TRUE(entries.contains(sceneFinishKey)) << entries.dump();
    // Values no measurement produces, to see them come back: the scene's entries first; the
    // configuration's, in the form earlier versions wrote (bare seconds), when the scene has none.
    const auto reservedWith = [&](bool sceneEntries) {
        nlohmann::json e = readJson(cached);
        e.erase(sceneKey);
        e.erase(sceneFinishKey);
        if (sceneEntries) {
            e[sceneKey] = 0.125;
            e[sceneFinishKey] = 0.0625;
        }
        // Below any real solve's time (a 16x16 solve takes about 0.2 ms): the set-up takes the
        // whole 1 s budget, so the solve is cut at its deadline, and a cut solve keeps the
        // reserved value unless it ran longer (reconstruction_stage.h, rememberedReconSeconds).
        e[key] = 1.0 / 65536.0;
        e[finishKey] = 0.03125;
        std::ofstream(cached) << e.dump();
        const RunResult rr = runWithEnv(env, cmd);
        EXPECT_EQ(rr.code, 0) << rr.output;
        const nlohmann::json times = readJson(path("g.json"))["time_s"];
        return std::make_pair(times["reconstruction_reserved"].get<double>(),
                              times["finish_reserved"].get<double>());
    };
    EXPECT_EQ(reservedWith(true), std::make_pair(0.125, 0.0625));
    EXPECT_EQ(reservedWith(false), std::make_pair(1.0 / 65536.0, 0.03125));
    // The real times replace them, each with the load its render's sampling felt (0 here: a
    // sampling this short is not measured; test_time_budget_cli.cpp measures one).
    entries = readJson(cached);
    EXPECT_NE(entries[key]["seconds"].get<double>(), 1.0 / 65536.0)
        << "the real reconstruction time replaces it";
    EXPECT_NE(entries[finishKey]["seconds"].get<double>(), 0.03125) << "the real finishing time replaces it";
    EXPECT_EQ(entries[sceneKey], entries[key]);
    EXPECT_GE(entries[key]["load"].get<double>(), 0.0);
    EXPECT_GE(entries[finishKey]["load"].get<double>(), 0.0);
}

// --edge-samples: the factor and the edge pixels found come back in --json (G-PT only), 0
// turns the probe off, and values above the bound are usage errors.
TEST_F(Cli, GptRenderReportsItsEdgeSamples) {
    auto render = [&](const std::string& flags) {
        return run("render " + kScene + " --method gpt -o " + path("e.exr") +
                   " --width 32 --height 32 --spp 2 --quiet --validate --json " + path("e.json") + flags);
    };
    auto readJson = [&] {
        std::ifstream in(path("e.json"));
        return nlohmann::json::parse(in);
    };
    RunResult r = render(" --edge-samples 3");
    ASSERT_EQ(r.code, 0) << r.output;
    nlohmann::json j = readJson();
    EXPECT_EQ(j["edge_samples"]["factor"].get<int>(), 3);
    // The kernel variant: occlusion beams exactly in the split build traversing in node steps.
    EXPECT_EQ(j["gpt_occlusion_beams"].get<bool>(),
              j["gpt_split_bounce"].get<bool>() && j["bvh_steps"].get<std::string>() == "nodes");
    const int pixels = j["edge_samples"]["pixels"].get<int>();
    EXPECT_GT(pixels, 0) << "the Cornell box's walls and boxes have edges";
    EXPECT_LT(pixels, 32 * 32 / 2);
    EXPECT_EQ(j["paths_completed"].get<long>(), 2L * (32 * 32 + 3 * pixels))
        << "2 spp, 3 more per edge pixel";
    r = render(" --edge-samples 0");
    ASSERT_EQ(r.code, 0) << r.output;
    j = readJson();
    EXPECT_EQ(j["edge_samples"]["factor"].get<int>(), 0);
    EXPECT_EQ(j["edge_samples"]["pixels"].get<int>(), 0);
    EXPECT_EQ(j["paths_completed"].get<long>(), 2L * 32 * 32);
    EXPECT_EQ(render(" --edge-samples 65").code, 2);
    EXPECT_EQ(render(" --edge-samples four").code, 2);

    // auto (the default): the factor follows the share of the pixels listed for the edge
    // samples (the edge pixels and their neighbours). At 32² the box's are 24 % of the pixels
    // (factor 2); at 24², 35 % (factor 1).
    r = render("");
    ASSERT_EQ(r.code, 0) << r.output;
    j = readJson();
    EXPECT_EQ(j["edge_samples"]["pixels"].get<int>(), pixels);
    EXPECT_GT(pixels, j["edge_samples"]["edge_pixels"].get<int>());
    EXPECT_EQ(j["edge_samples"]["factor"].get<std::uint32_t>(), autoEdgeSamples(pixels, 32 * 32));
    EXPECT_EQ(j["edge_samples"]["factor"].get<int>(), 2);
    EXPECT_EQ(j["paths_completed"].get<long>(), 2L * (32 * 32 + 2 * pixels));
    r = run("render " + kScene + " --method gpt -o " + path("e.exr") +
            " --width 24 --height 24 --spp 1 --quiet --json " + path("e.json"));
    ASSERT_EQ(r.code, 0) << r.output;
    j = readJson();
    EXPECT_EQ(j["edge_samples"]["factor"].get<std::uint32_t>(),
              autoEdgeSamples(j["edge_samples"]["pixels"].get<std::uint64_t>(), 24 * 24));
    EXPECT_EQ(j["edge_samples"]["factor"].get<int>(), 1);
}

// A textured scene demodulates by default: the JSON says where, the EXR gains the modulation
// layer, and `gdpt solve` of that EXR multiplies its reconstruction by it again (the same
// final image as the render's, up to the solver's float rounding); --demodulate off has none.
TEST_F(Cli, GptRenderOfATexturedSceneDemodulatesAndSolveUsesItsModulation) {
    const std::string textured = std::string(GDPT_SOURCE_DIR) + "/scenes/textured.gltf";
    auto render = [&](const std::string& flags) {
        return run("render " + textured + " --method gpt -o " + path("t.exr") +
                   " --width 32 --height 32 --spp 2 --quiet --validate --json " + path("t.json") + flags);
    };
    auto demodulation = [&] {
        std::ifstream in(path("t.json"));
        return nlohmann::json::parse(in)["demodulation"];
    };
    auto hasModulation = [&] {
        for (const NamedLayer& l : readExr(path("t.exr")))
            if (l.name == "modulation") return true;
        return false;
    };
    RunResult r = render("");
    ASSERT_EQ(r.code, 0) << r.output;
    nlohmann::json d = demodulation();
    EXPECT_TRUE(d["on"].get<bool>());
    EXPECT_GT(d["pixels"].get<int>(), 32 * 32 / 4);
    EXPECT_LT(d["pixels"].get<int>(), 32 * 32) << "the box edges and the walls' corners stay out";
    EXPECT_TRUE(hasModulation());
    r = run("solve " + path("t.exr") + " --recon wl1 --quiet -o " + path("s.exr"));  // the render's
    ASSERT_EQ(r.code, 0) << r.output;
    EXPECT_LT(relMse(readExrLayer(path("s.exr")), readExrLayer(path("t.exr"))), 1e-6);
    r = render(" --demodulate off");
    ASSERT_EQ(r.code, 0) << r.output;
    d = demodulation();
    EXPECT_FALSE(d["on"].get<bool>());
    EXPECT_EQ(d["pixels"].get<int>(), 0);
    EXPECT_FALSE(hasModulation());
    EXPECT_EQ(render(" --demodulate sometimes").code, 2);
}

// `gdpt info` names the scene's features and the kernel variant it selects, including the
// traversal stack: cornell_box's 36-triangle tree needs 4 entries (register stack of 8);
// the procedural furnace sphere's 1280 triangles need 13 (register stack of 16); and G-PT's
// reconstruction and primal weight by the scene.
TEST_F(Cli, InfoPrintsTheFeaturesAndTheKernelVariant) {
    const RunResult box = run("info " + kScene);
    ASSERT_EQ(box.code, 0) << box.output;
    EXPECT_NE(box.output.find("36 triangles"), std::string::npos) << box.output;
    EXPECT_NE(box.output.find("textures=0"), std::string::npos) << box.output;
    EXPECT_NE(box.output.find("bvhRegisterStack=8]"), std::string::npos) << box.output;
    const RunResult furnace = run("info " + std::string(GDPT_SOURCE_DIR) + "/scenes/furnace.gltf");
    ASSERT_EQ(furnace.code, 0) << furnace.output;
    EXPECT_NE(furnace.output.find("bvhRegisterStack=16]"), std::string::npos) << furnace.output;
    EXPECT_NE(box.output.find("gpt variant: demodulate=0"), std::string::npos) << box.output;
    const RunResult textured = run("info " + std::string(GDPT_SOURCE_DIR) + "/scenes/textured.gltf");
    ASSERT_EQ(textured.code, 0) << textured.output;
    EXPECT_NE(textured.output.find("gpt variant: demodulate=1"), std::string::npos) << textured.output;
    // G-PT's reconstruction and α as render chooses them: the box's, and the glossy box's (its
    // mirror sphere) and the furnace's (a sky of emissive triangles).
    EXPECT_NE(
        box.output.find("gpt reconstruction: wl1 (scene surfaces: rough), alpha 0.2 (scene light: emitters)"),
        std::string::npos)
        << box.output;
    const RunResult glossy = run("info " + std::string(GDPT_SOURCE_DIR) + "/scenes/glossy_cornell.gltf");
    ASSERT_EQ(glossy.code, 0) << glossy.output;
    EXPECT_NE(glossy.output.find("gpt reconstruction: wl2 (scene surfaces: glossy vertices)"),
              std::string::npos)
        << glossy.output;
    EXPECT_NE(furnace.output.find("alpha 0.4 (scene light: emissive sky)"), std::string::npos)
        << furnace.output;
    // The emitters' shares under the default rule: one light has them all; the open scene's
    // two are probed.
    EXPECT_NE(box.output.find("material 3 1.000 (probe)"), std::string::npos) << box.output;
    const RunResult open = run("info " + std::string(GDPT_SOURCE_DIR) + "/scenes/open_scene.gltf");
    ASSERT_EQ(open.code, 0) << open.output;
    EXPECT_NE(open.output.find("light shares"), std::string::npos) << open.output;
    EXPECT_NE(open.output.find("(probe)"), std::string::npos) << open.output;
}

TEST_F(Cli, DiffOfAnImageWithItselfIsZero) {
    const std::string out = path("a.exr");
    ASSERT_EQ(run("render " + kScene + " -o " + out + " --width 8 --height 8 --spp 2 --quiet").code, 0);
    const RunResult r = run("diff " + out + " " + out + " --json -");
    ASSERT_EQ(r.code, 0) << r.output;
    const auto j = nlohmann::json::parse(r.output);
    EXPECT_EQ(j["relmse"].get<double>(), 0.0);
    EXPECT_EQ(j["max_abs_error"].get<double>(), 0.0);
}

TEST_F(Cli, DiffErrorMapAveragesToRelMse) {
    const std::string a = path("a.exr"), b = path("b.exr"), map = path("map.exr");
    ASSERT_EQ(run("render " + kScene + " -o " + a + " --width 8 --height 8 --spp 2 --seed 1 --quiet").code,
              0);
    ASSERT_EQ(run("render " + kScene + " -o " + b + " --width 8 --height 8 --spp 2 --seed 2 --quiet").code,
              0);
    const RunResult r = run("diff " + a + " " + b + " --json - --error-map " + map);
    ASSERT_EQ(r.code, 0) << r.output;
    const auto j = nlohmann::json::parse(r.output);
    const double relmse = j["relmse"].get<double>();
    ASSERT_GT(relmse, 0.0);
    double quarters = 0.0;
    for (const auto& q : j["relmse_by_brightness"]) quarters += q.get<double>();
    EXPECT_NEAR(quarters, relmse, 1e-9 * relmse);
    const Image m = readExrLayer(map);
    double sum = 0.0;
    for (float v : m.plane(1)) sum += v;
    EXPECT_NEAR(sum / double(m.pixelCount()), relmse, 1e-5 * relmse);
    EXPECT_TRUE(std::filesystem::exists(path("map.png")));
    // The map may not overwrite an input.
    EXPECT_NE(run("diff " + a + " " + b + " --error-map " + a).code, 0);
}

TEST_F(Cli, DevicesListsAtLeastOneUsableDevice) {
    const RunResult r = run("devices --json");
    ASSERT_EQ(r.code, 0) << r.output;
    const auto j = nlohmann::json::parse(r.output);
    ASSERT_FALSE(j.empty());
    bool usable = false;
    for (const auto& d : j) usable = usable || d["usable"].get<bool>();
    EXPECT_TRUE(usable);
    // The text listing shows the same devices and their limits (a printf whose arguments
    // did not match its format crashed here once).
    const RunResult text = run("devices");
    ASSERT_EQ(text.code, 0) << text.output;
    EXPECT_NE(text.output.find(j[0]["name"].get<std::string>()), std::string::npos) << text.output;
    EXPECT_NE(text.output.find("maxStorageBufferRange " +
                               std::to_string(j[0]["max_storage_buffer_range"].get<std::uint64_t>() >> 20) +
                               " MiB"),
              std::string::npos)
        << text.output;
    EXPECT_NE(text.output.find("maxTexelBufferElements " +
                               std::to_string(j[0]["max_texel_buffer_elements"].get<std::uint64_t>() >> 20) +
                               " Mi"),
              std::string::npos)
        << text.output;
    EXPECT_NE(
        text.output.find("maxMemoryAllocationSize " +
                         std::to_string(j[0]["max_memory_allocation"].get<std::uint64_t>() >> 20) + " MiB"),
        std::string::npos)
        << text.output;
}

TEST_F(Cli, UnknownDeviceIsAnError) {
    const RunResult r = run("render " + kScene + " --device no-such-device --quiet -o " + path("x.exr"));
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.output.find("no-such-device"), std::string::npos);
    EXPECT_FALSE(fs::exists(path("x.exr")));
}

}  // namespace
}  // namespace gdpt

namespace gdpt {
namespace {

// SIGINT during a render stops it at the next batch boundary (batches are sized to stay
// well under a second), exits with 130 and leaves no output file.
TEST_F(Cli, InterruptStopsPromptlyWithoutOutput) {
    const std::string out = path("long.exr");
    const std::string cmd = std::string(GDPT_BINARY) + " render " + kScene + " -o " + out +
                            " --spp 100000 --quiet 2>/dev/null & pid=$!; sleep 1.5; kill -INT $pid; "
                            "start=$(date +%s%N); wait $pid; rc=$?; end=$(date +%s%N); "
                            "echo $rc $(( (end - start) / 1000000 ))";
    FILE* pipe = popen(cmd.c_str(), "r");
    ASSERT_NE(pipe, nullptr);
    int rc = -1;
    long stopMs = -1;
    ASSERT_EQ(std::fscanf(pipe, "%d %ld", &rc, &stopMs), 2);
    pclose(pipe);
    EXPECT_EQ(rc, 130);
    // A batch is at most 2^18 pixel-samples (~0.3 s on two idle cores); allow for a loaded
    // CI machine.
    EXPECT_LT(stopMs, 3000);
    EXPECT_FALSE(fs::exists(out));
    EXPECT_TRUE(temporaryFiles().empty());
}

}  // namespace
}  // namespace gdpt
