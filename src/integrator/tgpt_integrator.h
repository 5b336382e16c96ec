// tgpt_integrator.h — temporal gradient-domain path tracing (Manzi, Kettunen, Durand, Zwicker,
// Lehtinen, "Temporal Gradient-Domain Path Tracing", ACM TOG 35(6), 2016) as an integrator of
// windows of frames:
//   1. sample: every frame f as two G-PT renders of half the samples each (gpt_sampler.h),
//      the first with frame f's seed σ(f), the second with frame f+1's seed σ(f+1) (§3, as the
//      published code seeds them). Frame f+1's first half then replays, sample for sample,
//      the random numbers of frame f's second half in the next frame's scene: the temporal
//      difference dt_f = primal(f+1, first half) − primal(f, second half) is the mean of
//      paired differences, unbiased for the difference it pairs (below), and exactly 0 where
//      nothing moved;
//   2. reconstruct: a space-time screened Poisson solve of the window from every frame's
//      primal, dx, dy and the dt between its frames (poisson_spacetime.h; L1 by IRLS by
//      default; wl1, wl2 weight every row by its inverse variance, spacetime_weights.h, dt's
//      from the paired samples' groups, sample_groups.h), coupled to the previous window's last reconstructed
//      frame through the dt between the windows, so that a sequence has no seam at window boundaries;
//   3. compose: final = reconstruction + very-direct light, per frame (as G-PT, §5 of
//      Kettunen et al. 2015).
// The temporal shift (TgptOptions::shift): random replay in primary sample space, Jacobian 1.
// Motion (the default, as Manzi et al. re-seed by motion vectors): frame f+1's first half draws
// each pixel's samples from the stream of the pixel of frame f whose primary hit the scene's
// motion carried there, shifted by the motion's sub-pixel part (motion_map.h), so dt_f(p) =
// primal(f+1, first half)(π(p)) − primal(f, second half)(p) pairs paths that start on the same
// surface point; the space-time rows follow π. Replay: π = the same pixel. Reconnect: each frame
// one G-PT render, and dt along π from the reconnection shift's pass between the two frames
// (temporal_reconnect.h; no mixed rows, which need the paired halves).
// Texture demodulation is off (a frame's modulation differs from the next one's where something
// moves).
// Layers per frame: final, recon_spacetime_<l1|l2|wl1|wl2>, primal, dx, dy, dt (from the frame
// before, at this frame's pixels; 0 in the sequence's first frame and where a pixel has no
// source), var_dt (its variance, from the paired samples' groups: sample_groups.h),
// motion (offset to the source pixel in R, G; 1 in B where there is one), direct, var_primal,
// var_dx, var_dy, var_direct, primal_plus_direct.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "integrator/integrator.h"
#include "integrator/tgpt_window.h"
#include "poisson/poisson_spacetime.h"

namespace gdpt {

class TgptIntegrator final : public Integrator {
public:
    explicit TgptIntegrator(TgptOptions options);

    [[nodiscard]] std::string name() const override { return "tgpt"; }
    [[nodiscard]] std::uint32_t maxBatchSpp(int width, int height) const override;
    [[nodiscard]] ExrAttributes identity(const Scene& scene, const RenderOptions& options) const override;
    // One image is not a sequence: throws gdpt::UsageError (tgpt renders --frames).
    RenderOutput render(const vk::Context& ctx, const Scene& scene, const RenderOptions& options) override;
    [[nodiscard]] int windowFrames() const override { return options_.window; }
    std::vector<RenderOutput> renderWindow(const vk::Context& ctx, const FrameWindow& window,
                                           const RenderOptions& options) override;
    void describe(nlohmann::json& summary, const RenderStats& stats) const override;
    [[nodiscard]] std::string summary(const RenderStats& stats) const override;

private:
    // "l1", "l2", "wl1", "wl2".
    [[nodiscard]] std::string reconstructionName() const;

    // A frame's first half repeats the frame before's second half: that half's samples per
    // pixel (0: no frame before) and its sample groups (for the variance of dt).
    struct HalfPairing {
        std::uint32_t spp = 0;
        SampleGroups groups;
    };
    // The motion shift's and the replay's frame `frame` of `window`: two G-PT renders of half the
    // samples each, seeded σ(f) (replaying the frame before's second half, with `firstSampling`'s
    // streams; `partner`: where its pixels moved) and σ(f+1), combined. `share`: a timed frame's
    // seconds. `pairing` becomes this frame's second half's. Cancelled: the stats so far, with
    // `cancelled` set.
    FrameSamples sampleHalves(const vk::Context& ctx, const Scene& scene, const RenderOptions& options,
                              GptSamplingOptions firstSampling, const std::vector<std::uint32_t>& partner,
                              const FrameWindow& window, int frame, double share, HalfPairing& pairing);

    TgptOptions options_;
    // What the last window leaves this one (tgpt_window.h).
    std::optional<WindowCarry> carry_;
    // The space-time solver's buffers, kept from window to window (poisson_spacetime.h).
    SpaceTimeWorkspace workspace_;
    // The last window's solve, reserved (per frame) from the next window's budget.
    double lastSolveSeconds_ = 0.0;
    int lastSolveFrames_ = 1;
    // The reconnection shift: seconds per sample of its last pass (0: none yet).
    double secondsPerTemporalSample_ = 0.0;
};

}  // namespace gdpt
