#include "integrator/reconstruction_stage.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "integrator/recon_reserve.h"
#include "poisson/debias.h"
#include "util/interrupt.h"
#include "util/timer.h"

namespace gdpt {

double rememberedReconSeconds(double measured, double reserved, bool cut) {
    return cut ? std::max(measured, reserved) : measured;
}

ReconstructionStage::ReconstructionStage(std::vector<Reconstruction> reconstructions, double alpha,
                                         double tolerance, int debiasCells, std::optional<GpuSolver> solver)
    : debiasCells_(debiasCells), solverChoice_(solver) {
    for (Reconstruction r : reconstructions) {
        SolveOptions so;
        so.method = r;
        so.alpha = alpha;
        so.tolerance = tolerance;
        solves_.push_back(so);
    }
}

ReconstructionStage::~ReconstructionStage() = default;

void ReconstructionStage::setAlpha(double alpha) {
    for (SolveOptions& so : solves_) so.alpha = alpha;
}

void ReconstructionStage::setFinal(Reconstruction r) {
    if (solves_.empty() || solves_.front().method == r) return;
    const auto it =
        std::find_if(solves_.begin(), solves_.end(), [r](const SolveOptions& so) { return so.method == r; });
    if (it == solves_.end()) {
        solves_.front().method = r;
        return;
    }
    std::rotate(solves_.begin(), it, it + 1);
}

PoissonSolverGpu& ReconstructionStage::solver(const vk::Context& ctx, int width, int height) {
    if (!solver_ || solverCtx_ != &ctx || solverWidth_ != width || solverHeight_ != height) {
        solver_ = std::make_unique<PoissonSolverGpu>(ctx, width, height);
        for (SolveOptions& so : solves_) so.solver = resolveSolver(solverChoice_, ctx);
        solverCtx_ = &ctx;
        solverWidth_ = width;
        solverHeight_ = height;
        calibratedSeconds_ = -1.0;
        longestSeconds_ = 0.0;
    }
    return *solver_;
}

ReservedTime ReconstructionStage::reserve(const vk::Context& ctx, int width, int height,
                                          const ReconTimeCache* cache) {
    if (solves_.empty()) return {};
    PoissonSolverGpu& solverGpu = solver(ctx, width, height);  // first: a new solver resets the calibration
    if (cache) {
        const ReconReservation r = reserveReconstruction(ctx, solverGpu, solves_, *cache);
        reserveKey_ = r.key;
        reservedSeconds_ = r.time.seconds;
        return r.time;
    }
    if (calibratedSeconds_ < 0.0) {
        calibratedSeconds_ = 0.0;
        for (const SolveOptions& so : solves_)
            calibratedSeconds_ += calibrateReconSeconds(solverGpu, so, true);
    }
    return {std::max(calibratedSeconds_, longestSeconds_), 0.0};
}

std::vector<NamedLayer> ReconstructionStage::run(const PoissonInput& input, const RenderOptions& options,
                                                 RenderStats& stats, const ReconTimeCache* cache) {
    std::vector<NamedLayer> recons;
    if (solves_.empty()) return recons;
    Timer reconTimer;
    bool cut = false;  // a solve stopped at its deadline
    enterPhase("reconstruction");
    // An interrupt stops the reconstruction after the solver's current batch of iterations.
    const auto stopIfCancelled = [&options] {
        if (options.cancel && options.cancel->load()) throw Interrupted("reconstructing");
    };
    for (SolveOptions so : solves_) {
        stopIfCancelled();
        so.progress = [&](int, int, int) { stopIfCancelled(); };
        // The output's reservation, remembered as everything after sampling but the solves,
        // includes the readback, which ran before them: it is not the solves' to lose.
        so.deadline = options.reconstructionDeadline;
        if (so.deadline)
            *so.deadline += std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                std::chrono::duration<double, std::milli>(stats.readbackMs));
        Image recon;
        const SolveReport report = solver_->solve(input, so, recon);
        ReconstructionStats rs{
            toString(so.method), report.iterations, report.irlsIterations, report.residual, so.tolerance,
            report.converged,    report.ms};
        rs.stoppedAtDeadline = report.stoppedAtDeadline;
        rs.solver = toString(so.solver);
        rs.alpha = so.alpha;
        std::string debiased;
        if (debiases(so.method, debiasCells_)) {
            // The coarse scales from the primal (poisson/debias.h): a few ms on the host.
            Timer debiasTimer;
            const DebiasReport d = debiasImage(recon, *input.primal, debiasCells_);
            rs.debiasScale = d.scale;
            rs.debiasMeanChange = d.relativeMeanChange();
            rs.debiasMs = debiasTimer.ms();
            rs.ms += rs.debiasMs;
            debiased = ", " + describeDebias(d);
        }
        // Not converged (the iteration cap, or a tolerance below what float32 residuals
        // reach) is said as `gdpt solve` says it, and recorded for the JSON summary.
        if (!options.quiet) {
            const std::string scaled =
                report.scaleExponent ? ", inputs scaled by 2^-" + std::to_string(report.scaleExponent) : "";
            const std::string stopped =
                report.stoppedAtDeadline
                    ? " of " + std::to_string(so.irlsIterations) + ", stopped for the budget"
                    : "";
            std::fprintf(stderr,
                         "gdpt: %s reconstruction (%s, alpha %g): %d iterations (%d IRLS%s), residual "
                         "%.2g%s%s, %.1f ms%s\n",
                         toString(so.method), toString(so.solver), so.alpha, report.iterations,
                         report.irlsIterations, stopped.c_str(), report.residual,
                         report.converged ? "" : " NOT converged", scaled.c_str(), rs.ms, debiased.c_str());
        }
        cut = cut || rs.stoppedAtDeadline;
        stats.reconstructions.push_back(rs);
        stats.reconstructionMs += rs.ms;
        recons.push_back({std::string("recon_") + toString(so.method), std::move(recon)});
    }
    if (cache && !reserveKey_.empty())
        cache->put(reserveKey_, {rememberedReconSeconds(stats.reconstructionMs * 1e-3, reservedSeconds_, cut),
                                 stats.samplingLoad});
    longestSeconds_ = std::max(longestSeconds_, reconTimer.seconds());
    return recons;
}

nlohmann::json reconstructionsJson(const RenderStats& s) {
    nlohmann::json recons = nlohmann::json::array();
    for (const ReconstructionStats& r : s.reconstructions)
        recons.push_back({{"method", r.method},
                          {"iterations", r.iterations},
                          {"irls_iterations", r.irlsIterations},
                          {"residual", r.residual},
                          {"tolerance", r.tolerance},
                          {"alpha", r.alpha},
                          {"converged", r.converged},
                          {"debias_scale_px", r.debiasScale},
                          {"debias_mean_change", r.debiasMeanChange},
                          {"debias_ms", r.debiasMs},
                          {"stopped_at_deadline", r.stoppedAtDeadline},
                          {"solver", r.solver},
                          {"ms", r.ms}});
    return recons;
}

}  // namespace gdpt
