// `gdpt bench` end to end: one JSON record per scene with the BVH figures (build, collapse, SAH
// cost, nodes) and ray and sample rates, for a built-in scene and a glTF file; refusals of an
// unknown scene, a missing file, and --embree in a build without the baseline (or, in a build
// with it, the Embree record and the ratios). `gdpt bench-poisson` with the space-time methods:
// one record per method, converged to the tolerance; an unknown method refused.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_runner.h"

namespace gdpt {
namespace {

using nlohmann::json;

const std::string kScene = std::string(GDPT_SOURCE_DIR) + "/scenes/cornell_box.gltf";
const std::string kTiny = "--width 16 --height 16 --spp 1 --repeats 1";

class BenchCli : public test::TempDirTest {};

json readJson(const std::string& path) {
    std::ifstream in(path);
    return json::parse(in);
}

TEST_F(BenchCli, ReportsTheBvhAndRaysOfEachScene) {
    const std::string out = path("bench.json");
    const test::RunResult r = test::runGdpt("bench --scenes cbox," + kScene + " " + kTiny + " -o " + out);
    ASSERT_EQ(r.code, 0) << r.output;
    const json j = readJson(out);
    EXPECT_GE(j.at("threads").get<int>(), 1);
    ASSERT_EQ(j.at("scenes").size(), 2u);
    EXPECT_EQ(j["scenes"][0].at("scene"), "cbox");
    EXPECT_EQ(j["scenes"][1].at("scene"), kScene);
    for (const json& s : j["scenes"]) {
        EXPECT_GT(s.at("triangles").get<double>(), 0.0);
        EXPECT_GE(s.at("bvh_build_ms").get<double>(), 0.0);
        EXPECT_GE(s.at("bvh_collapse_ms").get<double>(), 0.0);
        // The SAH cost relative to the root box: at least one node visit and one triangle test.
        EXPECT_GE(s.at("bvh_sah_cost").get<double>(), 2.0);
        EXPECT_GE(s.at("bvh_nodes").get<double>(), 1.0);
        EXPECT_GT(s.at("primary_rays_per_s").get<double>(), 0.0);
        EXPECT_GT(s.at("incoherent_rays_per_s").get<double>(), 0.0);
        EXPECT_GT(s.at("pt_samples_per_s").get<double>(), 0.0);
        EXPECT_FALSE(s.contains("embree")) << "Embree figures without --embree";
    }
}

TEST_F(BenchCli, RefusesAnUnknownSceneAndAMissingFile) {
    const test::RunResult unknown = test::runGdpt("bench --scenes cbox,2m " + kTiny);
    EXPECT_EQ(unknown.code, 2) << unknown.output;
    EXPECT_NE(unknown.output.find("unknown scene '2m'"), std::string::npos) << unknown.output;
    const std::string missing = path("missing.gltf");
    const test::RunResult gone = test::runGdpt("bench --scenes " + missing + " " + kTiny);
    EXPECT_EQ(gone.code, 1) << gone.output;
    EXPECT_NE(gone.output.find("missing.gltf"), std::string::npos) << gone.output;
}

// The same test passes in either build: without the baseline --embree is a usage error that
// says how to get it; with it, the record holds Embree's figures and the ratios.
TEST_F(BenchCli, EmbreeBaselineOrWhyNot) {
    const std::string out = path("embree.json");
    const test::RunResult r = test::runGdpt("bench --embree --scenes cbox " + kTiny + " -o " + out);
    if (r.code == 2) {
        EXPECT_NE(r.output.find("-DGDPT_EMBREE=ON"), std::string::npos) << r.output;
        EXPECT_FALSE(std::filesystem::exists(out));
        return;
    }
    ASSERT_EQ(r.code, 0) << r.output;
    const json s = readJson(out).at("scenes").at(0);
    EXPECT_GT(s.at("embree").at("build_ms").get<double>(), 0.0);
    EXPECT_GT(s.at("embree").at("incoherent_rays_per_s").get<double>(), 0.0);
    EXPECT_GT(s.at("gdpt_over_embree").at("incoherent_rays").get<double>(), 0.0);
    EXPECT_GT(s.at("gdpt_over_embree").at("build_time").get<double>(), 0.0);
}

// The space-time solver's figures need no Vulkan device (they run on the host) and report a
// converged solve of the requested window.
TEST_F(BenchCli, PoissonBenchTimesTheSpaceTimeSolver) {
    // The JSON alone (stdout; the progress lines go to stderr).
    const test::RunResult r = test::runShell("(" + test::gdptBinary() +
                                             " bench-poisson --sizes 24x16 --methods st-l2,st-l1 --frames 3 "
                                             "--repeats 1 --threads 2 2>/dev/null)");
    ASSERT_EQ(r.code, 0) << r.output;
    const json j = json::parse(r.output);
    EXPECT_EQ(j.at("frames").get<int>(), 3);
    EXPECT_EQ(j.at("threads").get<int>(), 2);
    ASSERT_EQ(j.at("results").size(), 2u);
    EXPECT_EQ(j["results"][0].at("method"), "st-l2");
    EXPECT_EQ(j["results"][1].at("method"), "st-l1");
    for (const json& e : j["results"]) {
        EXPECT_TRUE(e.at("converged").get<bool>()) << e.dump();
        EXPECT_LE(e.at("residual").get<double>(), 1e-4) << e.dump();
        EXPECT_GT(e.at("iterations").get<int>(), 0) << e.dump();
        EXPECT_GT(e.at("median_ms").get<double>(), 0.0) << e.dump();
    }
    EXPECT_EQ(j["results"][1].at("irls_iterations").get<int>(), 6);
    const test::RunResult bad = test::runGdpt("bench-poisson --sizes 16 --methods st-l3 --repeats 1");
    EXPECT_EQ(bad.code, 2) << bad.output;
    EXPECT_NE(bad.output.find("unknown method 'st-l3'"), std::string::npos) << bad.output;
}

}  // namespace
}  // namespace gdpt
