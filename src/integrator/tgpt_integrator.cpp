// tgpt_integrator.cpp — temporal G-PT (tgpt_integrator.h).
#include "integrator/tgpt_integrator.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <utility>

#include "integrator/gpt_sampler.h"
#include "integrator/motion_map.h"
#include "integrator/reconstruction_stage.h"
#include "integrator/render_identity.h"
#include "integrator/sample_groups.h"
#include "integrator/spacetime_weights.h"
#include "integrator/temporal_reconnect.h"
#include "integrator/tgpt_window.h"
#include "poisson/poisson_spacetime.h"
#include "util/error.h"
#include "util/memory.h"
#include "util/timer.h"

namespace gdpt {
namespace {

// Two estimates of n_a and n_b samples combined with the weights w = n / (n_a + n_b), each
// value raised to `power`: 1 for the spp-weighted mean of the estimates, 2 for the variance of
// that mean from theirs.
Image combineHalves(const Image& a, double na, const Image& b, double nb, int power) {
    Image out = a;
    const double wa = std::pow(na / (na + nb), power), wb = std::pow(nb / (na + nb), power);
    for (int c = 0; c < 3; ++c)
        for (std::size_t i = 0; i < out.pixelCount(); ++i)
            out.plane(c)[i] = float(wa * a.plane(c)[i] + wb * b.plane(c)[i]);
    return out;
}

// The reconnection shift gives this fraction of a timed frame's share to the frame's G-PT render
// when there is a frame before, and the rest to the reconnection pass from it; with --spp the pass
// takes half the frame's samples per pixel in each direction. (Measured 2026-12-06 on lavapipe:
// a sample of the pass, both directions, costs about 1.6 G-PT samples, so half the samples take
// about 0.8 of the render's time.)
constexpr double kReconnectRenderShare = 0.55;

// The reconnection shift's frame: one G-PT render of the frame's samples seeded σ(f), and, with a
// frame `before`, the differences from it along map (temporal_reconnect.h), with their variance.
// secondsPerSample: what a sample of the pass took last (0: not known yet; the pass then takes
// half the render's samples); updated.
FrameSamples sampleReconnected(const vk::Context& ctx, const GptSamplingOptions& sampling,
                               const Scene* before, const Scene& scene, MotionMap map,
                               const RenderOptions& options, double share, std::uint32_t seed,
                               double& secondsPerSample) {
    const bool timed = options.timeBudget > 0.0;
    Timer frameTimer;
    RenderOptions whole = options;
    whole.whileCompiling = nullptr;
    whole.elapsedBefore = 0.0;
    whole.seed = seed;
    if (timed) whole.timeBudget = before ? kReconnectRenderShare * share : share;
    RenderResultGpt r = renderGpt(ctx, scene, whole, sampling);
    FrameSamples f;
    f.stats = r.stats;
    f.primal = std::move(r.primal);
    f.dx = std::move(r.dx);
    f.dy = std::move(r.dy);
    f.direct = std::move(r.direct);
    f.varPrimal = std::move(r.varPrimal);
    f.varDx = std::move(r.varDx);
    f.varDy = std::move(r.varDy);
    f.varDirect = std::move(r.varDirect);
    if (r.stats.cancelled || !before) return f;
    TemporalReconnectOptions t;
    t.spp = std::max<std::uint32_t>(1, r.stats.spp / 2);
    if (timed && secondsPerSample > 0.0)
        t.spp = std::max<std::uint32_t>(
            1, std::uint32_t(std::clamp((share - frameTimer.seconds()) / secondsPerSample, 0.0, 1e6)));
    t.seed = seed ^ 0x5bd1e995u;
    const TemporalDifferences d = reconnectDifferences(ctx, *before, scene, map, options.scene, t);
    if (d.cancelled) {
        f.stats.cancelled = true;
        return f;
    }
    secondsPerSample = d.seconds / double(t.spp);
    f.dt = d.dt;
    f.varDt = d.varDt;
    f.fromPrevious = std::move(map.partner);
    f.stats.tgpt.temporalSpp = t.spp;
    f.stats.tgpt.temporalMs = d.seconds * 1e3;
    f.stats.tgpt.temporalPairs = d.pairs;
    f.stats.tgpt.temporalFailures = d.failures;
    f.stats.raysTraced += d.rays;
    f.stats.nanSamples += d.nanSamples;
    return f;
}

// The counters and times of two renders of one frame, added.
RenderStats addStats(const RenderStats& a, const RenderStats& b) {
    RenderStats s = a;
    s.spp = a.spp + b.spp;
    s.partialPassRows = std::max(a.partialPassRows, b.partialPassRows);
    s.batches = a.batches + b.batches;
    s.bvhBuildMs += b.bvhBuildMs;
    s.uploadMs += b.uploadMs;
    s.pipelineWaitMs += b.pipelineWaitMs;
    s.samplingMs += b.samplingMs;
    s.readbackMs += b.readbackMs;
    s.raysTraced += b.raysTraced;
    s.pathsCompleted += b.pathsCompleted;
    s.nanSamples += b.nanSamples;
    s.shiftPairs += b.shiftPairs;
    s.shiftFailures += b.shiftFailures;
    for (const auto& [name, t] : b.kernels) {
        vk::KernelTime& k = s.kernels[name];
        k.count += t.count;
        k.totalMs += t.totalMs;
    }
    s.cancelled = a.cancelled || b.cancelled;
    return s;
}

// Groups of paired samples kept per half render (sample_groups.h): at most 16, so that a pixel's
// var_dt has up to 15 degrees of freedom (fewer below 16 samples per half, or in a timed half of
// fewer batches).
constexpr std::size_t kSampleGroups = 16;

// What a window keeps: the solver's fields (its workspace, also held from window to window),
// and per frame thirteen float RGB images (the halves' primals, the combined estimates and
// variances, var_dt; seventeen with the halves' dx, dy for mixed rows, nineteen with their
// weights' variances) until it is written, plus the sample groups of two half renders (one
// image per group, three for weighted mixed rows).
std::uint64_t windowBytes(int width, int height, int frames, bool mixed, bool weighted) {
    const std::uint64_t image = std::uint64_t(width) * std::uint64_t(height) * 3u * 4u;
    const std::uint64_t perFrame = mixed ? (weighted ? 19u : 17u) : 13u;
    const std::uint64_t groups = 2u * kSampleGroups * (mixed && weighted ? 3u : 1u);
    return spaceTimeSolveBytes(width, height, frames, mixed) +
           image * (std::uint64_t(frames) * perFrame + groups);
}

// Refuses a window larger than the machine's memory, before it is sampled.
void checkWindowMemory(int width, int height, int frames, bool mixed, bool weighted) {
    const std::uint64_t memory = physicalMemory();
    if (memory == 0) return;
    const std::uint64_t need = windowBytes(width, height, frames, mixed, weighted);
    if (need <= memory) return;
    const std::uint64_t perFrame = windowBytes(width, height, 1, mixed, weighted);
    throw Error("a tgpt window of " + std::to_string(frames) + " frames of " + std::to_string(width) + "x" +
                std::to_string(height) + " needs about " + gibibytes(need) +
                " for its space-time reconstruction, more than " + availableMemoryText(memory) +
                "; the largest window that fits is " + std::to_string(memory / perFrame) +
                " frames (--window), or render smaller frames");
}

}  // namespace

TemporalShift parseTemporalShift(const std::string& text) {
    if (text == "motion") return TemporalShift::Motion;
    if (text == "replay") return TemporalShift::Replay;
    if (text == "reconnect") return TemporalShift::Reconnect;
    throw UsageError("--temporal-shift must be motion, replay or reconnect, not '" + text + "'");
}

const char* temporalShiftName(TemporalShift shift) {
    switch (shift) {
        case TemporalShift::Motion:
            return "motion";
        case TemporalShift::Replay:
            return "replay";
        case TemporalShift::Reconnect:
            break;
    }
    return "reconnect";
}

TgptIntegrator::TgptIntegrator(TgptOptions options) : options_(std::move(options)) {
    options_.sampling.demodulate = Demodulation::Off;
    if (options_.window < 1) throw UsageError("--window must be at least 1 frame");
    if (options_.shift == TemporalShift::Reconnect && options_.gamma > 0.0)
        throw UsageError(
            "--gamma: the mixed rows pair the halves of the motion and replay shifts; the reconnection shift "
            "renders each frame whole (leave --gamma out, or 0)");
}

std::uint32_t TgptIntegrator::maxBatchSpp(int width, int height) const {
    return maxBatchSppFor(width, height, kGptBatchPixelSamples);
}

ExrAttributes TgptIntegrator::identity(const Scene& scene, const RenderOptions& options) const {
    (void)scene;
    return {{"shift_threshold", exactFloat(options.scene.shiftThreshold)},
            {"edge_samples", edgeSamplesText(options_.sampling.edgeSamples)},
            {"edge_sample_pixels", kEdgeSamplePixels},
            {"pair_weights", kPairWeights},
            {"window", std::to_string(options_.window)},
            {"temporal_shift", temporalShiftName(options_.shift)}};
}

RenderOutput TgptIntegrator::render(const vk::Context& ctx, const Scene& scene,
                                    const RenderOptions& options) {
    (void)ctx, (void)scene, (void)options;
    throw UsageError(
        "--method tgpt renders a sequence of frames (temporal differences between them): add --frames A:B");
}

FrameSamples TgptIntegrator::sampleHalves(const vk::Context& ctx, const Scene& scene,
                                          const RenderOptions& options, GptSamplingOptions firstSampling,
                                          const std::vector<std::uint32_t>& partner,
                                          const FrameWindow& window, int frame, double share,
                                          HalfPairing& pairing) {
    Timer frameTimer;
    const bool mixed = options_.gamma > 0.0;
    // The mixed rows' variances only weight them.
    const bool groupGradients = options_.weighted && mixed;
    const bool timed = options.timeBudget > 0.0;
    RenderOptions half = options;
    half.spp = std::max<std::uint32_t>(1, options.spp / 2);
    half.whileCompiling = nullptr;
    half.elapsedBefore = 0.0;
    // Timed: each half takes half of the frame's share.
    // The first half replays the frame before's second half: the same number of samples,
    // so that every one of them is paired (timed: whatever that second half reached). A
    // second half gets half the frame's share, in whole samples: the next first half will
    // take as many, and what a frame over- or underspends moves the later frames' shares.
    // (Giving it the rest of its frame's share instead made the halves alternate between
    // about 1/3 and 2/3 of the frame's samples.)
    const bool paired = pairing.spp > 0;
    if (timed) half.timeBudget = paired ? 0.0 : 0.5 * share;
    if (paired) half.spp = pairing.spp;
    half.seed = window.seed(frame);
    // Paired: the same groups of samples as the second half it repeats (batches end there).
    SampleGroupRecorder firstGroups =
        SampleGroupRecorder::atEnds(paired ? pairing.groups.ends : std::vector<std::uint32_t>{});
    if (paired) {
        firstSampling.groups = &firstGroups;
        firstSampling.groupGradients = groupGradients;
        half.batchStops = pairing.groups.ends;
    }
    RenderResultGpt first = renderGpt(ctx, scene, half, firstSampling);
    if (first.stats.cancelled) {
        FrameSamples cancelled;
        cancelled.stats = first.stats;
        return cancelled;
    }
    half.batchStops.clear();
    FrameSamples f;
    int dtGroups = 0;  // (stats are set below, from both halves)
    if (paired) {
        const SampleGroups groups = firstGroups.take();
        dtGroups = int(groups.ends.size());
        f.varDt = pairedDifferenceVariance(groups, pairing.groups, 0, partner);
        if (groupGradients) {
            f.varDxt = pairedDifferenceVariance(groups, pairing.groups, 1, partner);
            f.varDyt = pairedDifferenceVariance(groups, pairing.groups, 2, partner);
        }
        pairing.groups = {};
    }
    if (timed) half.timeBudget = paired ? 0.5 * share : std::max(1e-3, share - frameTimer.seconds());
    half.spp = std::max<std::uint32_t>(1, options.spp / 2);
    half.partialPass = false;
    half.seed = window.seed(frame + 1);
    // Its sample groups, which the next frame's first half repeats: equal ones where its
    // samples are known in advance, else its batch ends, merged in pairs past 16.
    const bool secondTimed = half.timeBudget > 0.0;
    if (!secondTimed) half.batchStops = equalGroupEnds(half.spp, kSampleGroups);
    SampleGroupRecorder secondGroups = secondTimed ? SampleGroupRecorder::everyBatch(kSampleGroups)
                                                   : SampleGroupRecorder::atEnds(half.batchStops);
    GptSamplingOptions secondSampling = options_.sampling;
    secondSampling.groups = &secondGroups;
    secondSampling.groupGradients = groupGradients;
    RenderResultGpt second = renderGpt(ctx, scene, half, secondSampling);
    if (second.stats.cancelled) {
        f.stats = addStats(first.stats, second.stats);
        return f;
    }
    half.batchStops.clear();
    pairing.groups = secondGroups.take();
    const double na = first.stats.spp, nb = second.stats.spp;
    f.primal = combineHalves(first.primal, na, second.primal, nb, 1);
    f.dx = combineHalves(first.dx, na, second.dx, nb, 1);
    f.dy = combineHalves(first.dy, na, second.dy, nb, 1);
    f.direct = combineHalves(first.direct, na, second.direct, nb, 1);
    f.varPrimal = combineHalves(first.varPrimal, na, second.varPrimal, nb, 2);
    f.varDx = combineHalves(first.varDx, na, second.varDx, nb, 2);
    f.varDy = combineHalves(first.varDy, na, second.varDy, nb, 2);
    f.varDirect = combineHalves(first.varDirect, na, second.varDirect, nb, 2);
    f.firstHalfPrimal = std::move(first.primal);
    f.secondHalfPrimal = std::move(second.primal);
    if (mixed) {
        f.firstHalfDx = std::move(first.dx);
        f.firstHalfDy = std::move(first.dy);
        f.secondHalfDx = std::move(second.dx);
        f.secondHalfDy = std::move(second.dy);
    }
    f.stats = addStats(first.stats, second.stats);
    f.stats.tgpt.firstHalfSpp = first.stats.spp;
    f.stats.tgpt.secondHalfSpp = second.stats.spp;
    f.stats.tgpt.dtVarianceGroups = dtGroups;
    pairing.spp = second.stats.spp;
    return f;
}

std::vector<RenderOutput> TgptIntegrator::renderWindow(const vk::Context& ctx, const FrameWindow& window,
                                                       const RenderOptions& options) {
    const int width = options.scene.width, height = options.scene.height;
    const bool mixed = options_.gamma > 0.0;
    checkWindowMemory(width, height, window.count, mixed, options_.weighted);
    Timer timer;
    std::vector<RenderOutput> outputs;
    std::vector<FrameSamples> frames;
    if (window.startsSequence) carry_.reset();
    const bool joined = carry_ && carry_->frame == window.first - 1;
    const bool motion = options_.shift == TemporalShift::Motion;
    const bool reconnect = options_.shift == TemporalShift::Reconnect;
    // The frame before the one being sampled, for the motion between them.
    std::shared_ptr<const Scene> previousScene = joined ? carry_->scene : nullptr;
    std::vector<PrimaryHit> previousHits = joined ? carry_->hits : std::vector<PrimaryHit>{};
    HalfPairing pairing;
    if (joined) pairing = {carry_->secondHalfSpp, std::move(carry_->secondHalfGroups)};

    // 1. Sampling: two half renders per frame, seeded σ(f) and σ(f+1) (the reconnection shift:
    // one render per frame, and the differences from the frame before by the reconnection pass).
    for (int k = 0; k < window.count; ++k) {
        const int frame = window.first + k;
        const auto scene = std::make_shared<const Scene>(window.scene(frame));
        const std::shared_ptr<const Scene> before = previousScene;
        // The motion shift: where the frame before's pixels moved, and the streams that
        // replay their paths there in this frame's first half.
        GptSamplingOptions firstSampling = options_.sampling;
        // Empty without a frame before (and for the replay shift): the same pixel.
        MotionMap map;
        Timer motionTimer;
        if (motion || reconnect) {
            std::vector<PrimaryHit> hits = primaryHits(*scene, options.scene.camera, width, height);
            if (previousScene) {
                map = motionBetween(*previousScene, previousHits, *scene, hits, options.scene.camera, width,
                                    height);
                if (!map.sameTopology && !options.quiet)
                    std::fprintf(stderr,
                                 "gdpt: warning: frames %d and %d have different triangle lists; their "
                                 "temporal differences replay paths at the same pixel\n",
                                 frame - 1, frame);
                if (motion)
                    firstSampling.streams =
                        std::make_shared<const std::vector<gpu::PixelStream>>(carriedStreams(map));
            }
            previousScene = scene;
            previousHits = std::move(hits);
        }
        const double motionMs = motionTimer.ms();
        const std::uint64_t partnered = map.partnered;
        // Timed: what is left of the window's budget (less the last window's solve time),
        // shared by the frames still to sample.
        const double frameStart = timer.seconds();
        const double share =
            std::max(1e-3, (options.timeBudget - options.elapsedBefore - frameStart -
                            lastSolveSeconds_ * double(window.count) / double(lastSolveFrames_)) /
                               double(window.count - k));
        if (reconnect) {
            FrameSamples f = sampleReconnected(ctx, options_.sampling, before.get(), *scene, std::move(map),
                                               options, share, window.seed(frame), secondsPerTemporalSample_);
            if (f.stats.cancelled) {
                outputs.push_back({{}, f.stats});
                return outputs;
            }
            f.stats.tgpt.motionPartnered = partnered;
            f.stats.tgpt.motionMs = motionMs;
            frames.push_back(std::move(f));
            continue;
        }
        FrameSamples f = sampleHalves(ctx, *scene, options, std::move(firstSampling), map.partner, window,
                                      frame, share, pairing);
        if (f.stats.cancelled) {
            outputs.push_back({{}, f.stats});
            return outputs;
        }
        f.stats.tgpt.motionPartnered = partnered;
        f.stats.tgpt.motionMs = motionMs;
        f.fromPrevious = std::move(map.partner);
        frames.push_back(std::move(f));
    }

    // 2. The space-time reconstruction of the window.
    WindowProblem w = windowProblem(frames, options_, joined ? &*carry_ : nullptr, width, height);

    SpaceTimeOptions solve;
    solve.l1 = options_.l1;
    solve.tolerance = options_.tolerance;
    SpaceTimeStats solved;
    const std::array<Field, 3> x = solveSpaceTime(w.problem, solve, &solved, &workspace_);
    lastSolveSeconds_ = solved.ms * 1e-3;
    lastSolveFrames_ = window.count;
    if (!options.quiet)
        std::fprintf(stderr,
                     "gdpt: space-time %s reconstruction of frames %d-%d: %d iterations (%d IRLS), "
                     "residual %.2g, %.1f ms\n",
                     reconstructionName().c_str(), window.first, window.first + window.count - 1,
                     solved.iterations, solved.irlsIterations, solved.residual, solved.ms);

    // 3. Compose each frame: reconstruction + very-direct light.
    outputs = composeWindow(frames, w.dtToPrevious,
                            WindowSolve{&x, solved, "spacetime_" + reconstructionName(), options_.tolerance},
                            window, joined, width, height);

    carry_ = WindowCarry{window.first + window.count - 1,
                         {},
                         std::move(frames.back().secondHalfPrimal),
                         pairing.spp,
                         std::move(pairing.groups),
                         mixed ? std::move(frames.back().secondHalfDx) : Image(),
                         mixed ? std::move(frames.back().secondHalfDy) : Image(),
                         std::move(previousScene),
                         std::move(previousHits)};
    const std::size_t last = std::size_t(window.count - 1) * std::size_t(width) * std::size_t(height);
    for (int c = 0; c < 3; ++c) carry_->recon[c].assign(x[c].begin() + std::ptrdiff_t(last), x[c].end());
    return outputs;
}

void TgptIntegrator::describe(nlohmann::json& j, const RenderStats& s) const {
    j["edge_samples"] = edgeSamplesJson(s);
    j["reconstructions"] = reconstructionsJson(s);
    j["tgpt"] = {{"window_first", s.tgpt.windowFirst},
                 {"window_frames", s.tgpt.windowFrames},
                 {"first_half_spp", s.tgpt.firstHalfSpp},
                 {"second_half_spp", s.tgpt.secondHalfSpp},
                 {"temporal_to_previous", s.tgpt.temporalToPrevious},
                 {"joined_previous_window", s.tgpt.joinedPreviousWindow},
                 {"temporal_shift", temporalShiftName(options_.shift)},
                 {"motion_partnered", s.tgpt.motionPartnered},
                 {"motion_ms", s.tgpt.motionMs},
                 {"dt_variance_groups", s.tgpt.dtVarianceGroups},
                 {"temporal_spp", s.tgpt.temporalSpp},
                 {"temporal_ms", s.tgpt.temporalMs},
                 {"temporal_pairs", s.tgpt.temporalPairs},
                 {"temporal_failures", s.tgpt.temporalFailures},
                 {"alpha", options_.alpha},
                 {"beta", options_.beta},
                 {"gamma", options_.gamma}};
}

std::string TgptIntegrator::reconstructionName() const {
    return std::string(options_.weighted ? "w" : "") + (options_.l1 ? "l1" : "l2");
}

std::string TgptIntegrator::summary(const RenderStats& s) const {
    return ", window " + std::to_string(s.tgpt.windowFirst) + "+" + std::to_string(s.tgpt.windowFrames);
}

}  // namespace gdpt
