// Images one pixel wide or high (1x1, 1xN, Nx1) with G-PT: the mean of every reconstruction
// (final image = recon_<name> + direct) equals the mean of a path-traced render of the same
// scene and size. Guards the class "G-PT at width or height 1": a pixel there has fewer than
// two pixel pairs (a 1x1 pixel none), which the primal estimator and the reconstruction must
// handle like any border pixel; a 1x1 G-PT primal used to be zero (the image 34 % too dark).
//
// Statistics. G-PT and PT run with different seeds, so the two image means are independent
// estimates of the same integral. PT's pixels are independent: var(mean) = Σ var_p / N². For
// G-PT the variance of the mean of a reconstruction has no closed form, so it is bounded by
// the primal's: the screened Poisson solve keeps the image mean of its primal term (exactly for
// L2, where A's columns sum to α² and the solver shifts the weighted mean; to within the
// reweighting for L1), and the primal pixels are correlated (neighbours share samples), so
// sd(Σ_p Y_p) <= Σ_p sd(Y_p) (Cauchy-Schwarz) with Y_p = primal_p + direct_p, whose variance is
// var_primal + var_direct (their covariance is neglected as in test_gpt_render.cpp: a sample
// that sees an emitter first ends there). The test is |Δmean| <= z · sqrt(se_gpt² + se_pt²)
// per size, reconstruction and channel, z Šidák-corrected over all of them (family alpha
// 1e-3). Power: at 1x1 the old error (-0.07 on a mean of about 0.2) is > 10 standard errors at
// these sample counts.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "cli_runner.h"
#include "image/exr_io.h"
#include "stats_normal.h"

namespace gdpt {
namespace {

using test::runGdpt;
using test::RunResult;

const std::string kScene = std::string(GDPT_SOURCE_DIR) + "/scenes/cornell_box.gltf";

class ThinImageCli : public test::TempDirTest {};

const Image& layer(const std::vector<NamedLayer>& layers, const std::string& name) {
    for (const NamedLayer& l : layers)
        if (l.name == name) return l.image;
    ADD_FAILURE() << "no layer '" << name << "'";
    static const Image empty;
    return empty;
}

TEST_F(ThinImageCli, GptMeanEqualsPathTracedMeanAtWidthOrHeightOne) {
    struct Size {
        int w, h, spp;
    };
    // Fewer samples per pixel as pixels grow, about the same standard error of the mean.
    const std::vector<Size> sizes = {{1, 1, 8192}, {1, 6, 2048}, {6, 1, 2048}};
    const std::vector<std::string> recons = {"recon_l1", "recon_l2", "recon_wl2", "recon_wl1"};
    const double z =
        test::twoSidedZ(test::sidakAlpha(1e-3, static_cast<int>(sizes.size() * (recons.size() + 1) * 3)));
    for (const Size& s : sizes) {
        const std::string size = " --width " + std::to_string(s.w) + " --height " + std::to_string(s.h) +
                                 " --spp " + std::to_string(s.spp) + " --quiet ";
        const std::string pt = path("pt.exr"), gpt = path("gpt.exr");
        const RunResult a = runGdpt("render " + kScene + size + "--method pt --seed 1 -o " + pt);
        ASSERT_EQ(a.code, 0) << a.output;
        const RunResult b =
            runGdpt("render " + kScene + size + "--method gpt --all-recon --seed 2 -o " + gpt);
        ASSERT_EQ(b.code, 0) << b.output;
        const std::vector<NamedLayer> p = readExr(pt), g = readExr(gpt);
        const Image& ptImage = layer(p, "");
        const Image& ptVar = layer(p, "variance");
        const Image& primal = layer(g, "primal");
        const Image& direct = layer(g, "direct");
        const Image& varPrimal = layer(g, "var_primal");
        const Image& varDirect = layer(g, "var_direct");
        const double n = static_cast<double>(ptImage.pixelCount());
        for (int c = 0; c < 3; ++c) {
            double ptMean = 0.0, ptVarMean = 0.0, gptSd = 0.0;
            for (std::size_t i = 0; i < ptImage.pixelCount(); ++i) {
                ptMean += ptImage.plane(c)[i] / n;
                ptVarMean += ptVar.plane(c)[i] / (n * n);
                gptSd += std::sqrt(double(varPrimal.plane(c)[i]) + varDirect.plane(c)[i]) / n;
            }
            const double se = std::sqrt(ptVarMean + gptSd * gptSd);
            ASSERT_GT(se, 0.0);
            for (const std::string& name : recons) {
                const Image& recon = layer(g, name);
                double gptMean = 0.0;
                for (std::size_t i = 0; i < recon.pixelCount(); ++i)
                    gptMean += (double(recon.plane(c)[i]) + direct.plane(c)[i]) / n;
                EXPECT_LE(std::abs(gptMean - ptMean), z * se)
                    << s.w << "x" << s.h << " " << name << " channel " << c << ": G-PT mean " << gptMean
                    << ", PT mean " << ptMean << ", standard error " << se;
            }
            // The primal itself, unreconstructed.
            double primalMean = 0.0;
            for (std::size_t i = 0; i < primal.pixelCount(); ++i)
                primalMean += (double(primal.plane(c)[i]) + direct.plane(c)[i]) / n;
            EXPECT_LE(std::abs(primalMean - ptMean), z * se)
                << s.w << "x" << s.h << " primal + direct, channel " << c;
        }
    }
}

}  // namespace
}  // namespace gdpt
