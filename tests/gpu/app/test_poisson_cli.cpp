// test_poisson_cli.cpp — `gdpt solve` and `gdpt clone` end to end: exit codes (0 ok, 1
// input/runtime error, 2 usage), one-line errors naming the file, outputs with the
// documented layers, and a reconstruction that reproduces the image its exact gradients
// came from.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "cli_runner.h"
#include "image/exr_io.h"
#include "image/png_preview.h"

namespace gdpt {
namespace {

namespace fs = std::filesystem;
using test::runGdpt;
using test::RunResult;

class PoissonCli : public test::TempDirTest {};

// A small gradient-domain EXR: primal = image + offset noise, exact dx/dy, a direct layer.
Image writeGradientExr(const std::string& file, bool withVariance) {
    const int w = 23, h = 17;
    Image truth(w, h), dx(w, h), dy(w, h), primal(w, h), direct(w, h, 0.25f), var(w, h, 0.01f);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                truth.at(x, y, c) = static_cast<float>(0.5 + 0.4 * std::sin(0.5 * x + c) * std::cos(0.3 * y));
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                primal.at(x, y, c) = truth.at(x, y, c) + ((x + y) % 2 ? 0.05f : -0.05f);
                if (x + 1 < w) dx.at(x, y, c) = truth.at(x + 1, y, c) - truth.at(x, y, c);
                if (y + 1 < h) dy.at(x, y, c) = truth.at(x, y + 1, c) - truth.at(x, y, c);
            }
    std::vector<NamedLayer> layers = {{"primal", primal}, {"dx", dx}, {"dy", dy}, {"direct", direct}};
    if (withVariance) {
        layers.push_back({"var_primal", var});
        layers.push_back({"var_dx", var});
        layers.push_back({"var_dy", var});
    }
    writeExr(file, layers);
    return truth;
}

TEST_F(PoissonCli, SolveWritesFinalAndReconLayers) {
    const Image truth = writeGradientExr(path("in.exr"), true);
    for (const char* recon : {"l2", "l1", "wl2", "wl1"}) {
        const std::string out = path(std::string("out_") + recon + ".exr");
        // The published reconstructions (--debias-cells 0): on a 23x17 image the default grid's
        // nodes are 3 px apart, and its hats would bring back part of the checkerboard.
        const RunResult r =
            runGdpt("solve " + path("in.exr") + " -o " + out + " --debias-cells 0 --recon " + recon);
        ASSERT_EQ(r.code, 0) << r.output;
        const Image rec = readExrLayer(out, "recon");
        const Image final = readExrLayer(out);
        double err = 0.0;
        for (int c = 0; c < 3; ++c)
            for (std::size_t i = 0; i < rec.pixelCount(); ++i) {
                err = std::max(err, double(std::abs(rec.plane(c)[i] - truth.plane(c)[i])));
                ASSERT_NEAR(final.plane(c)[i], rec.plane(c)[i] + 0.25f, 1e-6);
            }
        // The ±0.05 checkerboard in the primal is almost entirely rejected by the exact
        // gradients (it has no gradient support): the error stays well below 0.05.
        EXPECT_LT(err, 0.02) << recon;
    }
}

// Largest absolute difference between the 'recon' layers of two solve outputs.
double maxReconDifference(const std::string& a, const std::string& b) {
    const Image ia = readExrLayer(a, "recon"), ib = readExrLayer(b, "recon");
    double d = 0.0;
    for (int c = 0; c < 3; ++c)
        for (std::size_t i = 0; i < ia.pixelCount(); ++i)
            d = std::max(d, double(std::abs(ia.plane(c)[i] - ib.plane(c)[i])));
    return d;
}

// The IRLS schedule flags reach the solver: the defaults spelt out give the same bits, and a
// regulariser far above every residual makes the weights 1/(|e| + reg) uniform, which turns
// L1 back into the L2 solve (up to the solver tolerance), while the default L1 stays away
// from it. Out-of-range values are usage errors.
TEST_F(PoissonCli, SolveIrlsScheduleFlags) {
    // Outliers in a few gradients: what L1 rejects and L2 spreads out.
    writeGradientExr(path("clean.exr"), false);
    Image dx = readExrLayer(path("clean.exr"), "dx");
    for (int k = 0; k < 5; ++k)
        for (int c = 0; c < 3; ++c) dx.at(3 + 4 * k, 2 + 3 * k, c) += 2.0f;
    writeExr(path("in.exr"), {{"primal", readExrLayer(path("clean.exr"), "primal")},
                              {"dx", dx},
                              {"dy", readExrLayer(path("clean.exr"), "dy")}});
    // The published L1 (--debias-cells 0): the flags under test act on the solve, on the device
    // and on the host, each with its default inner tolerance spelt out.
    for (const auto& [solver, innerTolerance] :
         {std::pair<std::string, std::string>{"mg-pcg", "0.02"}, {"host-pcg", "0.005"}}) {
        SCOPED_TRACE(solver);
        const std::string in = path("in.exr") + " --tolerance 1e-6 --debias-cells 0 --solver " + solver + " ";
        ASSERT_EQ(runGdpt("solve " + in + "--recon l2 -o " + path("l2.exr")).code, 0);
        ASSERT_EQ(runGdpt("solve " + in + "--recon l1 -o " + path("l1.exr")).code, 0);
        ASSERT_EQ(runGdpt("solve " + in +
                          "--recon l1 --irls-iterations 6 --irls-reg-init 0.05 --irls-reg-iter 0.4 "
                          "--irls-inner-tolerance " +
                          innerTolerance + " -o " + path("l1_explicit.exr"))
                      .code,
                  0);
        ASSERT_EQ(runGdpt("solve " + in + "--recon l1 --irls-reg-init 1e6 --irls-reg-iter 1 -o " +
                          path("l1_reg.exr"))
                      .code,
                  0);
        EXPECT_EQ(maxReconDifference(path("l1.exr"), path("l1_explicit.exr")), 0.0);
        const double l1ToL2 = maxReconDifference(path("l1.exr"), path("l2.exr"));
        const double regToL2 = maxReconDifference(path("l1_reg.exr"), path("l2.exr"));
        EXPECT_GT(l1ToL2, 0.05);
        EXPECT_LT(regToL2, 0.1 * l1ToL2) << "L1 default to L2: " << l1ToL2;
        for (const char* bad : {"--irls-reg-iter 0", "--irls-reg-iter 1.5", "--irls-reg-init 0",
                                "--irls-inner-tolerance 0.9", "--solver mg-pcgx"})
            EXPECT_EQ(runGdpt("solve " + in + "--recon l1 " + bad + " -o " + path("bad.exr")).code, 2) << bad;
    }
    EXPECT_FALSE(fs::exists(path("bad.exr")));
}

// Fireflies in the primal (a few pixels far too bright, with no gradient support): L1 rejects
// them and its image is darker than the primal's mean; debiased (the default --debias-cells)
// the image mean is the primal's exactly, and the fine detail is still L1's (the fireflies
// stay rejected). L2 is not debiased.
TEST_F(PoissonCli, SolveDebiasesL1ToThePrimalsMean) {
    const Image truth = writeGradientExr(path("clean.exr"), false);
    Image primal = readExrLayer(path("clean.exr"), "primal");
    for (int k = 0; k < 4; ++k)
        for (int c = 0; c < 3; ++c) primal.at(2 + 5 * k, 3 + 3 * k, c) += 8.0f;
    writeExr(path("in.exr"), {{"primal", primal},
                              {"dx", readExrLayer(path("clean.exr"), "dx")},
                              {"dy", readExrLayer(path("clean.exr"), "dy")}});
    const auto mean = [](const Image& im) {
        const std::array<double, 3> m = im.meanRgb();
        return (m[0] + m[1] + m[2]) / 3.0;
    };
    const RunResult on = runGdpt("solve " + path("in.exr") + " --recon l1 -o " + path("on.exr"));
    ASSERT_EQ(on.code, 0) << on.output;
    EXPECT_NE(on.output.find("debiased at 3 px: mean +"), std::string::npos) << on.output;  // 17 px / 8
    ASSERT_EQ(runGdpt("solve " + path("in.exr") + " --recon l1 --debias-cells 0 -o " + path("off.exr")).code,
              0);
    const Image debiased = readExrLayer(path("on.exr"), "recon"),
                published = readExrLayer(path("off.exr"), "recon");
    EXPECT_NEAR(mean(debiased), mean(primal), 1e-5);
    EXPECT_LT(mean(published), mean(primal) - 0.05);  // the power: L1 alone is darker
    // The debiased image is the published one plus a smooth field: its pixel-to-pixel
    // differences stay near L1's (the fireflies are not put back).
    double worst = 0.0;
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < truth.height(); ++y)
            for (int x = 0; x + 1 < truth.width(); ++x) {
                const double d1 = debiased.at(x + 1, y, c) - debiased.at(x, y, c);
                const double d0 = published.at(x + 1, y, c) - published.at(x, y, c);
                worst = std::max(worst, std::abs(d1 - d0));
            }
    // A firefly is 8; its energy (32 per channel) spread over a hat of nodes 3 px apart
    // changes a difference by under 1.
    EXPECT_LT(worst, 1.5);
    const RunResult l2 = runGdpt("solve " + path("in.exr") + " --recon l2 -o " + path("l2.exr"));
    ASSERT_EQ(l2.code, 0) << l2.output;
    EXPECT_EQ(l2.output.find("debiased"), std::string::npos) << l2.output;
    EXPECT_EQ(runGdpt("solve " + path("in.exr") + " --debias-cells -2 -o " + path("bad.exr")).code, 2);
}

