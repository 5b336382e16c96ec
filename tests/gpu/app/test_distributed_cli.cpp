// Distributed rendering end to end (docs/distributed.md): `gdpt render --shard I/N` + `gdpt
// merge`, and `mpirun -n N gdpt render`, for PT and G-PT.
//
// What must hold, and why:
//   - shards merged in any order give the same bits (they are merged in part order), and
//     `mpirun -n N` gives the bits of the N shards' merge (the same parts, merged in rank
//     order, finished by the same code on the same device);
//   - against one process, every statistic differs by float32 rounding only. One process folds
//     the n samples of a pixel one batch after another, a split render folds each part and
//     then merges the parts (Chan et al. 1979). Every partial mean is a convex combination of
//     samples, all within sqrt(M2) of the pixel's mean μ (M2 = Σ (x − μ)² ≥ (x_i − μ)²), and a
//     merge step rounds its result by a few ulps of that magnitude, so over n merges in each of
//     the two renders |mean_split − mean_one| ≤ 2 · n · 3ε · (|μ| + sqrt(M2)), ε = 2^-24, M2 read
//     back from the variance layer (var · n (n − 1)). The resolved G-PT quantities combine up to
//     five statistics with weights ≤ 1: 5× that. A render with another seed (another set of
//     samples of the same pixels) breaks this bound in most pixels with any variance: the test
//     checks that too, so the bound can catch a part that takes the wrong samples.
//   - a rank that fails or dies makes the run exit non-zero naming it, with no output.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>
#include <string>
#include <tuple>
#include <vector>

#include "cli_runner.h"
#include "image/exr_io.h"
#include "same_bits.h"

