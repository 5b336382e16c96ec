// Scenes of many triangles from scripts/make-large-scene.py (written without gdpt's code): the
// render's --json "scene_size" and time_s.load, and the refusal of a scene whose render would
// not fit the machine's memory (GDPT_TEST_MEMORY_BYTES stands in for the machine's), naming
// the most triangles that would.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <string>

#include "cli_runner.h"

namespace gdpt {
namespace {

using nlohmann::json;

class SceneSizeCli : public test::TempDirTest {
protected:
    // Writes a terrain of about `triangles` triangles; returns the count the generator reports.
    std::uint64_t makeScene(const std::string& path, std::uint64_t triangles) {
        const test::RunResult r = test::runShell("python3 " + std::string(GDPT_SOURCE_DIR) +
                                                 "/scripts/make-large-scene.py --triangles " +
                                                 std::to_string(triangles) + " -o " + path);
        EXPECT_EQ(r.code, 0) << r.output;
        std::smatch m;
        const std::regex count(": ([0-9]+) triangles");
        if (!std::regex_search(r.output, m, count)) {
            ADD_FAILURE() << "no triangle count in: " << r.output;
            return 0;
        }
        return std::stoull(m[1].str());
    }
};

TEST_F(SceneSizeCli, JsonReportsTheSceneAndItsBytesPerTriangle) {
    const std::string scene = path("terrain.glb");
    const std::uint64_t triangles = makeScene(scene, 20000);
    const std::string out = path("r.json");
    const test::RunResult r =
        test::runGdpt("render " + scene + " --method pt --spp 1 --width 16 --height 16 -o " + path("r.exr") +
                      " --quiet --json " + out);
    ASSERT_EQ(r.code, 0) << r.output;
    std::ifstream in(out);
    const json j = json::parse(in);
    const json& s = j.at("scene_size");
    EXPECT_EQ(s.at("triangles").get<std::uint64_t>(), triangles);
    EXPECT_EQ(s.at("textures").get<int>(), 1);
    EXPECT_EQ(s.at("texels").get<int>(), 256 * 256);  // the generator's default texture
    // The two per-triangle tables alone take 48 + 80 bytes (TriangleGeom, TriangleShading);
    // the BVH adds well under 100 more.
    const double perTriangle = s.at("device_bytes_per_triangle").get<double>();
    EXPECT_GE(perTriangle, 128.0);
    EXPECT_LE(perTriangle, 300.0);
    EXPECT_GT(s.at("host_peak_bytes_per_triangle").get<double>(), 0.0);
    EXPECT_GT(j.at("time_s").at("load").get<double>(), 0.0);
    EXPECT_LE(j["time_s"]["load"].get<double>(), j["time_s"]["setup"].get<double>());
}

TEST_F(SceneSizeCli, ARenderBeyondTheMachinesMemoryIsRefusedWithTheSizeThatFits) {
    const std::string scene = path("terrain.glb");
    const std::uint64_t triangles = makeScene(scene, 100000);
    // 20 MB holds the loaded scene (about 90 bytes per triangle, which the loader checks) but
    // not its render (about 200 more per triangle).
    const std::string exr = path("r.exr");
    const test::RunResult refused =
        test::runGdpt("render " + scene + " --method pt --spp 1 --width 16 --height 16 --quiet -o " + exr,
                      "GDPT_TEST_MEMORY_BYTES=20000000");
    EXPECT_EQ(refused.code, 1) << refused.output;
    std::smatch m;
    const std::regex fits("fits with up to about ([0-9]+) triangles");
    ASSERT_TRUE(std::regex_search(refused.output, m, fits)) << refused.output;
    const std::uint64_t fitting = std::stoull(m[1].str());
    EXPECT_GT(fitting, 0u);
    EXPECT_LT(fitting, triangles);
    EXPECT_NE(refused.output.find("rendering the scene (" + std::to_string(triangles) + " triangles)"),
              std::string::npos)
        << refused.output;
    EXPECT_FALSE(std::filesystem::exists(exr)) << "output left behind";
    // The same scene renders when the machine has room for it.
    const test::RunResult rendered =
        test::runGdpt("render " + scene + " --method pt --spp 1 --width 16 --height 16 --quiet -o " + exr,
                      "GDPT_TEST_MEMORY_BYTES=200000000");
    EXPECT_EQ(rendered.code, 0) << rendered.output;
}

}  // namespace
}  // namespace gdpt
