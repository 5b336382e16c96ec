#include "integrator/budget_report.h"

#include <cstdio>

namespace gdpt {

BudgetReport budgetReport(double budget, const RenderStats& stats, double total, double reserved,
                          double afterSampling) {
    BudgetReport r;
    r.budget = budget;
    r.total = total;
    r.setup = stats.setupSeconds;
    r.compile = stats.compileMs * 1e-3;
    r.firstBatch = stats.firstBatchSeconds;
    r.reserved = reserved * stats.reserveScale;
    r.afterSampling = afterSampling;
    // Only a render that stopped at the minimum: a later rise of the reservation (the load grew)
    // is an overrun, not the fixed costs.
    r.fixedExceeded = budget > 0.0 && r.fixed() >= budget && stats.spp <= 1 && stats.partialPassRows == 0;
    return r;
}

nlohmann::json budgetJson(const BudgetReport& r, const RenderStats& stats) {
    return {{"seconds", r.budget},
            {"total_s", r.total},
            {"overrun", r.overrun()},
            {"setup_s", r.setup},
            {"kernel_compile_s", r.compile},
            {"first_batch_s", r.firstBatch},
            {"reserved_after_sampling_s", r.reserved},
            {"after_sampling_s", r.afterSampling},
            {"reserve_scale", stats.reserveScale},
            {"load_factor", stats.samplingLoad},
            {"fixed_s", r.fixed()},
            {"fixed_exceeded", r.fixedExceeded}};
}

std::optional<std::string> budgetNote(const BudgetReport& r, const RenderStats& stats) {
    char line[512];
    if (r.fixedExceeded) {
        std::snprintf(line, sizeof line,
                      "--time %g: the fixed costs alone take %.2f s (set-up %.2f s, of which the kernels' "
                      "compile %.2f s; the first batch %.2f s; %.2f s after sampling), more than the "
                      "budget: sampled the minimum, %u spp, and ended at %.2f s",
                      r.budget, r.fixed(), r.setup, r.compile, r.firstBatch, r.reserved, stats.spp, r.total);
        return std::string(line);
    }
    if (r.overrun() <= kBudgetTolerance) return std::nullopt;
    std::snprintf(line, sizeof line,
                  "--time %g: ended at %.2f s, %.0f %% over (set-up %.2f s, sampling %.2f s, after sampling "
                  "%.2f s against %.2f s reserved; load factor %.2f)",
                  r.budget, r.total, 100.0 * r.overrun(), r.setup, stats.samplingMs * 1e-3, r.afterSampling,
                  r.reserved, stats.samplingLoad);
    return std::string(line);
}

}  // namespace gdpt
