// poisson_spacetime.h — the space-time screened Poisson reconstruction of temporal
// gradient-domain path tracing (Manzi, Kettunen, Durand, Zwicker, Lehtinen 2016, "Temporal
// Gradient-Domain Path Tracing", §4): a window of F frames of W x H pixels is reconstructed at
// once from every frame's primal and spatial gradients and the temporal differences between
// consecutive frames. Per channel, the unknown frames I_0..I_{F-1} minimise
//     E(I) = Σ_f [ α² Σ_i wp (I_f,i − t_f,i)²                     primal rows
//                + Σ_i wdx (I_f,i+1 − I_f,i − dx_f,i)²             (x < W−1)
//                + Σ_i wdy (I_f,i+W − I_f,i − dy_f,i)² ]           (y < H−1)
//          + β² Σ_{f<F−1} Σ_i wdt (I_f+1,π(i) − I_f,i − dt_f,i)²   temporal rows
//          [+ β² Σ_i wdb (I_0,π(i) − previous_i − dtPrevious_i)²    the frame before, fixed]
//          [+ γ² Σ_{f<F−1} Σ_i Σ_{s∈{1,W}} wm ((I_f+1,π(i)+s − I_f+1,π(i))
//                                              − (I_f,i+s − I_f,i) − dst_f,i)²]   mixed rows
//          [+ γ² Σ_i Σ_s wbm ((I_0,π(i)+s − I_0,π(i)) − (previous_i+s − previous_i)
//                              − dstPrevious_i)²]                  mixed rows to the frame before
// which is poisson_problem.h's energy of each frame plus the temporal rows: a weighted graph
// Laplacian over the pixels' x, y and temporal neighbours plus the screening diagonal. π(i) is
// the pixel of the next frame that pixel i's temporal difference ends at: i itself (the
// same pixel: a 7-point Laplacian in (x, y, f)), or where the scene's motion carries i's
// surface point (integrator/motion_map.h); a pixel without one has no temporal row. One frame
// (F = 1) is exactly the 2D problem (tested against poisson_cpu.h).
// Mixed rows (γ > 0; Manzi et al. 2016's second-order, mixed spatio-temporal differences): the
// change of a spatial difference along the motion, dxt = ∂x∂t and dyt = ∂y∂t, where the motion
// carries the pair of pixels i, i+s rigidly (π(i+s) = π(i) + s in the same row or column). Each
// such row couples four unknowns, so it is not an edge of the graph Laplacian: the operator adds
// it in gather form. A mixed row to the fixed previous frame couples two unknowns of frame 0:
// it is an edge of frame 0 (like a dx or dy row, with its own target).
//
// L2: the weights are 1. L1 (the default of G-PT): iteratively reweighted least squares as the
// 2D device solver does it (poisson_irls.h, poisson_gpu.h's schedule): round 0 is the L2
// solve, round k ≥ 1 weights every row by 1 / (‖RGB residual‖ + ε_k), ε_k = regInit ·
// regIter^(k−1), renormalised to mean 1, each round warm-started from the last.
//
// Solver: conjugate gradients preconditioned by the diagonal (Jacobi), or for one frame and for
// windows with mixed rows by multigrid V-cycles (host_vcycle.h; one frame: 188 -> 24 iterations
// on a 1080p render; a V-cycle per frame in symmetric block Gauss-Seidel over the frames), in
// double precision on
// the CPU: the three channels in lockstep over one operator (its coefficients are shared), the
// pixels in ranges over the host's threads, each range's sums added in range order (the same
// bits for any thread count). Why not the device: on lavapipe a device CG iteration over the
// same number of unknowns costs about four times a host one (`gdpt bench-poisson`: 10 frames of
// 256², docs/animation.md has the figures), and the 2D multigrid does not carry the temporal
// rows; a window, warm-started from its primal, converges in tens of iterations.
#pragma once

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "poisson/poisson_cpu.h"

