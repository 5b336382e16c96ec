// budget_report.h — how a timed render (render --time) spent its budget: what it cost before
// the first sample (loading, upload, the kernels' compile), its first batch of one sample per
// pixel (the least an image takes), what it reserved for the stages after sampling (at the
// load it measured), and whether those fixed costs alone exceeded the budget. When they do the
// render samples that minimum and ends as early as it can; it says so in one line and in
// --json, as it says any overrun of more than the tolerance.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "integrator/render_options.h"

namespace gdpt {

// A timed render may end this much after its budget (relative) without a note.
inline constexpr double kBudgetTolerance = 0.10;

struct BudgetReport {
    double budget = 0.0;         // --time, seconds
    double total = 0.0;          // the render's wall time, seconds
    double setup = 0.0;          // time before the first sample (stats.setupSeconds)
    double compile = 0.0;        // of setup: the main kernels' first dispatch
    double firstBatch = 0.0;     // the first batch (PT, G-PT: one sample per pixel; MLT: one step)
    double reserved = 0.0;       // reserved after sampling, at the load of the last batch
    double afterSampling = 0.0;  // what the stages after sampling took
    bool fixedExceeded = false;  // fixed() >= budget, and the render sampled that minimum

    // What every render of the scene pays: the set-up, the first batch, the stages after.
    [[nodiscard]] double fixed() const { return setup + firstBatch + reserved; }
    [[nodiscard]] double overrun() const { return budget > 0.0 ? total / budget - 1.0 : 0.0; }
};

// `reserved`: the seconds reserved after sampling as measured (scaled here by
// stats.reserveScale); `afterSampling`: what followed the batch loop.
BudgetReport budgetReport(double budget, const RenderStats& stats, double total, double reserved,
                          double afterSampling);

// --json's "budget" object.
nlohmann::json budgetJson(const BudgetReport& r, const RenderStats& stats);

// The line a render prints about its budget, if any: the fixed costs exceeded it, or the
// render ended more than kBudgetTolerance after it (with where the time went).
std::optional<std::string> budgetNote(const BudgetReport& r, const RenderStats& stats);

}  // namespace gdpt
