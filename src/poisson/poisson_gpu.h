// poisson_gpu.h — screened Poisson reconstruction on the GPU (GLSL compute, float32), the
// device counterpart of the double-precision reference in poisson_cpu.h / poisson_irls.h.
//
// Solves, per RGB channel, argmin_I ‖H_dx I − dx‖²_W + ‖H_dy I − dy‖²_W + α²‖I − primal‖²_W
// (forward differences, gradient rows beyond the last column/row dropped; Kettunen et al.
// 2015, §4) with
//   L2   one weighted least-squares solve, by
//          mg-pcg  CG preconditioned with one symmetric multigrid V-cycle (default),
//          cg      plain CG (the published solver's method),
//          jacobi  damped Jacobi sweeps, mg  repeated V-cycles;
//        all iterate to the relative residual tolerance ‖b − A x‖ ≤ τ ‖b‖ per channel;
//   WL2  L2 with per-pixel inverse-variance row weights w = 1/(var + ε) from var_primal,
//        var_dx, var_dy (RGB-averaged, so one operator serves the three channels),
//        renormalised to mean 1;
//   L1   IRLS: weights 1/(‖RGB residual‖ + ε_k) with ε_k = regInit·regIter^(k−1), warm
//        starts, each inner solve by the chosen solver (poisson_irls.h).
// The whole iteration (including the CG scalars α_k, β_k) runs on the device; the host
// only submits batches of iterations and reads the convergence flags between batches.
// Sums are fixed-order tree reductions: the same input gives the same bits.
//
// Non-finite inputs are counted and neutralised before upload: a non-finite primal value
// becomes 0 with primal weight 0, a non-finite gradient 0 with row weight 0, a non-finite
// or negative variance gives weight 0 (counted apart: NonFiniteCounts::negativeVariance).
// α = 0 (or all primal weights 0) leaves A singular; the solution is then shifted so its
// weighted mean equals the primal's (the α → 0 limit, poisson_cpu.h).
//
// Large inputs: the device sums squares in float32 (‖b‖², the CG dot products), which
// overflow once values pass about 1e19 (the solve then saw ‖b‖ = inf and stopped after 0
// iterations with residual 0). Inputs whose largest magnitude exceeds kSolveMaxMagnitude are
// scaled by 2^-k first (primal, gradients and the IRLS regulariser alike; the variance
// weights are unchanged by a common factor) and the result by 2^k: a power of two commutes
// exactly with float arithmetic short of underflow, so this is the same solve
// (SolveReport::scaleExponent = k).
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "image/image.h"
#include "poisson/poisson_gpu_engine.h"
#include "poisson/weight_contrast.h"
#include "vk/commands.h"
#include "vk/timing.h"

