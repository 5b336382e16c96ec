// `gdpt converge` end to end: the results.json schema ("gdpt-converge-1") with one run record
// per method x budget x repeat and the same rows in results.csv, and a tiny convergence study
// in which every method's error falls with time. relMSE itself is tested against hand-computed
// values in tests/unit/image/test_metrics.cpp; here only its use by the command is checked.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "cli_runner.h"

namespace gdpt {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const std::string kScene = std::string(GDPT_SOURCE_DIR) + "/scenes/cornell_box.gltf";

class ConvergeCli : public test::TempDirTest {};

std::vector<std::vector<std::string>> readCsv(const std::string& path) {
    std::vector<std::vector<std::string>> rows;
    std::ifstream in(path);
    std::string line;
    while (std::getline(in, line)) {
        std::vector<std::string> fields;
        std::stringstream fieldsIn(line);
        std::string field;
        while (std::getline(fieldsIn, field, ',')) fields.push_back(field);
        rows.push_back(fields);
    }
    return rows;
}

// The CSV prints numbers with the stream default of 6 significant digits, so a CSV value
// must equal the JSON value to 6 digits: |a - b| <= 5e-6 |b| (+ a tiny absolute floor for 0).
void expectSameNumber(const std::string& csvField, double jsonValue, const std::string& what) {
    const double csvValue = std::stod(csvField);
    EXPECT_NEAR(csvValue, jsonValue, 5e-6 * std::abs(jsonValue) + 1e-300) << what;
}

// Checks DIR/results.json against schema gdpt-converge-1 and DIR/results.csv against it.
void checkResults(const fs::path& dir, const std::vector<std::string>& methods,
                  const std::vector<double>& times, int repeats, int width, int height) {
    std::ifstream in(dir / "results.json");
    ASSERT_TRUE(in) << "no results.json";
    const json j = json::parse(in);

    // Top level: required keys with their types.
    ASSERT_TRUE(j.is_object());
    EXPECT_EQ(j.value("schema", ""), "gdpt-converge-1");
    for (const char* key : {"scene", "reference", "device"})
        EXPECT_TRUE(j.contains(key) && j[key].is_string()) << key;
    for (const char* key : {"width", "height", "repeats"})
        EXPECT_TRUE(j.contains(key) && j[key].is_number_integer()) << key;
    EXPECT_EQ(j["width"], width);
    EXPECT_EQ(j["height"], height);
    EXPECT_EQ(j["repeats"], repeats);
    ASSERT_TRUE(j.contains("methods") && j["methods"].is_array());
    EXPECT_EQ(j["methods"].get<std::vector<std::string>>(), methods);
    ASSERT_TRUE(j.contains("times") && j["times"].is_array());
    EXPECT_EQ(j["times"].get<std::vector<double>>(), times);
    for (const char* key : {"runs", "summary", "equal_time"})
        ASSERT_TRUE(j.contains(key) && j[key].is_array()) << key;
    EXPECT_TRUE(j.contains("target_relmse") && j["target_relmse"].is_number());
    ASSERT_TRUE(j.contains("time_to_target_s") && j["time_to_target_s"].is_object());
    for (const auto& m : methods)
        EXPECT_TRUE(j["time_to_target_s"].contains(m) && j["time_to_target_s"][m].is_number()) << m;

    // Runs: exactly one record per (method, budget, repeat), each with every field.
    const json& runs = j["runs"];
    EXPECT_EQ(runs.size(), methods.size() * times.size() * static_cast<std::size_t>(repeats));
    std::set<std::tuple<std::string, double, int>> seen;
    for (const json& r : runs) {
        ASSERT_TRUE(r.is_object());
        ASSERT_TRUE(r.contains("method") && r["method"].is_string()) << r.dump();
        ASSERT_TRUE(r.contains("repeat") && r["repeat"].is_number_integer()) << r.dump();
        ASSERT_TRUE(r.contains("spp") && r["spp"].is_number_unsigned()) << r.dump();
        // Rows of the partial last pass (one sample more): fewer than the image's rows.
        ASSERT_TRUE(r.contains("partial_pass_rows") && r["partial_pass_rows"].is_number_unsigned())
            << r.dump();
        EXPECT_LT(r["partial_pass_rows"].get<unsigned>(), static_cast<unsigned>(height)) << r.dump();
        for (const char* key : {"budget_s", "seconds", "recon_seconds", "relmse", "mse", "mae", "mean_bias"})
            ASSERT_TRUE(r.contains(key) && r[key].is_number()) << key << " in " << r.dump();
        const auto m = r["method"].get<std::string>();
        const double budget = r["budget_s"];
        const int repeat = r["repeat"];
        EXPECT_NE(std::find(methods.begin(), methods.end(), m), methods.end()) << m;
        EXPECT_NE(std::find(times.begin(), times.end(), budget), times.end()) << budget;
        EXPECT_TRUE(repeat >= 0 && repeat < repeats) << repeat;
        EXPECT_TRUE(seen.insert({m, budget, repeat}).second) << "duplicate run " << r.dump();
        EXPECT_GE(r["spp"].get<unsigned>(), 1u);
        EXPECT_GT(r["seconds"].get<double>(), 0.0);
        EXPECT_GE(r["relmse"].get<double>(), 0.0);
        EXPECT_GE(r["mse"].get<double>(), 0.0);
        EXPECT_GE(r["mae"].get<double>(), 0.0);
        EXPECT_EQ(r["recon_seconds"].get<double>() > 0.0, m != "pt")
            << "only G-PT reconstructs: " << r.dump();
    }

    // Summary: one entry per (method, budget), bracketing its runs' errors.
    const json& summary = j["summary"];
    EXPECT_EQ(summary.size(), methods.size() * times.size());
    for (const json& s : summary) {
        for (const char* key : {"budget_s", "seconds_median", "spp_median", "relmse_median", "relmse_min",
                                "relmse_max", "mse_median", "bias_median"})
            ASSERT_TRUE(s.contains(key) && s[key].is_number()) << key << " in " << s.dump();
        EXPECT_LE(s["relmse_min"].get<double>(), s["relmse_median"].get<double>());
        EXPECT_LE(s["relmse_median"].get<double>(), s["relmse_max"].get<double>());
        double lo = INFINITY, hi = -INFINITY;
        for (const json& r : runs)
            if (r["method"] == s["method"] && r["budget_s"] == s["budget_s"]) {
                lo = std::min(lo, r["relmse"].get<double>());
                hi = std::max(hi, r["relmse"].get<double>());
            }
        EXPECT_EQ(s["relmse_min"].get<double>(), lo) << s.dump();
        EXPECT_EQ(s["relmse_max"].get<double>(), hi) << s.dump();
    }
    EXPECT_EQ(j["equal_time"].size(), times.size());

    // CSV: the header, then the JSON runs in the same order with the same values.
    const auto rows = readCsv((dir / "results.csv").string());
    ASSERT_EQ(rows.size(), runs.size() + 1);
    const std::vector<std::string> header = {
        "method", "budget_s", "repeat", "seconds",  "recon_seconds", "spp", "partial_pass_rows",
        "relmse", "mse",      "mae",    "mean_bias"};
    ASSERT_EQ(rows[0], header);
    for (std::size_t i = 0; i < runs.size(); ++i) {
        const auto& row = rows[i + 1];
        const json& r = runs[i];
        ASSERT_EQ(row.size(), header.size()) << "csv row " << i + 1;
        EXPECT_EQ(row[0], r["method"].get<std::string>()) << "csv row " << i + 1;
        EXPECT_EQ(std::stoi(row[2]), r["repeat"].get<int>()) << "csv row " << i + 1;
        EXPECT_EQ(std::stoul(row[5]), r["spp"].get<unsigned long>()) << "csv row " << i + 1;
        EXPECT_EQ(std::stoul(row[6]), r["partial_pass_rows"].get<unsigned long>()) << "csv row " << i + 1;
        for (std::size_t k : {1u, 3u, 4u, 7u, 8u, 9u, 10u})
            expectSameNumber(row[k], r[header[k]].get<double>(),
                             "csv row " + std::to_string(i + 1) + " " + header[k]);
    }
}

// A minimal study with two methods, two budgets and two repeats (so that the repeat index
// is exercised) on an 8x8 image: only the file formats are under test here.
TEST_F(ConvergeCli, ResultsJsonFollowsTheSchemaAndMatchesTheCsv) {
    const test::RunResult r = test::runGdpt("converge " + kScene +
                                            " --make-reference 64 --width 8 --height 8 --methods pt,gpt-l2 "
                                            "--times 0.05,0.1 --repeats 2 --validate -o " +
                                            path("out"));
    ASSERT_EQ(r.code, 0) << r.output;
    checkResults(dir_ / "out", {"pt", "gpt-l2"}, {0.05, 0.1}, 2, 8, 8);
    EXPECT_TRUE(fs::exists(dir_ / "out" / "error_vs_time.dat"));
    EXPECT_TRUE(temporaryFiles("out").empty());
}

// Why the error must fall between the two budgets, for every method.
//
// Each run uses its own fixed seed (1, 2, ... in method/budget order), so a run's image is
// a deterministic function of the spp it reached; only that spp depends on timing. For an
// unbiased estimator (PT; G-PT with L2 reconstruction) the expected relMSE against an
// independent reference is c/n + c_ref, where n is the spp and c_ref the reference's own
// noise (1024 spp here). L1 and weighted-L2 reconstructions are biased but consistent, and
// at these sample counts their error falls at least as fast (their bias is far below the
// noise of a few hundred spp).
//
// The budgets differ by 8x (0.25 s vs 2 s), and the per-run fixed costs (scene upload,
// pipeline creation, counted in the budget) make the sampling time differ by more. So the
// test first requires spp(2 s) >= 2 spp(0.25 s): that fails only if the machine became
// about 4x slower between two runs a few seconds apart, and it is reported as such.
// Given n2 >= 2 n1 and n1 >= 1, the expected ratio relMSE(2 s)/relMSE(0.25 s) is
// (1/n2 + 1/nr)/(1/n1 + 1/nr) <= 0.5 + 0.5 n1/nr; measured n1 is ~35 spp for PT and 1 for
// G-PT (its first batch overruns 0.25 s), so <= 0.52. The relMSE of a 32x32 image averages
// ~1000 independent pixels, each a squared error with relative spread ~sqrt(2), so each
// relMSE is known to ~sqrt(2/1000) = 4.5% and the ratio to ~6.5%; requiring a ratio below
// 0.8 leaves more than 4 standard errors above the worst expected 0.52. Measured on two
// loaded cores (relMSE, spp at 0.25 s -> 2 s): PT 0.087 (32) -> 0.010 (379), G-PT L1 49 (1)
// -> 0.012 (94), L2 0.52 (1) -> 0.011 (83), wL2 0.47 (1) -> 0.0095 (86).
TEST_F(ConvergeCli, ErrorFallsWithTimeForEveryMethod) {
    const std::vector<std::string> methods = {"pt", "gpt-l1", "gpt-l2", "gpt-wl2", "gpt-wl1"};
    // The spp condition is a precondition of the comparison, not the property under test: one
    // stall of the shared machine (seen twice in full parallel runs: a G-PT 2 s run at 1 spp,
    // its budget taken by a reconstruction reserve raised by a stalled earlier run) voids it.
    // Then the whole benchmark runs once more, and the second attempt is judged.
    std::map<std::pair<std::string, double>, json> byRun;
    for (int attempt = 0; attempt < 2; ++attempt) {
        const std::string out = path("out" + std::to_string(attempt));
        const test::RunResult r =
            test::runGdpt("converge " + kScene +
                          " --make-reference 1024 --width 32 --height 32 "
                          "--methods pt,gpt-l1,gpt-l2,gpt-wl2,gpt-wl1 --times 0.25,2 --repeats 1 "
                          "--validate -o " +
                          out);
        ASSERT_EQ(r.code, 0) << r.output;
        checkResults(fs::path(out), methods, {0.25, 2.0}, 1, 32, 32);
        if (HasFatalFailure()) return;
        std::ifstream in(fs::path(out) / "results.json");
        const json j = json::parse(in);
        byRun.clear();
        for (const json& run : j["runs"])
            byRun[{run["method"].get<std::string>(), run["budget_s"].get<double>()}] = run;
        bool valid = true;
        for (const auto& m : methods)
            valid = valid && byRun.at({m, 2.0})["spp"].get<unsigned>() >=
                                 2 * byRun.at({m, 0.25})["spp"].get<unsigned>();
        if (valid) break;
    }
    for (const auto& m : methods) {
        const json& shortRun = byRun.at({m, 0.25});
        const json& longRun = byRun.at({m, 2.0});
        const unsigned n1 = shortRun["spp"], n2 = longRun["spp"];
        ASSERT_GE(n2, 2 * n1) << m << ": the 2 s run reached " << n2 << " spp, the 0.25 s run " << n1
                              << " (in both attempts): the machine slowed down ~4x between runs, the error "
                                 "comparison is void";
        const double e1 = shortRun["relmse"], e2 = longRun["relmse"];
        EXPECT_LT(e2, 0.8 * e1) << m << ": relMSE " << e1 << " at " << n1 << " spp, " << e2 << " at " << n2
                                << " spp";
    }
}

// --env lights the runs and the made reference alike, as gdpt render's --env lights a render.
// The Cornell box's open side lets the environment in: with --env 0.5 its 16x16 image's mean is
// about 0.227 against 0.120 without. Against a reference rendered with --env 0.5, every run with
// the same --env has a mean bias within its noise (measured: the mean of a 1-spp 16x16 render
// spreads by a standard deviation of about 0.014 over seeds, for PT and G-PT alike, and the runs
// here take at least 1 spp), so |bias| < 0.05 is more than 3.5 standard deviations; runs without
// it miss the environment's light (bias about -0.107, 7.6 standard deviations below 0), so
// bias < -0.05 separates the two with the same margin. A reference that converge makes is
// cached under a key that includes the environment: the two made here are two files.
TEST_F(ConvergeCli, EnvironmentLightsTheRunsAndTheMadeReference) {
    const std::string size = " --width 16 --height 16";
    const std::string ref = path("ref.exr");
    const test::RunResult made =
        test::runGdpt("render " + kScene + " --env 0.5 --spp 1024" + size + " --quiet -o " + ref);
    ASSERT_EQ(made.code, 0) << made.output;
    const auto biases = [&](const std::string& env, double envValue, const std::string& out) {
        const test::RunResult r =
            test::runGdpt("converge " + kScene + env + " --reference " + ref + size +
                          " --methods pt,gpt --times 0.5 --repeats 1 --validate -o " + path(out));
        EXPECT_EQ(r.code, 0) << r.output;
        std::map<std::string, double> bias;
        std::ifstream in(fs::path(path(out)) / "results.json");
        if (!in) return bias;
        const json j = json::parse(in);
        EXPECT_EQ(j.value("env", json()), json::array({envValue, envValue, envValue})) << env;
        for (const json& run : j["runs"])
            bias[run["method"].get<std::string>()] = run["mean_bias"].get<double>();
        return bias;
    };
    const std::map<std::string, double> lit = biases(" --env 0.5", 0.5, "lit");
    ASSERT_EQ(lit.size(), 2u);
    for (const auto& [method, bias] : lit) EXPECT_LT(std::abs(bias), 0.05) << method << " with --env";
    const std::map<std::string, double> unlit = biases("", 0.0, "unlit");
    ASSERT_EQ(unlit.size(), 2u);
    for (const auto& [method, bias] : unlit) EXPECT_LT(bias, -0.05) << method << " without --env";

    for (const std::string env : {" --env 0.5", ""}) {
        const test::RunResult r = test::runGdpt("converge " + kScene + env + " --make-reference 16" + size +
                                                " --methods pt --times 0.05 --repeats 1 -o " + path("made"));
        ASSERT_EQ(r.code, 0) << r.output;
    }
    int references = 0;
    for (const std::string& name : listing("made")) references += name.rfind("reference_", 0) == 0 ? 1 : 0;
    EXPECT_EQ(references, 2);
}

}  // namespace
}  // namespace gdpt
