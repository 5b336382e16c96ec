// reconstruction_stage.h — the screened Poisson stage that the gradient-domain methods share
// (G-PT, gmlt): the solver for the device and image size (made once, its pipelines compiled
// once), the time a timed render reserves for it, the solves themselves with progress,
// cancellation and their report, and the report's JSON.
#pragma once

#include <memory>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>
#include <vector>

#include "image/exr_io.h"
#include "integrator/render_options.h"
#include "poisson/poisson_gpu.h"

namespace gdpt {

namespace vk {
class Context;
}
class ReconTimeCache;

class ReconstructionStage {
public:
    // The reconstructions in order (the first gives the final image), with the primal weight
    // alpha, the relative residual at which each solve stops, and the cells of the coarse grid
    // at which the biased ones are debiased against the primal (poisson/debias.h; 0 = not).
    // `solver`: the linear solver of every solve, or nullopt for the device's default
    // (resolveSolver, poisson_gpu.h).
    ReconstructionStage(std::vector<Reconstruction> reconstructions, double alpha, double tolerance,
                        int debiasCells = 0, std::optional<GpuSolver> solver = std::nullopt);
    ~ReconstructionStage();

    [[nodiscard]] const std::vector<SolveOptions>& solves() const { return solves_; }
    // The primal weight of every solve from now on. The time reserved stays the one measured
    // or remembered for the constructor's α (G-PT: 0.2, raised by gpt_alpha.h). A larger α's
    // solve converges in fewer iterations (the engine under a sky: 16-17 at 0.8 against 29 at
    // 0.2), so a reservation calibrated at 0.2 errs long; one remembered from a render at a
    // larger α errs short for a render at 0.2, whose IRLS the reconstruction deadline cuts.
    void setAlpha(double alpha);
    // The reconstruction that gives the final image from now on: moved to the front if it is
    // one of the stage's, else in place of the first. The time reserved stays the one for the
    // constructor's reconstructions (G-PT: WL1, which gpt_reconstruction.h may turn into WL2,
    // whose single solve takes about as long); a timed render remembers what the solves took,
    // per scene, for the next one (ReconTimeCache).
    void setFinal(Reconstruction r);
    [[nodiscard]] bool empty() const { return solves_.empty(); }
    // The solver for this device and size (made on first use, kept for later renders so that
    // its pipelines are compiled once).
    PoissonSolverGpu& solver(const vk::Context& ctx, int width, int height);
    // The time a timed render reserves for the solves. With a cache: the remembered time (and
    // load) of this device, size and solves, else one calibration solve per reconstruction
    // (its first dispatches compile the solver's kernels, which takes seconds only when
    // lavapipe's shader cache is cold, when the set-up is long anyway). Without: one warm
    // calibration per stage, raised to the longest reconstruction it has run (the steady
    // state of a benchmark that renders many times).
    ReservedTime reserve(const vk::Context& ctx, int width, int height, const ReconTimeCache* cache);
    // Runs every solve of `input` (after solver() for the input's size): the layers
    // recon_<name> in order; adds each solve's report to stats (and says it unless
    // options.quiet); an interrupt (options.cancel) stops it after the solver's current batch
    // (throws Interrupted). With a cache, remembers the time for reserve().
    std::vector<NamedLayer> run(const PoissonInput& input, const RenderOptions& options, RenderStats& stats,
                                const ReconTimeCache* cache);

private:
    std::vector<SolveOptions> solves_;
    int debiasCells_ = 0;
    std::optional<GpuSolver> solverChoice_;
    std::unique_ptr<PoissonSolverGpu> solver_;
    const vk::Context* solverCtx_ = nullptr;
    int solverWidth_ = 0, solverHeight_ = 0;
    std::string reserveKey_;           // the cache key of the last reservation (with a cache)
    double reservedSeconds_ = 0.0;     // the remembered or calibrated time of that reservation
    double calibratedSeconds_ = -1.0;  // without a cache: the warm calibration (< 0: not yet)
    double longestSeconds_ = 0.0;      // without a cache: the longest reconstruction so far
};

// The reconstruction time a timed render remembers for the next one: what it measured, but
// never less than what it had reserved when a solve was cut at its deadline (`cut`): the cut
// time says only that the full solve takes longer, and remembering it made the next render
// reserve as little, stop again, and stay at one IRLS round for good (bench/RESULTS.md, "The
// reconstruction on the host").
double rememberedReconSeconds(double measured, double reserved, bool cut);

// The reports of a render's reconstructions as `render --json` writes them.
nlohmann::json reconstructionsJson(const RenderStats& stats);

}  // namespace gdpt
