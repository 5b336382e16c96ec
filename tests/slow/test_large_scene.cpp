// A scene of five million textured triangles (scripts/make-large-scene.py) loads, builds its
// BVH, uploads and renders on the device within the machine's memory, with finite output and
// the sizes and times in --json. Label slow: about a minute with its generation.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_runner.h"

namespace gdpt {
namespace {

using nlohmann::json;

class LargeScene : public test::TempDirTest {};

TEST_F(LargeScene, FiveMillionTexturedTrianglesRender) {
    const std::string scene = path("terrain_5m.glb");
    const test::RunResult made =
        test::runShell("python3 " + std::string(GDPT_SOURCE_DIR) +
                       "/scripts/make-large-scene.py --triangles 5000000 -o " + scene);
    ASSERT_EQ(made.code, 0) << made.output;
    for (const char* method : {"pt", "gpt"}) {
        const std::string out = path(std::string(method) + ".json");
        const test::RunResult r =
            test::runGdpt("render " + scene + " --method " + method +
                          " --spp 1 --width 64 --height 64 --quiet -o " + path("r.exr") + " --json " + out);
        ASSERT_EQ(r.code, 0) << method << ": " << r.output;  // finite pixels are checked before writing
        std::ifstream in(out);
        const json j = json::parse(in);
        const json& s = j.at("scene_size");
        EXPECT_GE(s.at("triangles").get<double>(), 4.99e6) << method;
        EXPECT_EQ(s.at("textures").get<int>(), 1);
        // Measured 2026-12-04: 251 bytes per triangle at the peak (144 of them the device
        // tables); a render that kept a second copy of its tables would pass 380.
        EXPECT_LE(s.at("host_peak_bytes_per_triangle").get<double>(), 380.0) << method;
        for (const char* phase : {"load", "bvh_build", "upload"})
            EXPECT_GT(j.at("time_s").at(phase).get<double>(), 0.0) << method << " " << phase;
        std::fprintf(stderr,
                     "%s: load %.2f s, BVH %.2f s, upload %.2f s, %.0f bytes per triangle at the peak\n",
                     method, j["time_s"]["load"].get<double>(), j["time_s"]["bvh_build"].get<double>(),
                     j["time_s"]["upload"].get<double>(), s["host_peak_bytes_per_triangle"].get<double>());
    }
}

}  // namespace
}  // namespace gdpt