namespace gdpt {

// L2, inverse-variance weighted L2, L1 (IRLS; Kettunen et al. 2015) and L1 with
// inverse-variance row weights taken from a box-filtered variance (weightedL1Weights).
enum class Reconstruction { L2, WeightedL2, L1, WeightedL1 };
// HostPcg: not on the device but on the host's threads, in double precision (the space-time
// solver of poisson_spacetime.h with one frame: CG preconditioned by one multigrid V-cycle
// (host_vcycle.h), IRLS with the same schedule and weights). On a CPU device (lavapipe) it
// is several times faster than the device's solvers (bench/RESULTS.md, "The reconstruction
// on the host"); a singular problem (α = 0 or no primal row) still goes to the device.
enum class GpuSolver { MgPcg, Cg, Jacobi, Mg, HostPcg };

// Parses "l1|l2|wl2|wl1" and "mg-pcg|cg|jacobi|mg|host-pcg"; throws gdpt::UsageError otherwise.
Reconstruction parseReconstruction(const std::string& text);
GpuSolver parseGpuSolver(const std::string& text);
const char* toString(Reconstruction r);
const char* toString(GpuSolver s);
inline constexpr double kDeviceIrlsInnerTolerance = 0.02;
inline constexpr double kHostIrlsInnerTolerance = 0.005;

// The --solver choices of `gdpt render` and `gdpt solve`, and their help.
inline constexpr const char* kSolverChoices[] = {"auto", "mg-pcg", "cg", "jacobi", "mg", "host-pcg"};
inline constexpr const char* kSolverHelp =
    "Linear solver of the reconstruction: auto (host-pcg on a CPU Vulkan device such as lavapipe, where "
    "it is several times faster; mg-pcg on a GPU), mg-pcg (device, multigrid-preconditioned CG), cg, "
    "jacobi, mg (device), host-pcg (the host's threads, CG preconditioned by a multigrid V-cycle, in "
    "double precision)";
// "auto" (nullopt) or a solver's name (parseGpuSolver); throws gdpt::UsageError otherwise.
std::optional<GpuSolver> parseSolverChoice(const std::string& text);
// The solver of a choice on `ctx`: the chosen one, or for auto host-pcg on a CPU device
// (lavapipe, where the host's threads solve 2-5x faster) and mg-pcg on any other.
GpuSolver resolveSolver(std::optional<GpuSolver> choice, const vk::Context& ctx);

struct SolveOptions {
    Reconstruction method = Reconstruction::L2;
    GpuSolver solver = GpuSolver::MgPcg;
    double alpha = 0.2;        // primal rows are α (I − t): energy weight α²
    double tolerance = 1e-4;   // relative residual per channel
    int maxIterations = 2000;  // per (inner) solve: CG steps, V-cycles or Jacobi sweeps
    // IRLS (L1): the published default regulariser (regInit 0.05), fewer rounds because each
    // inner solve runs to a tolerance instead of a fixed 50 CG steps. Six rounds with factor
    // 0.4 end near the regulariser of eight with 0.5 (5.1e-4 against 7.8e-4) and measured
    // the same or lower relMSE on the Cornell box at 4-32 spp and the scene set at 8 spp,
    // with the same outlier rejection, in 15-20 % less solve time (bench/RESULTS.md,
    // IRLS schedule).
    int irlsIterations = 6;
    double irlsRegInit = 0.05;
    double irlsRegIter = 0.4;
    // Inner tolerance before the last IRLS round. On renders the result hardly depends on it
    // (Cornell box 4-32 spp, relMSE within 2 % from 0.001 to 0.1), but outlier rejection
    // does (a test image with corrupted gradients: rmse 0.0015 at 0.001, 0.014 at 0.01,
    // 0.015 at 0.02, 0.050 at 0.05). 0.02 instead of 0.01 keeps that and takes 20-30 % fewer
    // iterations on low-spp renders (bench/RESULTS.md, IRLS schedule). The host's CG, when
    // its preconditioner was the diagonal (before host_vcycle.h's V-cycle), left more
    // low-frequency error at the same relative residual than multigrid: at 0.02 its L1
    // images were 0.6-1.3 % above the device's relMSE, at 0.005 0.0-1.1 % below it, still in
    // under half the device's time on lavapipe (Cornell box, 8 and 32 spp, bench/RESULTS.md,
    // "The reconstruction on the host"). nullopt: the solver's default
    // (kDeviceIrlsInnerTolerance, kHostIrlsInnerTolerance).
    std::optional<double> irlsInnerTolerance;
    double varianceEpsilon = 1e-4;  // WL2, WL1: w = 1/(var + ε)
    // WL1: the variances are averaged over a (2r+1)² box first, so that a row's weight is
    // not an estimate from the same samples as its value (unfiltered, WL1 and WL2 trade
    // variance for a bias of their own: bench/RESULTS.md, variance-weighted L1).
    int varianceFilterRadius = 3;
    // WL1: no row's variance weight further than this factor from the median row's
    // (boundWeightContrast; 0 = unbounded). The weights of a firefly-heavy image span orders of
    // magnitude, which made the solves take 20x the iterations of L1 (641 against 30 on the
    // door ajar at 256²) and kept nothing of the lower error: within 4x of the median the
    // iterations are 1-3x L1's and the error is as low or lower on every scene of the set
    // (bench/RESULTS.md, "Weighted L1 with bounded weights").
    double varianceWeightContrast = kDefaultVarianceWeightContrast;
    VcycleParams vcycle{};          // smoother and sweeps of mg / mg-pcg
    bool keepHistory = false;       // fill SolveReport::history (test mode)
    bool warmStart = true;          // start from the primal (else from 0)
    vk::GpuTimer* timer = nullptr;  // per-kernel GPU times (capacity: scopes per batch)
    // Called after every submitted batch: IRLS rounds finished (L2: 0, then 1), rounds in
    // all, inner iterations recorded so far. For progress reports on long solves.
    std::function<void(int roundsDone, int rounds, int iterations)> progress;
    // IRLS (L1, WL1): no further reweighting round is started that would end after this time,
    // at the mean time of the rounds so far (a timed render's budget). The result is then the
    // last finished round's: a milder L1 (weights of a larger regulariser). None: no limit.
    std::optional<std::chrono::steady_clock::time_point> deadline;
};

// Values replaced (each counted once per value; a variance per pixel and layer).
struct NonFiniteCounts {
    std::size_t primal = 0, dx = 0, dy = 0, variance = 0, weight = 0;  // NaN or infinite
    std::size_t negativeVariance = 0;  // finite but negative: not a variance (weight 0)
    [[nodiscard]] std::size_t total() const {
        return primal + dx + dy + variance + weight + negativeVariance;
    }
};

// Largest input magnitude the device solves unscaled (2^32): squares up to 2^64, summed over
// 2^28 pixels (16384²) with weights, stay far below float's 3.4e38.
inline constexpr double kSolveMaxMagnitude = 4294967296.0;

struct SolveReport {
    int iterations = 0;              // inner iterations, summed over IRLS rounds
    int irlsIterations = 0;          // 1 for L2/WL2
    int batches = 0;                 // command buffers submitted (host round trips)
    double residual = 0.0;           // true final relative residual, max over channels
    bool converged = false;          // every channel of the last solve reached the tolerance
    bool stoppedAtDeadline = false;  // IRLS rounds left out for SolveOptions::deadline
    double ms = 0.0;                 // wall time of the solve (upload to download)
    NonFiniteCounts nonFinite;
    // The inputs were scaled by 2^-scaleExponent for the device and the result back by
    // 2^scaleExponent (0: unscaled; kSolveMaxMagnitude).
    int scaleExponent = 0;
    // Test mode: relative residual ‖r_k‖/‖b‖ per channel after iteration k of the last
    // solve (k = 0 is the initial guess; Jacobi records every second sweep).
    std::vector<std::array<double, 3>> history;
    std::map<std::string, vk::KernelTime> kernels;  // copy of the timer's totals
};

// Inputs of one reconstruction: all images of one size. Optional per-pixel weights (shared
// by the channels, ≥ 0) multiply the rows; optional variances enable WL2 and WL1 weights.
struct PoissonInput {
    const Image* primal = nullptr;
    const Image* dx = nullptr;
    const Image* dy = nullptr;
    const Image* varPrimal = nullptr;
    const Image* varDx = nullptr;
    const Image* varDy = nullptr;
    const std::vector<float>* weightPrimal = nullptr;
    const std::vector<float>* weightDx = nullptr;
    const std::vector<float>* weightDy = nullptr;
};

// Whether `r` is solved by IRLS rounds (L1, WL1) / needs the variance layers (WL2, WL1).
bool isIrls(Reconstruction r);
bool needsVariance(Reconstruction r);
// Whether a render (or `gdpt solve`) with this --debias-cells takes r's coarse scales from the
// primal (poisson/debias.h): the biased reconstructions (L1, WL1, WL2) with cells > 0. L2 is
// unbiased as it is (a linear function of unbiased estimates).
bool debiases(Reconstruction r, int debiasCells);

// A row's weight from an RGB variance image (WL2): 1/(mean variance at i + ε); 0 where a
// channel is non-finite or negative (no variance is), counted in `counts`.
double inverseVariance(const Image& var, std::size_t i, double eps, NonFiniteCounts& counts);
// The same from a box-filtered variance (WL1, boxFilteredVariance): 0 for -1 (none valid).
double inverseFilteredVariance(float filtered, double eps);

// Mean over RGB of `var`, averaged over the (2·radius+1)² box around each pixel (clipped at
// the borders; separable, linear in the pixels). A pixel with a non-finite or a negative
// channel counts as missing: it is left out of the averages and counted in `nonFinite` or
// `negative`; a box with no valid value gives -1 (the caller's weight 0).
std::vector<float> boxFilteredVariance(const Image& var, int radius, std::size_t& nonFinite,
                                       std::size_t& negative);

class PoissonSolverGpu {
public:
    // addressing: see PoissonGpuEngine (default: descriptors unless a field is too large).
    PoissonSolverGpu(const vk::Context& ctx, int width, int height, PoissonKernels* kernels = nullptr,
                     std::optional<PoissonAddressing> addressing = std::nullopt);

