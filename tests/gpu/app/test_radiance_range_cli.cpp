// Radiance gdpt cannot represent never reaches an output layer as NaN or infinity. Guards the
// class "non-finite values in output layers": per-pixel statistics and the Poisson solver's
// norms hold squares of radiance in float32, so emission or inputs near float's range used to
// give NaN/Inf pixels (emissive factor × strength overflowing; --env 1e38 put NaN in G-PT's
// primal) or a solve that stopped after 0 iterations with residual 0 and returned its primal
// (‖b‖² overflowed). Now:
//  * render refuses emission outside [0, kMaxRadiance] (scene/radiance_range.h) with one
//    line naming the material or --env and the representable range, and writes nothing;
//  * the solver scales inputs above kSolveMaxMagnitude by a power of two and the result back,
//    which is exactly the same solve (poisson_gpu.h): the L2 solve of X·2^100 is bit for bit
//    the solve of X times 2^100;
//  * the last guard (image/finite_check.h) refuses to write a layer that overflowed anyway.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "cli_runner.h"
#include "image/exr_io.h"

namespace gdpt {
namespace {

namespace fs = std::filesystem;
using test::runGdpt;
using test::RunResult;

const std::string kScene = std::string(GDPT_SOURCE_DIR) + "/scenes/cornell_box.gltf";

class RadianceRangeCli : public test::TempDirTest {
protected:
    // The Cornell box with its light's KHR_materials_emissive_strength set to `strength`.
    std::string sceneWithStrength(const std::string& strength) {
        std::ifstream in(kScene);
        std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        const std::string key = "\"emissiveStrength\": 17.0";
        const auto pos = text.find(key);
        EXPECT_NE(pos, std::string::npos) << "the scene's light has emissiveStrength 17.0";
        if (pos != std::string::npos) text.replace(pos, key.size(), "\"emissiveStrength\": " + strength);
        const std::string file = path("box_" + strength + ".gltf");
        std::ofstream(file) << text;
        return file;
    }
    // `args` fails with exit 1, one line containing each of `why`, and no output file.
    void expectRefused(const std::string& args, const std::vector<std::string>& why) {
        const RunResult r = runGdpt(args + " --quiet -o " + path("out.exr"));
        EXPECT_EQ(r.code, 1) << args << ": " << r.output;
        for (const std::string& w : why)
            EXPECT_NE(r.output.find(w), std::string::npos) << w << " in: " << r.output;
        EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << "one line: " << r.output;
        EXPECT_FALSE(fs::exists(path("out.exr")));
    }
};

TEST_F(RadianceRangeCli, RenderRefusesEmissionOutsideTheRepresentableRange) {
    const std::string size = " --width 8 --height 8 --spp 2 ";
    // 1e30 is a float, its square is not: refused by the radiance range. 1e39 overflows float
    // itself (factor × strength): the loader refuses it already, naming the material.
    const std::string squareOverflows = sceneWithStrength("1e30");
    const std::string overflows = sceneWithStrength("1e39");
    for (const char* method : {"gpt", "pt"}) {
        expectRefused("render " + squareOverflows + size + "--method " + method,
                      {squareOverflows, "material", "emission", "representable range [0, 1e+12]"});
        expectRefused("render " + overflows + size + "--method " + method,
                      {overflows, "material", "overflows single precision"});
    }
    expectRefused("render " + kScene + size + "--method gpt --env 1e38", {"--env", "representable range"});
    // Power: the same scene within range renders.
    const RunResult ok =
        runGdpt("render " + sceneWithStrength("1e6") + size + "--quiet -o " + path("ok.exr"));
    EXPECT_EQ(ok.code, 0) << ok.output;
}

// An L2 solve of a smooth image with noisy primal and exact gradients, at magnitude 1 and at
// magnitude 2^100 (~1.3e30, whose squares overflow float): the second is the first times
// 2^100 bit for bit, and it did iterate.
TEST_F(RadianceRangeCli, SolveOfHugeInputsIsTheScaledSolve) {
    const int w = 19, h = 13;
    const auto write = [&](const std::string& file, int exponent) {
        Image primal(w, h), dx(w, h), dy(w, h);
        for (int c = 0; c < 3; ++c)
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) {
                    const auto truth = [&](int u, int v) {
                        return 0.5 + 0.3 * std::sin(0.4 * u + c) * std::cos(0.3 * v);
                    };
                    primal.at(x, y, c) =
                        std::ldexp(float(truth(x, y) + ((x + y) % 2 ? 0.05 : -0.05)), exponent);
                    if (x + 1 < w)
                        dx.at(x, y, c) = std::ldexp(float(truth(x + 1, y) - truth(x, y)), exponent);
                    if (y + 1 < h)
                        dy.at(x, y, c) = std::ldexp(float(truth(x, y + 1) - truth(x, y)), exponent);
                }
        writeExr(file, {{"primal", primal}, {"dx", dx}, {"dy", dy}});
    };
    write(path("one.exr"), 0);
    write(path("huge.exr"), 100);
    RunResult r = runGdpt("solve " + path("one.exr") + " --recon l2 -o " + path("one_out.exr"));
    ASSERT_EQ(r.code, 0) << r.output;
    r = runGdpt("solve " + path("huge.exr") + " --recon l2 -o " + path("huge_out.exr"));
    ASSERT_EQ(r.code, 0) << r.output;
    EXPECT_EQ(r.output.find(" 0 iterations"), std::string::npos) << r.output;
    const Image one = readExrLayer(path("one_out.exr"), "recon"),
                huge = readExrLayer(path("huge_out.exr"), "recon");
    ASSERT_TRUE(one.sameSize(huge));
    for (int c = 0; c < 3; ++c)
        for (std::size_t i = 0; i < one.pixelCount(); ++i)
            ASSERT_EQ(std::ldexp(one.plane(c)[i], 100), huge.plane(c)[i])
                << "channel " << c << " pixel " << i;
    // L1 has an absolute regulariser, so no bit identity; it must still iterate to a finite
    // image close to the scaled one.
    r = runGdpt("solve " + path("huge.exr") + " --recon l1 -o " + path("huge_l1.exr"));
    ASSERT_EQ(r.code, 0) << r.output;
    const Image l1 = readExrLayer(path("huge_l1.exr"), "recon");
    for (int c = 0; c < 3; ++c)
        for (std::size_t i = 0; i < l1.pixelCount(); ++i)
            ASSERT_NEAR(std::ldexp(l1.plane(c)[i], -100), one.plane(c)[i], 0.05)
                << "channel " << c << " pixel " << i;
}

// The last guard: a final image that overflows (reconstruction 3e38 + direct 3e38) is not
// written; the error names the output and the layer.
TEST_F(RadianceRangeCli, SolveRefusesToWriteAnOverflowingImage) {
    const Image big(4, 3, 3e38f), zero(4, 3, 0.0f);
    writeExr(path("in.exr"), {{"primal", big}, {"dx", zero}, {"dy", zero}, {"direct", big}});
    expectRefused("solve " + path("in.exr") + " --recon l2", {path("out.exr"), "not written", "the image"});
}

}  // namespace
}  // namespace gdpt
