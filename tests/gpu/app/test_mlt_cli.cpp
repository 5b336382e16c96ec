// `gdpt render --method pssmlt|gmlt`: the JSON reports the chains, both acceptance rates and
// the bootstrap's normalisation with its standard error; the options that need per-pixel
// statistics (checkpoints, shards, the variance-weighted reconstructions) are usage errors
// that leave no output behind.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_runner.h"
#include "temp_dir.h"

namespace gdpt {
namespace {

using test::runGdpt;
using test::RunResult;

const std::string kScene = std::string(GDPT_SOURCE_DIR) + "/scenes/cornell_box.gltf";

class MltCli : public test::TempDirTest {};

TEST_F(MltCli, JsonReportsChainsAcceptanceAndNormalisation) {
    for (const std::string method : {"pssmlt", "gmlt"}) {
        const RunResult r = runGdpt("render " + kScene + " --method " + method +
                                    " --width 24 --height 16 --spp 8 --chains 512 --large-step 0.25 "
                                    "--split-bounce on -o " +
                                    path(method + ".exr") + " --json " + path(method + ".json"));
        ASSERT_EQ(r.code, 0) << r.output;
        EXPECT_NE(r.output.find("512 chains, acceptance"), std::string::npos) << r.output;
        EXPECT_TRUE(std::filesystem::exists(path(method + ".png")));
        std::ifstream in(path(method + ".json"));
        const nlohmann::json j = nlohmann::json::parse(in);
        EXPECT_EQ(j["method"], method);
        const nlohmann::json& m = j.at("mlt");
        EXPECT_EQ(m["chains"], 512);
        EXPECT_FLOAT_EQ(m["large_step_probability"].get<float>(), 0.25f);
        // 8 mutations per pixel of 384 pixels on 512 chains: 6 steps of every chain.
        EXPECT_EQ(m["mutations"], 6 * 512);
        EXPECT_EQ(m["proposed_small"].get<int>() + m["proposed_large"].get<int>(), 6 * 512);
        for (const char* rate : {"acceptance_small", "acceptance_large"}) {
            EXPECT_GT(m[rate].get<double>(), 0.0) << rate;
            EXPECT_LT(m[rate].get<double>(), 1.0) << rate;
        }
        EXPECT_GE(m["bootstrap_samples"], 512 * 16);
        EXPECT_GT(m["bootstrap_ess"].get<double>(), 1.0);
        EXPECT_LE(m["bootstrap_ess"].get<double>(), m["bootstrap_samples"].get<double>());
        EXPECT_GT(m["normalisation"].get<double>(), 0.0);
        EXPECT_GT(m["normalisation_stderr"].get<double>(), 0.0);
        EXPECT_LT(m["normalisation_stderr"].get<double>(), 0.1 * m["normalisation"].get<double>());
        EXPECT_GE(m["splat_s"].get<double>(), 0.0);
        EXPECT_LT(m["splat_s"].get<double>(), j["time_s"]["sampling"].get<double>());
        EXPECT_EQ(j["reconstructions"].size(), method == "gmlt" ? 1u : 0u);
        // --split-bounce reaches gmlt's kernel (G-PT's sample); pssmlt traces the path tracer's.
        // gmlt's primal weight is its own default (0.05, not G-PT's 0.2).
        if (method == "gmlt") {
            EXPECT_TRUE(m.at("split_bounce").get<bool>());
            EXPECT_DOUBLE_EQ(j["reconstructions"][0].at("alpha").get<double>(), 0.05);
        } else {
            EXPECT_FALSE(m.contains("split_bounce"));
        }
    }
}

// Left unset, --large-step, --target-exponent, --target-block and --alpha are each method's
// own: pssmlt 0.5 and Kelemen's target (exponent 1, undivided); gmlt 0.7, its target to the
// power 0.25 divided per block of 16 pixels, and a primal weight of 0.05 (bench/RESULTS.md,
// "G-MLT's large-step probability", "A tempered target for G-MLT's chains", "G-MLT's target per
// image block", "G-MLT's primal weight"). Given, --target-exponent and --target-block reach the
// chains of both.
TEST_F(MltCli, DefaultsAreEachMethodsOwn) {
    // An 8 x 8 render of `method` with `flags`; its --json report.
    const auto render = [&](const std::string& method, const std::string& flags, const std::string& tag) {
        const RunResult r =
            runGdpt("render " + kScene + " --method " + method + " --width 8 --height 8 --spp 2 " + flags +
                    " -o " + path(method + tag + ".exr") + " --json " + path(method + tag + ".json"));
        EXPECT_EQ(r.code, 0) << r.output;
        std::ifstream in(path(method + tag + ".json"));
        return nlohmann::json::parse(in);
    };
    for (const std::string method : {"pssmlt", "gmlt"}) {
        const nlohmann::json j = render(method, "", "");
        EXPECT_FLOAT_EQ(j.at("mlt").at("large_step_probability").get<float>(),
                        method == "gmlt" ? 0.7f : 0.5f);
        EXPECT_FLOAT_EQ(j.at("mlt").at("target_exponent").get<float>(), method == "gmlt" ? 0.25f : 1.0f);
        EXPECT_EQ(j.at("mlt").at("target_block").get<int>(), method == "gmlt" ? 16 : 0);
        if (method == "gmlt") {
            EXPECT_DOUBLE_EQ(j["reconstructions"][0].at("alpha").get<double>(), 0.05);
        }
        // The exponent given: reported, and the chains walk another target (other acceptances).
        const nlohmann::json g = render(method, "--target-exponent 0.5", "_g");
        EXPECT_FLOAT_EQ(g.at("mlt").at("target_exponent").get<float>(), 0.5f);
        EXPECT_NE(g.at("mlt").at("acceptance_small").get<double>(),
                  j.at("mlt").at("acceptance_small").get<double>())
            << method;
        // Blocks of 4 pixels: four divisors on the 8 x 8 image (gmlt's 16 is one, a constant
        // that changes no acceptance), so the chains walk another target.
        const nlohmann::json b = render(method, "--target-block 4", "_b");
        EXPECT_EQ(b.at("mlt").at("target_block").get<int>(), 4);
        EXPECT_NE(b.at("mlt").at("acceptance_small").get<double>(),
                  j.at("mlt").at("acceptance_small").get<double>())
            << method;
    }
}

TEST_F(MltCli, OptionsThatNeedPerPixelStatisticsAreUsageErrors) {
    const std::string base = "render " + kScene + " --width 8 --height 8 --spp 2 -o " + path("x.exr") + " ";
    const struct {
        std::string flags, says;
    } cases[] = {
        {"--method gmlt --checkpoint " + path("c.exr"), "Markov chains"},
        {"--method pssmlt --shard 0/2", "Markov chains"},
        {"--method gmlt --recon wl1", "l1 or l2"},
        {"--method gmlt --recon wl2", "l1 or l2"},
        {"--method gmlt --alpha 0", "--alpha"},
    };
    for (const auto& c : cases) {
        const RunResult r = runGdpt(base + c.flags);
        EXPECT_EQ(r.code, 2) << c.flags << "\n" << r.output;
        EXPECT_NE(r.output.find(c.says), std::string::npos) << c.flags << "\n" << r.output;
        EXPECT_FALSE(std::filesystem::exists(path("x.exr"))) << c.flags;
        EXPECT_FALSE(std::filesystem::exists(path("c.exr"))) << c.flags;
    }
    // The same render with --recon l2 is fine (the power of the check above).
    const RunResult ok = runGdpt(base + "--method gmlt --recon l2");
    EXPECT_EQ(ok.code, 0) << ok.output;
}

}  // namespace
}  // namespace gdpt