namespace gdpt {
namespace {

using test::RunResult;

const std::string kScene = std::string(GDPT_SOURCE_DIR) + "/scenes/cornell_box.gltf";
constexpr int kSpp = 6;

const Image& layer(const std::vector<NamedLayer>& layers, const std::string& name) {
    for (const NamedLayer& l : layers)
        if (l.name == name) return l.image;
    throw std::runtime_error("no layer '" + name + "'");
}

// The statistics layers of a method and the variance layer of each (the final image of PT is
// its mean; G-PT's resolved primal, gradients and direct light).
std::vector<std::pair<std::string, std::string>> statisticLayers(const std::string& method) {
    if (method == "pt") return {{"", "variance"}};
    return {{"primal", "var_primal"}, {"dx", "var_dx"}, {"dy", "var_dy"}, {"direct", "var_direct"}};
}

struct BoundCheck {
    std::size_t values = 0;   // channel values with variance
    std::size_t beyond = 0;   // of which beyond the rounding bound
    double worstRatio = 0.0;  // largest |a − b| / bound over all values
};

// Compares the statistics layers of `a` and `b` against the rounding bound of the header.
BoundCheck roundingBound(const std::string& a, const std::string& b, const std::string& method) {
    const auto la = readExr(a), lb = readExr(b);
    const double n = kSpp, eps = std::ldexp(1.0, -24);
    const double factor = (method == "pt" ? 1.0 : 5.0) * 2.0 * n * 3.0 * eps;
    BoundCheck r;
    for (const auto& [value, variance] : statisticLayers(method)) {
        const Image &x = layer(la, value), &y = layer(lb, value), &v = layer(la, variance);
        for (int c = 0; c < 3; ++c)
            for (std::size_t i = 0; i < x.pixelCount(); ++i) {
                const double m2 = double(v.plane(c)[i]) * n * (n - 1.0);
                const double bound = factor * (std::abs(x.plane(c)[i]) + std::sqrt(m2)) + 1e-30;
                const double diff = std::abs(double(x.plane(c)[i]) - double(y.plane(c)[i]));
                r.worstRatio = std::max(r.worstRatio, diff / bound);
                if (m2 > 0.0) {
                    ++r.values;
                    r.beyond += diff > bound ? 1 : 0;
                }
            }
    }
    return r;
}

bool mpiUsable() {
#if GDPT_TEST_MPI
    return test::runShell("mpirun --version").output.find("Open MPI") != std::string::npos;
#else
    return false;
#endif
}

// mpirun of Open MPI as the tests run it: as root if need be (CI runs as root), more ranks
// than cores allowed.
std::string mpiLauncher(int ranks, const std::string& env = "") {
    return "env OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 "
           "OMPI_MCA_rmaps_base_oversubscribe=1 " +
           env + " mpirun -n " + std::to_string(ranks) + " ";
}
std::string mpirun(int ranks, const std::string& env = "") {
    return mpiLauncher(ranks, env) + test::gdptBinary() + " ";
}

class DistributedCli : public test::TempDirTest, public ::testing::WithParamInterface<std::string> {
protected:
    [[nodiscard]] std::string render(const std::string& extra, int seed = 3) const {
        return "render " + kScene + " --width 24 --height 16 --spp " + std::to_string(kSpp) + " --method " +
               GetParam() + " --seed " + std::to_string(seed) + " --quiet --validate " + extra;
    }
    void renderShards(int parts, const std::string& prefix) const {
        for (int i = 0; i < parts; ++i) {
            const RunResult r =
                test::runGdpt(render("--shard " + std::to_string(i) + "/" + std::to_string(parts) + " -o " +
                                     path(prefix + std::to_string(i) + ".exr")));
            ASSERT_EQ(r.code, 0) << r.output;
        }
    }
};

TEST_P(DistributedCli, ShardsMergedInAnyOrderEqualOneProcessUpToRounding) {
    RunResult r = test::runGdpt(render("-o " + path("one.exr")));
    ASSERT_EQ(r.code, 0) << r.output;
    renderShards(3, "s");
    r = test::runGdpt("merge " + path("s2.exr") + " " + path("s0.exr") + " " + path("s1.exr") + " -o " +
                      path("m1.exr") + " --quiet --validate");
    ASSERT_EQ(r.code, 0) << r.output;
    r = test::runGdpt("merge " + path("s1.exr") + " " + path("s2.exr") + " " + path("s0.exr") + " -o " +
                      path("m2.exr") + " --quiet --validate --json " + path("m2.json"));
    ASSERT_EQ(r.code, 0) << r.output;
    test::expectSameExrLayers(path("m1.exr"), path("m2.exr"));
    EXPECT_NE(test::readText(path("m2.json")).find("\"parts\": 3"), std::string::npos);

    const BoundCheck same = roundingBound(path("m1.exr"), path("one.exr"), GetParam());
    EXPECT_GT(same.values, 500u);
    EXPECT_EQ(same.beyond, 0u) << "worst |difference| / bound " << same.worstRatio;
    // The final image: G-PT's reconstruction from statistics that differ by rounding.
    const auto merged = readExr(path("m1.exr")), one = readExr(path("one.exr"));
    const Image &x = layer(merged, ""), &y = layer(one, "");
    for (int c = 0; c < 3; ++c)
        for (std::size_t i = 0; i < x.pixelCount(); ++i)
            EXPECT_NEAR(x.plane(c)[i], y.plane(c)[i], 1e-4 * (1.0 + std::abs(y.plane(c)[i])))
                << "pixel " << i;

    // Power: other samples of the same pixels (another seed) break the bound almost everywhere.
    r = test::runGdpt(render("-o " + path("other.exr"), /*seed=*/4));
    ASSERT_EQ(r.code, 0) << r.output;
    const BoundCheck other = roundingBound(path("other.exr"), path("one.exr"), GetParam());
    EXPECT_GT(other.beyond, other.values * 9 / 10) << other.beyond << " of " << other.values;
}

TEST_P(DistributedCli, MpiRanksEqualTheMergeOfAsManyShards) {
    if (!mpiUsable()) GTEST_SKIP() << "gdpt was built without MPI, or mpirun is not Open MPI's";
    for (int ranks : {2, 3}) {
        const std::string n = std::to_string(ranks);
        renderShards(ranks, "shard" + n + "_");
        std::string shards;
        for (int i = 0; i < ranks; ++i) shards += " " + path("shard" + n + "_" + std::to_string(i) + ".exr");
        RunResult r = test::runGdpt("merge" + shards + " -o " + path("merged" + n + ".exr") + " --quiet");
        ASSERT_EQ(r.code, 0) << r.output;
        r = test::runShell(mpirun(ranks) +
                           render("-o " + path("mpi" + n + ".exr") + " --json " + path("mpi" + n + ".json")));
        ASSERT_EQ(r.code, 0) << r.output;
        test::expectSameExrLayers(path("mpi" + n + ".exr"), path("merged" + n + ".exr"));
        const std::string json = test::readText(path("mpi" + n + ".json"));
        EXPECT_NE(json.find("\"parts\": " + n), std::string::npos) << json;
        EXPECT_NE(json.find("\"spp\": " + std::to_string(kSpp)), std::string::npos) << json;
    }
}

INSTANTIATE_TEST_SUITE_P(Methods, DistributedCli, ::testing::Values("pt", "gpt"));

class DistributedRuns : public test::TempDirTest {
protected:
    [[nodiscard]] static std::string render(const std::string& extra) {
        return "render " + kScene + " --width 24 --height 16 --spp 4 --quiet " + extra;
    }
    // Nothing was written: no output and no temporary file.
    void expectNoOutput() const {
        for (const std::string& name : listing()) ADD_FAILURE() << "left behind: " << name;
    }
};

TEST_F(DistributedRuns, ARankThatFailsOrDiesEndsTheRunWithNoOutput) {
    if (!mpiUsable()) GTEST_SKIP() << "gdpt was built without MPI, or mpirun is not Open MPI's";
    const std::string out = " -o " + path("out.exr") + " --json " + path("out.json");
    RunResult r = test::runShell(mpirun(3, "GDPT_TEST_RANK_FAULT=2:sampling") + render(out));
    EXPECT_NE(r.code, 0);
    EXPECT_NE(r.output.find("rank 2 failed: simulated failure while sampling"), std::string::npos)
        << r.output;
    expectNoOutput();
    r = test::runShell(mpirun(2, "GDPT_TEST_RANK_FAULT=1:loading") + render(out));
    EXPECT_NE(r.code, 0);
    EXPECT_NE(r.output.find("rank 1 failed before sampling"), std::string::npos) << r.output;
    expectNoOutput();
    r = test::runShell(mpirun(2, "GDPT_TEST_RANK_FAULT=1:killed") + render(out));
    EXPECT_NE(r.code, 0) << r.output;
    expectNoOutput();
}

TEST_F(DistributedRuns, RanksThatWouldRenderDifferentImagesAreRefusedBeforeSampling) {
    if (!mpiUsable()) GTEST_SKIP() << "gdpt was built without MPI, or mpirun is not Open MPI's";
    // Each rank its own seed: the shell expands the rank Open MPI gives it.
    const RunResult r = test::runShell(mpiLauncher(2) + "sh -c 'exec " + test::gdptBinary() + " " +
                                       render("-o " + path("out.exr")) + " --seed $OMPI_COMM_WORLD_RANK'");
    EXPECT_NE(r.code, 0);
    EXPECT_NE(r.output.find("rank 1 would render another image than rank 0: seed 1 (rank 0: 0)"),
              std::string::npos)
        << r.output;
    expectNoOutput();
}

// --time: every part samples for the budget, and the merge counts what each took.
TEST_F(DistributedRuns, TimedPartsSampleForTheBudgetAndTheMergeCountsWhatEachTook) {
    const auto partSpp = [](const std::string& json) {
        const nlohmann::json j = nlohmann::json::parse(json);
        return std::make_pair(j.at("spp").get<std::uint32_t>(),
                              j.at("distributed").at("part_spp").get<std::vector<std::uint32_t>>());
    };
    const std::string timed = "render " + kScene + " --width 24 --height 16 --method pt --quiet --time 1 ";
    for (int i : {0, 1}) {
        const RunResult r = test::runGdpt(timed + "--shard " + std::to_string(i) + "/2 -o " +
                                          path("t" + std::to_string(i) + ".exr"));
        ASSERT_EQ(r.code, 0) << r.output;
    }
    RunResult r = test::runGdpt("merge " + path("t1.exr") + " " + path("t0.exr") + " --quiet -o " +
                                path("m.exr") + " --json " + path("m.json"));
    ASSERT_EQ(r.code, 0) << r.output;
    auto [spp, parts] = partSpp(test::readText(path("m.json")));
    ASSERT_EQ(parts.size(), 2u);
    EXPECT_GE(parts[0], 1u);
    EXPECT_GE(parts[1], 1u);
    EXPECT_EQ(spp, parts[0] + parts[1]);
    if (!mpiUsable()) GTEST_SKIP() << "gdpt was built without MPI, or mpirun is not Open MPI's";
    r = test::runShell(mpirun(2) + timed + "-o " + path("mpi.exr") + " --json " + path("mpi.json"));
    ASSERT_EQ(r.code, 0) << r.output;
    std::tie(spp, parts) = partSpp(test::readText(path("mpi.json")));
    ASSERT_EQ(parts.size(), 2u);
    EXPECT_GE(parts[0], 1u);
    EXPECT_GE(parts[1], 1u);
    EXPECT_EQ(spp, parts[0] + parts[1]);
}

TEST_F(DistributedRuns, BadShardsAndSplitsAreRefusedByName) {
    for (int i : {0, 2}) {
        const RunResult r = test::runGdpt(render("--method pt --shard " + std::to_string(i) + "/3 -o " +
                                                 path("s" + std::to_string(i) + ".exr")));
        ASSERT_EQ(r.code, 0) << r.output;
    }
    RunResult r = test::runGdpt("merge " + path("s0.exr") + " " + path("s2.exr") + " -o " + path("out.exr"));
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.output.find("1 of the 3 parts are missing: 1/3"), std::string::npos) << r.output;
    r = test::runGdpt(render("--method pt --seed 9 --shard 1/3 -o " + path("foreign.exr")));
    ASSERT_EQ(r.code, 0) << r.output;
    r = test::runGdpt("merge " + path("s0.exr") + " " + path("foreign.exr") + " " + path("s2.exr") + " -o " +
                      path("out.exr"));
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.output.find("foreign.exr belongs to another render than"), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(path("out.exr")));
    // Usage: a malformed part, more parts than samples.
    r = test::runGdpt(render("--shard 3/3 -o " + path("x.exr")));
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.output.find("parts are numbered 0 to 2"), std::string::npos) << r.output;
    r = test::runGdpt(render("--shard 0/5 -o " + path("x.exr")));
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.output.find("--spp 4 cannot be split into 5 parts"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace gdpt
