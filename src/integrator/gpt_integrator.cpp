#include "integrator/gpt_integrator.h"

#include <algorithm>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>

#include "integrator/render_identity.h"
#include "util/interrupt.h"
#include "util/timer.h"
#include "vk/context.h"

namespace gdpt {

GptIntegrator::GptIntegrator(std::string name, GptOptions options)
    : name_(std::move(name)), options_(std::move(options)) {}

GptIntegrator::~GptIntegrator() = default;

std::uint32_t GptIntegrator::maxBatchSpp(int width, int height) const {
    return maxBatchSppFor(width, height, kGptBatchPixelSamples);
}

ExrAttributes GptIntegrator::identity(const Scene& scene, const RenderOptions& options) const {
    return {{"shift_threshold", exactFloat(options.scene.shiftThreshold)},
            {"edge_samples", std::to_string(options_.sampling.edgeSamples)},
            {"demodulate", demodulates(scene, options_.sampling.demodulate) ? "on" : "off"}};
}

std::vector<SolveOptions> GptIntegrator::solves() const {
    std::vector<SolveOptions> out;
    for (Reconstruction r : options_.reconstructions) {
        SolveOptions so;
        so.method = r;
        so.alpha = options_.alpha;
        so.tolerance = options_.tolerance;
        out.push_back(so);
    }
    return out;
}

PoissonSolverGpu& GptIntegrator::solver(const vk::Context& ctx, int width, int height) {
    if (!solver_ || solverCtx_ != &ctx || solverWidth_ != width || solverHeight_ != height) {
        solver_ = std::make_unique<PoissonSolverGpu>(ctx, width, height);
        solverCtx_ = &ctx;
        solverWidth_ = width;
        solverHeight_ = height;
        calibratedSeconds_ = -1.0;
        longestSeconds_ = 0.0;
    }
    return *solver_;
}

double GptIntegrator::reserveAfterSampling(const vk::Context& ctx, int width, int height) {
    const std::vector<SolveOptions> s = solves();
    if (s.empty()) return 0.0;
    PoissonSolverGpu& solverGpu = solver(ctx, width, height);
    if (options_.reconCache) {
        const ReconReservation r = reserveReconstruction(ctx, solverGpu, s, *options_.reconCache);
        reserveKey_ = r.key;
        return r.seconds;
    }
    if (calibratedSeconds_ < 0.0) {
        calibratedSeconds_ = 0.0;
        for (const SolveOptions& so : s)
            calibratedSeconds_ += calibrateReconSeconds(solverGpu, so, /*warmUp=*/true);
    }
    return std::max(calibratedSeconds_, longestSeconds_);
}

RenderOutput GptIntegrator::render(const vk::Context& ctx, const Scene& scene, const RenderOptions& options) {
    const std::vector<SolveOptions> solveList = solves();
    const int width = options.scene.width, height = options.scene.height;
    // Stage 1, sampling. The reconstruction's pipelines are created while the path kernels
    // compile.
    RenderOptions sampling = options;
    if (!solveList.empty()) {
        // The solver's fields are allocated here, after the sampling pass has checked that the
        // image's per-pixel buffers fit the device (an image too large is refused at once).
        sampling.whileCompiling = [&] {
            if (options.whileCompiling) options.whileCompiling();
            solver(ctx, width, height).preparePipelines(solveList);
        };
    }
    RenderResultGpt g = renderGpt(ctx, scene, sampling, options_.sampling);
    RenderOutput out;
    out.stats = g.stats;
    if (g.stats.cancelled || g.stats.handedOff) return out;

    // Stage 2, the screened Poisson reconstructions of the primal and gradients.
    PoissonInput input;
    input.primal = &g.primal;
    input.dx = &g.dx;
    input.dy = &g.dy;
    input.varPrimal = &g.varPrimal;
    input.varDx = &g.varDx;
    input.varDy = &g.varDy;
    std::vector<NamedLayer> recons;
    Timer reconTimer;
    enterPhase("reconstruction");
    // An interrupt stops the reconstruction after the solver's current batch of iterations.
    const auto stopIfCancelled = [&options] {
        if (options.cancel && options.cancel->load()) throw Interrupted("reconstructing");
    };
    for (SolveOptions so : solveList) {
        stopIfCancelled();
        so.progress = [&](int, int, int) { stopIfCancelled(); };
        Image recon;
        const SolveReport report = solver_->solve(input, so, recon);
        // Not converged (the iteration cap, or a tolerance below what float32 residuals
        // reach) is said as `gdpt solve` says it, and recorded for the JSON summary.
        if (!options.quiet) {
            const std::string scaled =
                report.scaleExponent ? ", inputs scaled by 2^-" + std::to_string(report.scaleExponent) : "";
            std::fprintf(stderr,
                         "gdpt: %s reconstruction: %d iterations (%d IRLS), residual %.2g%s%s, %.1f ms\n",
                         toString(so.method), report.iterations, report.irlsIterations, report.residual,
                         report.converged ? "" : " NOT converged", scaled.c_str(), report.ms);
        }
        out.stats.reconstructions.push_back({toString(so.method), report.iterations, report.irlsIterations,
                                             report.residual, so.tolerance, report.converged, report.ms});
        out.stats.reconstructionMs += report.ms;
        recons.push_back({std::string("recon_") + toString(so.method), std::move(recon)});
    }
    if (!solveList.empty()) {
        if (options_.reconCache && !reserveKey_.empty())
            options_.reconCache->put(reserveKey_, out.stats.reconstructionMs * 1e-3);
        longestSeconds_ = std::max(longestSeconds_, reconTimer.seconds());
    }

    // Stage 3, compose: final = reconstruction (x modulation) + direct (Kettunen et al. 2015,
    // §5: the very-direct light is not reconstructed). Without a reconstruction, the primal.
    out.layers.push_back({"", gptFinal(g, recons.empty() ? g.primal : recons.front().image)});
    for (NamedLayer& r : recons) out.layers.push_back(std::move(r));
    Image primalPlusDirect = gptFinal(g, g.primal);
    const std::vector<NamedLayer> buffers = {{"primal", std::move(g.primal)},
                                             {"dx", std::move(g.dx)},
                                             {"dy", std::move(g.dy)},
                                             {"direct", std::move(g.direct)},
                                             {"var_primal", std::move(g.varPrimal)},
                                             {"var_dx", std::move(g.varDx)},
                                             {"var_dy", std::move(g.varDy)},
                                             {"var_direct", std::move(g.varDirect)},
                                             {"primal_plus_direct", std::move(primalPlusDirect)}};
    out.layers.insert(out.layers.end(), buffers.begin(), buffers.end());
    if (g.stats.demodulated) out.layers.push_back({"modulation", std::move(g.modulation)});
    return out;
}

void GptIntegrator::describe(nlohmann::json& j, const RenderStats& s) const {
    j["gpt_split_bounce"] = s.gptSplitBounce;
    j["edge_samples"] = {{"factor", s.edgeSamples}, {"pixels", s.edgePixels}};
    j["demodulation"] = {{"on", s.demodulated}, {"pixels", s.demodulatedPixels}};
    nlohmann::json recons = nlohmann::json::array();
    for (const ReconstructionStats& r : s.reconstructions)
        recons.push_back({{"method", r.method},
                          {"iterations", r.iterations},
                          {"irls_iterations", r.irlsIterations},
                          {"residual", r.residual},
                          {"tolerance", r.tolerance},
                          {"converged", r.converged},
                          {"ms", r.ms}});
    j["reconstructions"] = recons;
}

std::string GptIntegrator::summary(const RenderStats& s) const {
    std::string text;
    if (s.edgePixels)
        text += ", x" + std::to_string(1 + s.edgeSamples) + " in " + std::to_string(s.edgePixels) +
                " edge pixels";
    if (s.demodulated) text += ", demodulated in " + std::to_string(s.demodulatedPixels) + " pixels";
    return text;
}

}  // namespace gdpt