namespace gdpt {

// A pixel whose temporal difference ends nowhere (SpaceTimeProblem::temporalPartner).
inline constexpr std::uint32_t kNoTemporalPartner = 0xFFFFFFFFu;

struct SpaceTimeProblem {
    int width = 0;
    int height = 0;
    int frames = 0;
    double alpha = 0.2;  // primal rows α (I − t), as poisson_problem.h
    double beta = 1.0;   // temporal rows β (I_f+1 − I_f − dt)
    double gamma = 0.0;  // mixed rows γ (the change of dx, dy along the motion − dxt, dyt); 0: none
    // Frame-major planar fields: frame f's pixel i at f·W·H + i. dt has F − 1 frames (the
    // target of I_f+1 − I_f at each pixel).
    std::array<Field, 3> primal, dx, dy, dt;
    // With γ > 0: the targets of the mixed rows at frame f's pixel i ((F − 1)·W·H each, as dt):
    // dxt_f,i of (I_f+1,π(i)+1 − I_f+1,π(i)) − (I_f,i+1 − I_f,i), dyt the same with +W.
    std::array<Field, 3> dxt, dyt;
    // Warm start (F·W·H per channel), e.g. each frame's own 2D reconstruction; empty: the
    // primal.
    std::array<Field, 3> initial;
    // Optional row weights (F·W·H each, finite and ≥ 0, shared by the channels), multiplying
    // the primal, dx and dy rows (0 drops a row; poisson_gpu.h's weights for WL2, WL1 and
    // non-finite input). L1's IRLS weights multiply them, renormalised over the rows kept.
    Field weightPrimal, weightDx, weightDy;
    // The same for the temporal rows ((F − 1)·W·H, at the earlier frame's pixel, as dt), the
    // mixed rows (as dxt, dyt; with γ > 0) and the rows to the previous frame (W·H, with
    // `previous`, and its mixed rows with dxtPrevious): the variance-weighted reconstructions
    // (tgpt --recon wl1|wl2).
    Field weightDt, weightDxt, weightDyt, weightDtPrevious, weightDxtPrevious, weightDytPrevious;
    // Optional: the frame before the window, already reconstructed (W·H per channel), and the
    // target of I_0 − previous: temporal rows β (I_0 − previous − dtPrevious) that tie the
    // window to the one before it (a sequence reconstructed window by window has no seam).
    std::array<Field, 3> previous, dtPrevious;
    // Optional, with `previous` and γ > 0: the mixed rows to the previous frame (W·H per
    // channel, at its pixels j): γ ((I_0,π(j)+s − I_0,π(j)) − (previous_j+s − previous_j) −
    // dxtPrevious_j) for s = 1 (dyt: W) where π carries j, j+s rigidly; with the previous frame
    // fixed each is a spatial difference row of frame 0. Empty: none (dt rows only there).
    std::array<Field, 3> dxtPrevious, dytPrevious;
    // π: where each temporal row ends, or empty for the same pixel everywhere. temporalPartner
    // has (F − 1)·W·H entries: for frame f's pixel i (at f·W·H + i), the pixel index (0 ..
    // W·H − 1) in frame f+1 that dt_f,i is the difference to, or kNoTemporalPartner (no row).
    // previousPartner (W·H, with `previous`): the same from the frame before into frame 0.
    std::vector<std::uint32_t> temporalPartner, previousPartner;