    // Reconstructs into `out` (resized). Throws gdpt::Error on size mismatch or bad options.
    SolveReport solve(const PoissonInput& in, const SolveOptions& options, Image& out);

    // Creates the pipeline variants that solve() with each of `solves` dispatches, by solving
    // a small noisy problem (16x16) on the same kernels: the variants do not depend on the
    // size. Lets a renderer create them while its path kernels compile, instead of in the
    // reconstruction after sampling (RenderOptions::whileCompiling).
    void preparePipelines(const std::vector<SolveOptions>& solves);

    // The device's fields and kernels, made by the first call (a host-pcg solve needs none).
    [[nodiscard]] PoissonGpuEngine& engine();
    [[nodiscard]] int width() const { return width_; }
    [[nodiscard]] int height() const { return height_; }

private:
    struct InnerResult {
        int iterations = 0;
        bool converged = false;
    };
    // trueResidual: finish with b − A x recomputed (else the recursive residual is reported).
    InnerResult innerSolve(const SolveOptions& o, double tolerance, bool irls, bool singular,
                           bool trueResidual, SolveReport& report);
    void readHistory(int count, SolveReport& report);
    // The solve of the prepared inputs (planar RGB, scaled; weights: wp, wdx, wdy planes) on the
    // device, or on the host (HostPcg); each returns the planar RGB solution.
    std::vector<float> solveOnDevice(const std::vector<float>& primal, const std::vector<float>& dx,
                                     const std::vector<float>& dy, const std::vector<float>& weights,
                                     const SolveOptions& o, bool singular, std::size_t rows,
                                     SolveReport& report);
    std::vector<float> solveOnHost(const std::vector<float>& primal, const std::vector<float>& dx,
                                   const std::vector<float>& dy, const std::vector<float>& weights,
                                   const SolveOptions& o, SolveReport& report) const;

