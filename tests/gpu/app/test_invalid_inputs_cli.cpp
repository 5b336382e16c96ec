// `solve`, `clone` and `diff` treat invalid input values alike. Guards the class "invalid
// inputs are reported or refused, never silently used": NaN or infinite values anywhere, and
// negative values in a variance layer. Each command says what it found, in which file and
// layer, in how many pixels (and the first), and what it did with them, or refuses (exit 1,
// one line naming the file) when nothing usable is left. Before: a NaN `direct` layer gave a
// NaN image without a word; negative variances were reported as "non-finite"; clone zeroed a
// NaN source silently; diff of an all-NaN image printed "relMSE nan ... (0 pixels)" and exited 0.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "cli_runner.h"
#include "image/exr_io.h"

namespace gdpt {
namespace {

namespace fs = std::filesystem;
using test::runGdpt;
using test::RunResult;

class InvalidInputsCli : public test::TempDirTest {
protected:
    static constexpr int kW = 12, kH = 9;
    // A gradient-domain EXR of a smooth image with exact gradients, a direct layer and
    // variances; `edit` changes the layers before writing.
    void writeSolveInput(const std::string& file, const std::function<void(std::vector<NamedLayer>&)>& edit) {
        Image primal(kW, kH), dx(kW, kH), dy(kW, kH), direct(kW, kH, 0.25f), var(kW, kH, 0.01f);
        for (int c = 0; c < 3; ++c)
            for (int y = 0; y < kH; ++y)
                for (int x = 0; x < kW; ++x) {
                    const auto t = [&](int u, int v) {
                        return float(0.5 + 0.2 * std::sin(0.5 * u + 0.3 * v + c));
                    };
                    primal.at(x, y, c) = t(x, y);
                    if (x + 1 < kW) dx.at(x, y, c) = t(x + 1, y) - t(x, y);
                    if (y + 1 < kH) dy.at(x, y, c) = t(x, y + 1) - t(x, y);
                }
        std::vector<NamedLayer> layers = {{"primal", primal}, {"dx", dx},          {"dy", dy},
                                          {"direct", direct}, {"var_primal", var}, {"var_dx", var},
                                          {"var_dy", var}};
        edit(layers);
        writeExr(file, layers);
    }
    static Image& layer(std::vector<NamedLayer>& layers, const std::string& name) {
        for (NamedLayer& l : layers)
            if (l.name == name) return l.image;
        throw std::runtime_error("no layer " + name);
    }
    static bool allFinite(const Image& im) {
        for (int c = 0; c < 3; ++c)
            for (float v : im.plane(c))
                if (!std::isfinite(v)) return false;
        return true;
    }
    static void expectContains(const std::string& text, const std::vector<std::string>& parts) {
        for (const std::string& p : parts)
            EXPECT_NE(text.find(p), std::string::npos) << "'" << p << "' in: " << text;
    }
};

TEST_F(InvalidInputsCli, SolveReportsNonFiniteAndNegativeValuesPerLayer) {
    const std::string in = path("in.exr"), out = path("out.exr");
    writeSolveInput(in, [](std::vector<NamedLayer>& l) {
        layer(l, "direct").at(3, 2, 1) = std::nanf("");
        layer(l, "direct").at(5, 4, 0) = INFINITY;
        layer(l, "dx").at(7, 1, 2) = std::nanf("");
        layer(l, "var_dx").at(2, 6, 0) = -0.5f;
    });
    RunResult r = runGdpt("solve " + in + " --recon wl2 -o " + out);
    ASSERT_EQ(r.code, 0) << r.output;
    expectContains(r.output,
                   {in + ": layer 'direct': NaN or infinite values in 2 of 108 pixels (the first at (3, 2))",
                    "counted as zero", in + ": layer 'dx': NaN or infinite values in 1 of 108 pixels",
                    "left out of the solve",
                    in + ": layer 'var_dx': negative values (not a variance) in 1 of 108 pixels "
                         "(the first at (2, 6))"});
    EXPECT_EQ(r.output.find("non-finite inputs"), std::string::npos) << r.output;
    EXPECT_TRUE(allFinite(readExrLayer(out))) << "the final image";
    EXPECT_TRUE(allFinite(readExrLayer(out, "recon")));

    // Nothing usable left: refused, naming the layer.
    const auto refused = [&](const std::string& why,
                             const std::function<void(std::vector<NamedLayer>&)>& edit,
                             const std::string& recon) {
        writeSolveInput(path("bad.exr"), edit);
        const RunResult b =
            runGdpt("solve " + path("bad.exr") + " --recon " + recon + " -o " + path("bad_out.exr"));
        EXPECT_EQ(b.code, 1) << b.output;
        expectContains(b.output, {path("bad.exr"), why});
        EXPECT_FALSE(fs::exists(path("bad_out.exr")));
    };
    refused(
        "layer 'var_dy' has no valid variance",
        [](std::vector<NamedLayer>& l) { layer(l, "var_dy") = Image(kW, kH, -1.0f); }, "wl2");
    refused(
        "layer 'primal' has no finite pixel",
        [](std::vector<NamedLayer>& l) { layer(l, "primal") = Image(kW, kH, std::nanf("")); }, "l2");
}

TEST_F(InvalidInputsCli, CloneReportsANonFiniteSourceAndRefusesANonFiniteTarget) {
    Image source(6, 5, 0.8f), target(10, 8, 0.2f), mask(6, 5, 1.0f);
    source.at(2, 2, 0) = std::nanf("");
    writeExr(path("source.exr"), source);
    writeExr(path("target.exr"), target);
    writeExr(path("mask.exr"), mask);
    const std::string args = " --mask " + path("mask.exr") + " --offset 2,2 -o " + path("out.exr");
    RunResult r = runGdpt("clone --source " + path("source.exr") + " --target " + path("target.exr") + args);
    ASSERT_EQ(r.code, 0) << r.output;
    expectContains(r.output,
                   {path("source.exr") + ": NaN or infinite values in 1 of 30 pixels (the first at (2, 2))",
                    "replaced by the target's"});
    EXPECT_TRUE(allFinite(readExrLayer(path("out.exr"))));
    target.at(0, 0, 2) = -INFINITY;
    writeExr(path("bad_target.exr"), target);
    fs::remove(path("out.exr"));
    r = runGdpt("clone --source " + path("source.exr") + " --target " + path("bad_target.exr") + args);
    EXPECT_EQ(r.code, 1) << r.output;
    expectContains(r.output, {path("bad_target.exr") + ": NaN or infinite values in 1 of 80 pixels"});
    EXPECT_FALSE(fs::exists(path("out.exr")));
}

TEST_F(InvalidInputsCli, DiffNamesNonFiniteFilesAndFailsWithNothingToCompare) {
    Image a(8, 8, 0.5f), b(8, 8, 0.5f), nan(8, 8, std::nanf("")), small(4, 8, 0.5f);
    a.at(1, 3, 0) = INFINITY;
    writeExr(path("a.exr"), a);
    writeExr(path("b.exr"), b);
    writeExr(path("nan.exr"), nan);
    writeExr(path("small.exr"), small);
    RunResult r = runGdpt("diff " + path("a.exr") + " " + path("b.exr"));
    ASSERT_EQ(r.code, 0) << r.output;
    expectContains(r.output,
                   {path("a.exr") + ": NaN or infinite values in 1 of 64 pixels (the first at (1, 3))",
                    "left out of the metrics", "(63 pixels, 1 non-finite)"});
    r = runGdpt("diff " + path("nan.exr") + " " + path("b.exr"));
    EXPECT_EQ(r.code, 1) << r.output;
    expectContains(r.output, {path("nan.exr"), path("b.exr"), "nothing to compare"});
    EXPECT_EQ(r.output.find("relMSE"), std::string::npos) << r.output;
    // Different sizes: both files named (also a message class: which file is which size).
    r = runGdpt("diff " + path("small.exr") + " " + path("b.exr"));
    EXPECT_EQ(r.code, 1) << r.output;
    expectContains(r.output, {path("small.exr") + " (4x8)", path("b.exr") + " (8x8)"});
}

}  // namespace
}  // namespace gdpt