    [[nodiscard]] std::size_t pixels() const { return std::size_t(width) * std::size_t(height); }
    [[nodiscard]] std::size_t size() const { return pixels() * std::size_t(frames); }
};

// Whether the spatial rows of frame-major pixel i of `p` exist: dx not in its frame's last
// column, dy not in its last row (the solve's weights are 0 there; setVarianceWeights leaves
// them out of its statistics too).
inline bool spaceTimeHasDx(const SpaceTimeProblem& p, std::size_t i) {
    return (i % p.pixels()) % std::size_t(p.width) + 1 != std::size_t(p.width);
}
inline bool spaceTimeHasDy(const SpaceTimeProblem& p, std::size_t i) {
    return (i % p.pixels()) + std::size_t(p.width) < p.pixels();
}

struct SpaceTimeOptions {
    bool l1 = true;  // else L2
    // IRLS (L1): the 2D device solver's schedule (poisson_gpu.h SolveOptions).
    int irlsIterations = 6;
    double regInit = 0.05;
    double regIter = 0.4;
    double innerTolerance = 0.02;  // relative residual of the rounds before the last
    double tolerance = 1e-4;       // relative residual of the last round (and of L2)
    int maxIterations = 4000;      // per solve
    int threads = 0;               // host threads; 0 = the machine's cores
    // CG preconditioned by multigrid V-cycles (host_vcycle.h, one per frame) instead of the
    // diagonal, where that pays: one-frame windows (G-PT's reconstruction) and windows with
    // mixed rows (γ > 0).
    bool multigrid = true;
    // With multigrid and several frames: symmetric block Gauss-Seidel over the frames (a
    // V-cycle per frame, the couplings between neighbouring frames applied between them)
    // instead of block Jacobi. Measured (bench/RESULTS.md, "Block Gauss-Seidel over the
    // frames"): less than half the iterations, 8-20 % less time on tgpt's windows.
    bool coupleFrames = true;
    // IRLS: the rounds after the first stop at this time (a timed render's budget), mid-round
    // if need be: the result is the iterate reached, which every CG step brings closer.
    std::optional<std::chrono::steady_clock::time_point> deadline;
    // Called after each round (rounds finished, rounds in all, iterations so far) and every 16
    // iterations within a round (rounds finished so far). It may throw to stop the solve.
    std::function<void(int roundsDone, int rounds, int iterations)> progress;
};

struct SpaceTimeStats {
    int iterations = 0;              // PCG iterations, summed over rounds, max over channels
    int irlsIterations = 0;          // rounds run (the last possibly cut at the deadline); 1 for L2
    double residual = 0.0;           // relative residual of the last solve, max over channels
    bool converged = false;          // every channel's last solve reached the tolerance
    bool stoppedAtDeadline = false;  // rounds cut or left out for SpaceTimeOptions::deadline
    bool multigrid = false;          // CG was preconditioned by V-cycles (else the diagonal)
    bool coupledFrames = false;      // ... coupled by block Gauss-Seidel over the frames
    double ms = 0.0;
};

class SpaceTimeWorkspace;

// The reconstruction of the window, three channels of F·W·H values, in `workspace`'s buffers
// where given (the same bits as without). Throws gdpt::Error if the sizes disagree, a value is
// not finite, α ≤ 0 (the primal rows anchor the solve) or β < 0.
std::array<Field, 3> solveSpaceTime(const SpaceTimeProblem& problem, const SpaceTimeOptions& options = {},
                                    SpaceTimeStats* stats = nullptr, SpaceTimeWorkspace* workspace = nullptr);

// The buffers of a solve (the operator, the weights, CG's vectors, the V-cycles' hierarchies),
// kept for the next: a sequence reconstructed window by window reuses them instead of touching
// fresh memory for each window, which on a virtual machine cost a fifth of a later 10 × 256²
// window's solve (bench/RESULTS.md, "The space-time solve, 2026-12-05"). Holds about
// spaceTimeSolveBytes between solves.
class SpaceTimeWorkspace {
public:
    SpaceTimeWorkspace();
    ~SpaceTimeWorkspace();
    SpaceTimeWorkspace(SpaceTimeWorkspace&&) noexcept;
    SpaceTimeWorkspace& operator=(SpaceTimeWorkspace&&) noexcept;
    SpaceTimeWorkspace(const SpaceTimeWorkspace&) = delete;
    SpaceTimeWorkspace& operator=(const SpaceTimeWorkspace&) = delete;

    struct State;  // poisson_spacetime.cpp's

private:
    friend std::array<Field, 3> solveSpaceTime(const SpaceTimeProblem&, const SpaceTimeOptions&,
                                               SpaceTimeStats*, SpaceTimeWorkspace*);
    std::unique_ptr<State> state_;
};

// Bytes solveSpaceTime holds for a window: about 17 doubles per pixel, channel and frame (the
// targets, the iterate, CG's vectors, the operator's weights), 20 with mixed rows.
[[nodiscard]] constexpr std::uint64_t spaceTimeSolveBytes(int width, int height, int frames,
                                                          bool mixed = false) {
    return std::uint64_t(width) * std::uint64_t(height) * std::uint64_t(frames) * 3u * (mixed ? 20u : 17u) *
           8u;
}

// The exact L2 minimiser of one channel (Eigen's sparse LDLT on the normal equations): the
// reference of the iterative solver in tests, for small windows.
Field solveSpaceTimeExactL2(const SpaceTimeProblem& problem, int channel);

}  // namespace gdpt