TEST_F(PoissonCli, SolveFromSeparateFilesAndErrors) {
    writeGradientExr(path("in.exr"), false);
    writeExr(path("p.exr"), readExrLayer(path("in.exr"), "primal"));
    writeExr(path("dx.exr"), readExrLayer(path("in.exr"), "dx"));
    writeExr(path("dy.exr"), readExrLayer(path("in.exr"), "dy"));
    RunResult r = runGdpt("solve --primal " + path("p.exr") + " --dx " + path("dx.exr") + " --dy " +
                          path("dy.exr") + " -o " + path("sep.exr") + " --solver cg");
    EXPECT_EQ(r.code, 0) << r.output;
    EXPECT_TRUE(fs::exists(path("sep.exr")));
    // Usage errors: nothing to read, unknown method.
    EXPECT_EQ(runGdpt("solve -o " + path("x.exr")).code, 2);
    EXPECT_EQ(runGdpt("solve " + path("in.exr") + " --recon l3").code, 2);
    // Input errors: wl2 without variance layers, a file without the layers.
    r = runGdpt("solve " + path("in.exr") + " --recon wl2 -o " + path("w.exr"));
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.output.find("var_primal"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(path("w.exr")));
    r = runGdpt("solve " + path("p.exr") + " -o " + path("q.exr"));
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.output.find("p.exr"), std::string::npos) << r.output;
}

