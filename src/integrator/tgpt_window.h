// tgpt_window.h — the steps of temporal G-PT (tgpt_integrator.h) after a window's frames are
// sampled: the space-time problem of the window from its frames' estimates (and the frame
// before the window, when the window continues a sequence), and each frame's output layers
// from the window's solution. Internal to gdpt_integrator.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "integrator/integrator.h"
#include "integrator/motion_map.h"
#include "integrator/sample_groups.h"
#include "poisson/poisson_spacetime.h"

namespace gdpt {

// One frame's two half renders, combined.
struct FrameSamples {
    Image primal, dx, dy, direct, varPrimal, varDx, varDy, varDirect;
    Image firstHalfPrimal;   // seeded σ(f): pairs with the previous frame's second half
    Image secondHalfPrimal;  // seeded σ(f+1): pairs with the next frame's first half
    // The halves' spatial differences, for the mixed rows (γ > 0 only; else empty).
    Image firstHalfDx, firstHalfDy, secondHalfDx, secondHalfDy;
    // Where each pixel of the frame before moved to in this one (its first half's streams
    // follow it); empty for the replay shift or without a frame before.
    std::vector<std::uint32_t> fromPrevious;
    // The variances of the paired differences from the frame before (at its pixels, as the
    // solve's rows), from the sample groups of its second half and this first half; empty
    // without a frame before (or with fewer than two groups); dxt, dyt for weighted mixed rows.
    Image varDt, varDxt, varDyt;
    // The reconnection shift: the differences from the frame before (at its pixels, as varDt).
    Image dt;
    RenderStats stats;
};

// What a window leaves the next one: its last frame's reconstruction and its second half's
// primal (seeded like the next window's first frame's first half).
struct WindowCarry {
    int frame = -1;
    std::array<std::vector<double>, 3> recon;
    Image secondHalfPrimal;
    std::uint32_t secondHalfSpp = 0;
    SampleGroups secondHalfGroups;     // its sample groups (the next first half repeats them)
    Image secondHalfDx, secondHalfDy;  // with mixed rows: the targets of the rows across
    // The motion shift: the last frame's scene and primary hits (motion_map.h).
    std::shared_ptr<const Scene> scene;
    std::vector<PrimaryHit> hits;
};

// The space-time problem of a window, and each frame's dt from the frame before at the frame's
// own pixels (its layer; empty where there is no frame before).
struct WindowProblem {
    SpaceTimeProblem problem;
    std::vector<Image> dtToPrevious;
};

// The problem of `frames` (the window's, in order) under `options`; `previous`: the window
// before when this one continues it (its rows to the fixed frame before), else null.
WindowProblem windowProblem(const std::vector<FrameSamples>& frames, const TgptOptions& options,
                            const WindowCarry* previous, int width, int height);

// The solve of a window, as each frame's output reports it.
struct WindowSolve {
    const std::array<Field, 3>* x = nullptr;  // the solution, frame-major
    SpaceTimeStats stats;
    std::string name;  // "spacetime_" + the reconstruction's name
    double tolerance = 0.0;
};

// Each frame's output: final (reconstruction + very-direct light) and the layers of
// tgpt_integrator.h, from the window's solution. Takes the frames' images and `dtToPrevious`.
std::vector<RenderOutput> composeWindow(std::vector<FrameSamples>& frames, std::vector<Image>& dtToPrevious,
                                        const WindowSolve& solve, const FrameWindow& window, bool joined,
                                        int width, int height);

}  // namespace gdpt
