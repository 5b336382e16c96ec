// tgpt_window.cpp — a temporal G-PT window's problem and outputs (tgpt_window.h).
#include "integrator/tgpt_window.h"

#include "integrator/gpt_sampler.h"
#include "integrator/spacetime_weights.h"
#include "poisson/poisson_gpu.h"

namespace gdpt {
namespace {

// The temporal differences from `earlier` to `later`, at the earlier frame's pixels p:
// later(π(p)) − earlier(p), 0 where p has no partner; π = the same pixel if `partner` is empty.
Image differenceAlong(const Image& later, const Image& earlier, const std::vector<std::uint32_t>& partner) {
    Image out(earlier.width(), earlier.height());
    for (int c = 0; c < 3; ++c)
        for (std::size_t p = 0; p < out.pixelCount(); ++p) {
            const std::uint32_t q = partner.empty() ? std::uint32_t(p) : partner[p];
            if (q != kNoTemporalPartner) out.plane(c)[p] = later.plane(c)[q] - earlier.plane(c)[p];
        }
    return out;
}

// The same differences moved to the later frame's pixels (the dt layer of the later frame).
Image atLaterPixels(const Image& dt, const std::vector<std::uint32_t>& partner) {
    if (partner.empty()) return dt;
    Image out(dt.width(), dt.height());
    for (int c = 0; c < 3; ++c)
        for (std::size_t p = 0; p < out.pixelCount(); ++p)
            if (partner[p] != kNoTemporalPartner) out.plane(c)[partner[p]] = dt.plane(c)[p];
    return out;
}

// Per pixel q of a frame: the offset (x, y) to the pixel of the frame before that it came
// from, and 1 in the third channel where it has one (the same pixel for the replay shift).
Image motionLayer(const std::vector<std::uint32_t>& partner, bool hasPrevious, int width, int height) {
    Image out(width, height);
    if (!hasPrevious) return out;
    for (std::size_t p = 0; p < out.pixelCount(); ++p) {
        const std::uint32_t q = partner.empty() ? std::uint32_t(p) : partner[p];
        if (q == kNoTemporalPartner) continue;
        out.plane(0)[q] = float(int(p % std::size_t(width)) - int(q % std::uint32_t(width)));
        out.plane(1)[q] = float(int(p / std::size_t(width)) - int(q / std::uint32_t(width)));
        out.plane(2)[q] = 1.0f;
    }
    return out;
}

// Appends an image (W·H per channel) to a frame-major field.
void append(std::array<Field, 3>& to, const Image& image) {
    for (int c = 0; c < 3; ++c) to[c].insert(to[c].end(), image.plane(c).begin(), image.plane(c).end());
}

// Frame `frame` of a frame-major field of W·H pixels per frame.
Image frameOf(const std::array<Field, 3>& x, std::size_t frame, int width, int height) {
    Image out(width, height);
    const std::size_t np = out.pixelCount();
    for (int c = 0; c < 3; ++c)
        for (std::size_t i = 0; i < np; ++i) out.plane(c)[i] = float(x[c][frame * np + i]);
    return out;
}

}  // namespace

WindowProblem windowProblem(const std::vector<FrameSamples>& frames, const TgptOptions& options,
                            const WindowCarry* previous, int width, int height) {
    const bool mixed = options.gamma > 0.0;
    const bool motion = options.shift == TemporalShift::Motion;
    const bool reconnect = options.shift == TemporalShift::Reconnect;
    // dt_k = first half of k+1 − second half of k (the same random numbers in consecutive
    // frames); the reconnection shift's from its pass.
    WindowProblem out;
    SpaceTimeProblem& problem = out.problem;
    problem.width = width;
    problem.height = height;
    problem.frames = int(frames.size());
    problem.alpha = options.alpha;
    problem.beta = options.beta;
    problem.gamma = options.gamma;
    // dt at the earlier frame's pixels, as the solve takes it; the layers hold it at the
    // later frame's pixels.
    std::vector<Image>& dtToPrevious = out.dtToPrevious;
    dtToPrevious.resize(frames.size());
    for (std::size_t k = 0; k < frames.size(); ++k) {
        append(problem.primal, frames[k].primal);
        append(problem.dx, frames[k].dx);
        append(problem.dy, frames[k].dy);
        if (k > 0) {
            const Image dt = reconnect
                                 ? frames[k].dt
                                 : differenceAlong(frames[k].firstHalfPrimal, frames[k - 1].secondHalfPrimal,
                                                   frames[k].fromPrevious);
            append(problem.dt, dt);
            if (mixed) {
                // The change of each spatial difference along the motion, from the paired halves
                // (the same random numbers): the mixed rows' targets.
                append(problem.dxt, differenceAlong(frames[k].firstHalfDx, frames[k - 1].secondHalfDx,
                                                    frames[k].fromPrevious));
                append(problem.dyt, differenceAlong(frames[k].firstHalfDy, frames[k - 1].secondHalfDy,
                                                    frames[k].fromPrevious));
            }
            if (motion || reconnect)
                problem.temporalPartner.insert(problem.temporalPartner.end(), frames[k].fromPrevious.begin(),
                                               frames[k].fromPrevious.end());
            dtToPrevious[k] = atLaterPixels(dt, frames[k].fromPrevious);
        }
    }
    if (previous) {
        const Image dt = reconnect ? frames[0].dt
                                   : differenceAlong(frames[0].firstHalfPrimal, previous->secondHalfPrimal,
                                                     frames[0].fromPrevious);
        problem.previous = previous->recon;
        append(problem.dtPrevious, dt);
        if (mixed && !previous->secondHalfDx.empty()) {
            // Mixed rows across the windows' boundary, with targets as inside a window.
            append(problem.dxtPrevious,
                   differenceAlong(frames[0].firstHalfDx, previous->secondHalfDx, frames[0].fromPrevious));
            append(problem.dytPrevious,
                   differenceAlong(frames[0].firstHalfDy, previous->secondHalfDy, frames[0].fromPrevious));
        }
        if (motion || reconnect) problem.previousPartner = frames[0].fromPrevious;
        dtToPrevious[0] = atLaterPixels(dt, frames[0].fromPrevious);
    }
    if (options.weighted) {
        // Rows weighted by their inverse variances; a pair without a variance of dt (fewer
        // than two groups: one sample per half) has 0 there, as a one-sample half's own.
        const auto orZero = [&](const Image& v) { return v.empty() ? Image(width, height) : v; };
        RowVariances v;
        for (std::size_t k = 0; k < frames.size(); ++k) {
            v.primal.push_back(frames[k].varPrimal);
            v.dx.push_back(frames[k].varDx);
            v.dy.push_back(frames[k].varDy);
            if (k == 0) continue;
            v.dt.push_back(orZero(frames[k].varDt));
            if (mixed) {
                v.dxt.push_back(orZero(frames[k].varDxt));
                v.dyt.push_back(orZero(frames[k].varDyt));
            }
        }
        if (previous) v.dtPrevious = orZero(frames[0].varDt);
        if (!problem.dxtPrevious[0].empty()) {
            v.dxtPrevious = orZero(frames[0].varDxt);
            v.dytPrevious = orZero(frames[0].varDyt);
        }
        const SolveOptions defaults;
        setVarianceWeights(problem, v, options.l1, defaults.varianceEpsilon, defaults.varianceFilterRadius);
    }
    return out;
}

std::vector<RenderOutput> composeWindow(std::vector<FrameSamples>& frames, std::vector<Image>& dtToPrevious,
                                        const WindowSolve& solve, const FrameWindow& window, bool joined,
                                        int width, int height) {
    std::vector<RenderOutput> outputs;
    const SpaceTimeStats& solved = solve.stats;
    for (std::size_t k = 0; k < frames.size(); ++k) {
        FrameSamples& f = frames[k];
        Image recon = frameOf(*solve.x, k, width, height);
        RenderOutput out;
        out.stats = f.stats;
        ReconstructionStats r;
        r.method = solve.name;
        r.iterations = solved.iterations;
        r.irlsIterations = solved.irlsIterations;
        r.residual = solved.residual;
        r.tolerance = solve.tolerance;
        r.converged = solved.converged;
        r.ms = solved.ms / double(frames.size());  // the window's solve, shared by its frames
        out.stats.reconstructions.push_back(r);
        out.stats.reconstructionMs = r.ms;
        out.stats.tgpt.windowFirst = window.first;
        out.stats.tgpt.windowFrames = window.count;
        out.stats.tgpt.temporalToPrevious = k > 0 || joined;
        out.stats.tgpt.joinedPreviousWindow = joined;
        const bool hasPrevious = k > 0 || joined;
        if (dtToPrevious[k].empty()) dtToPrevious[k] = Image(width, height);
        out.layers.push_back({"", gptFinal(recon, nullptr, &f.direct)});
        Image primalPlusDirect = gptFinal(f.primal, nullptr, &f.direct);
        out.layers.push_back({"recon_" + solve.name, std::move(recon)});
        out.layers.push_back({"primal", std::move(f.primal)});
        out.layers.push_back({"dx", std::move(f.dx)});
        out.layers.push_back({"dy", std::move(f.dy)});
        out.layers.push_back({"dt", std::move(dtToPrevious[k])});
        out.layers.push_back(
            {"var_dt", f.varDt.empty() ? Image(width, height) : atLaterPixels(f.varDt, f.fromPrevious)});
        out.layers.push_back({"motion", motionLayer(f.fromPrevious, hasPrevious, width, height)});
        out.layers.push_back({"direct", std::move(f.direct)});
        out.layers.push_back({"var_primal", std::move(f.varPrimal)});
        out.layers.push_back({"var_dx", std::move(f.varDx)});
        out.layers.push_back({"var_dy", std::move(f.varDy)});
        out.layers.push_back({"var_direct", std::move(f.varDirect)});
        out.layers.push_back({"primal_plus_direct", std::move(primalPlusDirect)});
        outputs.push_back(std::move(out));
    }
    return outputs;
}

}  // namespace gdpt