    vk::CommandStream& stream();

    const vk::Context& ctx_;
    int width_, height_;
    PoissonKernels* kernels_;
    std::optional<PoissonAddressing> addressing_;
    // Made on first use by a device solve (engine()), not by the constructor: a host-pcg
    // reconstruction uses neither, and the multigrid fields of a 3840x2160 image take about
    // 1.4 GB of device memory.
    std::unique_ptr<PoissonGpuEngine> engine_;
    std::unique_ptr<vk::CommandStream> stream_;
    int roundsDone_ = 0, rounds_ = 1;  // for SolveOptions::progress
};

// A repeatable stand-in for a low-spp G-PT output: smooth primal, hash-noise gradients and
// a small constant variance, width x height. For calibrating solve times and for
// PoissonSolverGpu::preparePipelines.
struct SyntheticReconProblem {
    Image primal, dx, dy, variance;
};
SyntheticReconProblem syntheticReconProblem(int width, int height);

// One-call reconstruction for the renderer: primal, gradients and optional variances (WL2
// and WL1 use them).
Image reconstruct(const vk::Context& ctx, const Image& primal, const Image& dx, const Image& dy,
                  const Image* varPrimal, const Image* varDx, const Image* varDy, const SolveOptions& options,
                  SolveReport* report = nullptr);

}  // namespace gdpt
