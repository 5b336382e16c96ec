// The decisions of a timed render, without a device or a clock: the next batch from the time
// left (sampling_loop.h), the reservations after sampling at another load, the budget's
// report and note (budget_report.h) and the remembered times (recon_reserve.h), each against
// values worked out by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "integrator/budget_report.h"
#include "integrator/recon_reserve.h"
#include "integrator/reconstruction_stage.h"
#include "integrator/sampling_loop.h"
#include "temp_dir.h"

namespace gdpt {
namespace {

// Whole samples for at most half the time left, never more than the schedule's next batch,
// at least one while one fits; then a partial pass (its own 10 % margin); then stop.
TEST(TimedBatch, TakesAtMostHalfOfTheTimeLeft) {
    const TimedBatch half = nextTimedBatch(10.0, 1.0, 8, true, 100);
    EXPECT_EQ(half.spp, 5u);
    EXPECT_EQ(half.rows, 100u);
    EXPECT_EQ(nextTimedBatch(10.0, 1.0, 2, true, 100).spp, 2u) << "the schedule's batch when smaller";
    EXPECT_EQ(nextTimedBatch(3.9, 1.0, 16, true, 100).spp, 1u);
    EXPECT_EQ(nextTimedBatch(1.5, 1.0, 16, true, 100).spp, 1u) << "one whole sample while one fits";
    const TimedBatch partial = nextTimedBatch(0.5, 1.0, 16, true, 100);
    EXPECT_EQ(partial.spp, 1u);
    EXPECT_EQ(partial.rows, 45u);
    EXPECT_EQ(nextTimedBatch(0.5, 1.0, 16, false, 100).spp, 0u) << "no partial pass: stop";
    EXPECT_EQ(nextTimedBatch(0.0, 1.0, 16, true, 100).spp, 0u);
    EXPECT_EQ(nextTimedBatch(-2.0, 1.0, 16, true, 100).spp, 0u) << "the fixed costs overran: stop";
}

TEST(TimedBatch, ReservationsCarryToTheLoadMeasured) {
    const std::vector<ReservedTime> r = {{1.0, 2.0}, {0.5, 0.0}};
    EXPECT_DOUBLE_EQ(reservedAtLoad(r, 0.0), 1.5) << "no load measured: as remembered";
    EXPECT_DOUBLE_EQ(reservedAtLoad(r, 4.0), 2.5)
        << "twice as busy: the first doubles; the second was measured now";
    EXPECT_DOUBLE_EQ(reservedAtLoad(r, 1.0), 1.0);
    EXPECT_DOUBLE_EQ(reservedAtLoad({}, 3.0), 0.0);
}

RenderStats statsOf(double setup, double compileMs, double reserveScale, std::uint32_t spp) {
    RenderStats s;
    s.setupSeconds = setup;
    s.firstBatchSeconds = 0.25;
    s.compileMs = compileMs;
    s.reserveScale = reserveScale;
    s.spp = spp;
    s.samplingMs = 1000.0;
    s.samplingLoad = 2.0;
    return s;
}

// The fixed costs: the set-up, the first batch (one sample per pixel) and the reservation at
// the last batch's load (0.6 s remembered, scaled by 2).
TEST(BudgetReport, FixedCostsAreTheSetUpTheFirstSampleAndTheReservationAtTheLastLoad) {
    const BudgetReport r = budgetReport(4.0, statsOf(3.0, 2000.0, 2.0, 1), 4.9, 0.6, 0.5);
    EXPECT_DOUBLE_EQ(r.reserved, 1.2);
    EXPECT_DOUBLE_EQ(r.fixed(), 4.45);
    EXPECT_TRUE(r.fixedExceeded);
    EXPECT_NEAR(r.overrun(), 0.225, 1e-12);
    const nlohmann::json j = budgetJson(r, statsOf(3.0, 2000.0, 2.0, 1));
    EXPECT_EQ(j["fixed_exceeded"], true);
    EXPECT_DOUBLE_EQ(j["kernel_compile_s"].get<double>(), 2.0);
    EXPECT_DOUBLE_EQ(j["load_factor"].get<double>(), 2.0);
    EXPECT_DOUBLE_EQ(j["reserve_scale"].get<double>(), 2.0);
    const auto note = budgetNote(r, statsOf(3.0, 2000.0, 2.0, 1));
    ASSERT_TRUE(note.has_value());
    EXPECT_NE(note->find("fixed costs alone take 4.45 s"), std::string::npos) << *note;
    EXPECT_NE(note->find("the first batch 0.25 s"), std::string::npos) << *note;
    EXPECT_NE(note->find("compile 2.00 s"), std::string::npos) << *note;
    EXPECT_NE(note->find("the minimum, 1 spp"), std::string::npos) << *note;
}

TEST(BudgetReport, NoteOnlyBeyondTheTolerance) {
    const RenderStats s = statsOf(1.0, 0.0, 1.0, 12);
    EXPECT_FALSE(budgetReport(1.0, s, 4.0, 0.5, 0.5).fixedExceeded) << "12 spp: not the minimum";
    EXPECT_FALSE(budgetReport(4.0, s, 4.0, 0.5, 0.5).fixedExceeded);
    EXPECT_FALSE(budgetNote(budgetReport(4.0, s, 4.39, 0.5, 0.5), s).has_value()) << "within 10 %";
    const auto over = budgetNote(budgetReport(4.0, s, 4.6, 0.5, 1.1), s);
    ASSERT_TRUE(over.has_value());
    EXPECT_NE(over->find("15 % over"), std::string::npos) << *over;
    EXPECT_NE(over->find("1.10 s against 0.50 s reserved"), std::string::npos) << *over;
}

// The cache holds {"seconds", "load"} per key and still reads the bare seconds that earlier
// versions wrote (load not known); entries of any other form are ignored.
class ReconTimeCacheFile : public test::TempDirTest {};

// A reconstruction cut at its deadline does not lower the remembered time (which made every
// later timed render reserve as little and stop after one round again); a full one sets it.
TEST(ReconstructionTime, ACutSolveDoesNotLowerTheRememberedTime) {
    EXPECT_DOUBLE_EQ(rememberedReconSeconds(0.07, 0.13, true), 0.13);
    EXPECT_DOUBLE_EQ(rememberedReconSeconds(0.20, 0.13, true), 0.20) << "cut, yet longer than reserved";
    EXPECT_DOUBLE_EQ(rememberedReconSeconds(0.07, 0.13, false), 0.07) << "a full solve is what it took";
}

TEST_F(ReconTimeCacheFile, ReadsBothFormsAndWritesTheLoad) {
    const std::string file = path("recon_times.json");
    std::ofstream(file) << R"({"old": 0.25, "new": {"seconds": 0.5, "load": 1.5}, "text": "x",
                              "negative": -1, "no seconds": {"load": 2}})";
    const ReconTimeCache cache(file);
    ASSERT_TRUE(cache.get("old").has_value());
    EXPECT_DOUBLE_EQ(cache.get("old")->seconds, 0.25);
    EXPECT_DOUBLE_EQ(cache.get("old")->load, 0.0);
    ASSERT_TRUE(cache.get("new").has_value());
    EXPECT_DOUBLE_EQ(cache.get("new")->seconds, 0.5);
    EXPECT_DOUBLE_EQ(cache.get("new")->load, 1.5);
    for (const char* bad : {"text", "negative", "no seconds", "missing"}) EXPECT_FALSE(cache.get(bad)) << bad;
    cache.put("old", {0.75, 3.0});
    std::ifstream in(file);
    const nlohmann::json j = nlohmann::json::parse(in);
    EXPECT_DOUBLE_EQ(j["old"]["seconds"].get<double>(), 0.75);
    EXPECT_DOUBLE_EQ(j["old"]["load"].get<double>(), 3.0);
    EXPECT_DOUBLE_EQ(j["new"]["seconds"].get<double>(), 0.5) << "the other entries are kept";
}

// A scoped cache (a scene's) prefers its own entry, falls back to the key's latest entry of any
// scope, and writes both, so another scene's render finds the latest time of the configuration.
TEST_F(ReconTimeCacheFile, AScopePrefersItsOwnEntry) {
    const std::string file = path("recon_times.json");
    const ReconTimeCache door(file, "scene door"), box(file, "scene box");
    door.put("k", {0.9, 1.0});
    ASSERT_TRUE(box.get("k").has_value());
    EXPECT_DOUBLE_EQ(box.get("k")->seconds, 0.9) << "no entry of its own: the latest";
    box.put("k", {0.4, 1.0});
    EXPECT_DOUBLE_EQ(door.get("k")->seconds, 0.9) << "its own entry, not the latest";
    EXPECT_DOUBLE_EQ(box.get("k")->seconds, 0.4);
    EXPECT_DOUBLE_EQ(ReconTimeCache(file).get("k")->seconds, 0.4) << "unscoped: the latest";
}

}  // namespace
}  // namespace gdpt