TEST_F(PoissonCli, CloneWritesPngAndExr) {
    Image source(12, 10, 0.8f), target(30, 24, 0.1f), mask(12, 10);
    for (int y = 2; y < 8; ++y)
        for (int x = 2; x < 10; ++x) mask.at(x, y, 0) = 1.0f;
    writeExr(path("s.exr"), source);
    writeExr(path("t.exr"), target);
    writeExr(path("m.exr"), mask);
    RunResult r = runGdpt("clone --source " + path("s.exr") + " --target " + path("t.exr") + " --mask " +
                          path("m.exr") + " --offset 5,6 -o " + path("out.exr"));
    ASSERT_EQ(r.code, 0) << r.output;
    // A constant source has zero gradients: the clone region takes the boundary value.
    const Image out = readExrLayer(path("out.exr"));
    EXPECT_NEAR(out.at(10, 10, 0), 0.1f, 1e-4);
    r = runGdpt("clone --source " + path("s.exr") + " --target " + path("t.exr") + " --mask " +
                path("m.exr") + " --offset 5,6 --mixed -o " + path("out.png"));
    EXPECT_EQ(r.code, 0) << r.output;
    EXPECT_TRUE(fs::exists(path("out.png")));
    EXPECT_EQ(runGdpt("clone --source " + path("s.exr") + " --target " + path("t.exr") + " --mask " +
                      path("m.exr") + " --offset 5 -o " + path("bad.png"))
                  .code,
              2);
    // Mask size must match the source.
    r = runGdpt("clone --source " + path("t.exr") + " --target " + path("t.exr") + " --mask " +
                path("m.exr") + " -o " + path("bad.exr"));
    EXPECT_EQ(r.code, 1);
    EXPECT_FALSE(fs::exists(path("bad.exr")));
}

}  // namespace
}  // namespace gdpt
