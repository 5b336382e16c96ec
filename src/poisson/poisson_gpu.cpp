// poisson_gpu.cpp — the GPU solvers (L2 by MG-PCG/CG/Jacobi/MG, WL2, L1 by IRLS) built from
// the engine's kernels; see poisson_gpu.h. Batching: each command buffer holds a batch of
// iterations whose size grows geometrically, the device computes α_k/β_k and convergence
// flags itself and freezes converged channels, so a batch may overshoot without changing
// the result; the host reads the flags between batches only.
#include "poisson/poisson_gpu.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

#include "poisson/poisson_spacetime.h"
#include "poisson_shared.h"
#include "util/error.h"
#include "util/timer.h"
#include "vk/context.h"

namespace gdpt {
namespace {

using namespace gpu;

// Copies an image's planes into one planar RGB vector, replacing non-finite values by 0
// and counting them; returns per-pixel validity (all three channels finite).
std::vector<float> sanitise(const Image& im, std::size_t& count, std::vector<std::uint8_t>& valid) {
    const std::size_t n = im.pixelCount();
    std::vector<float> out(3 * n);
    valid.assign(n, 1);
    for (int c = 0; c < 3; ++c)
        for (std::size_t i = 0; i < n; ++i) {
            const float v = im.plane(c)[i];
            if (std::isfinite(v)) {
                out[static_cast<std::size_t>(c) * n + i] = v;
            } else {
                out[static_cast<std::size_t>(c) * n + i] = 0.0f;
                valid[i] = 0;
                ++count;
            }
        }
    return out;
}

// The largest magnitude of the (finite) values.
float maxMagnitude(const std::vector<float>& values) {
    float m = 0.0f;
    for (float v : values) m = std::max(m, std::abs(v));
    return m;
}

// k >= 0 such that magnitude · 2^-k <= kSolveMaxMagnitude.
int scaleExponentFor(double magnitude) {
    if (!(magnitude > kSolveMaxMagnitude)) return 0;
    int exponent = 0;
    (void)std::frexp(magnitude / kSolveMaxMagnitude, &exponent);  // magnitude/max < 2^exponent
    return exponent;
}

int growBatch(int batch, int cap) {
    return std::min(batch * 2, cap);
}

}  // namespace

PoissonSolverGpu::PoissonSolverGpu(const vk::Context& ctx, int width, int height, PoissonKernels* kernels,
                                   std::optional<PoissonAddressing> addressing)
    : ctx_(ctx), width_(width), height_(height), kernels_(kernels), addressing_(addressing) {
    if (width <= 0 || height <= 0)
        throw Error("Poisson solver: invalid size " + std::to_string(width) + "x" + std::to_string(height));
}

PoissonGpuEngine& PoissonSolverGpu::engine() {
    if (!engine_) engine_ = std::make_unique<PoissonGpuEngine>(ctx_, width_, height_, kernels_, addressing_);
    return *engine_;
}

vk::CommandStream& PoissonSolverGpu::stream() {
    if (!stream_) stream_ = std::make_unique<vk::CommandStream>(ctx_, "poisson solve");
    return *stream_;
}

void PoissonSolverGpu::readHistory(int count, SolveReport& report) {
    const int entries = std::min(count + 1, static_cast<int>(kPoissonMaxHistory));
    std::vector<float> raw(static_cast<std::size_t>(entries) * 3);
    const vk::Buffer& scalars = engine().scalars;
    scalars.download(raw.data(), raw.size() * sizeof(float), sizeof(PoissonScalars));
    PoissonScalars sc{};
    scalars.download(&sc, sizeof(sc));
    report.history.clear();
    for (int k = 0; k < entries; ++k) {
        std::array<double, 3> rel{};
        for (int c = 0; c < 3; ++c) {
            const double rr = raw[static_cast<std::size_t>(k) * 3 + static_cast<std::size_t>(c)];
            rel[static_cast<std::size_t>(c)] =
                sc.bb[c] > 0.0f ? std::sqrt(rr / double(sc.bb[c])) : std::sqrt(rr);
        }
        report.history.push_back(rel);
    }
}

PoissonSolverGpu::InnerResult PoissonSolverGpu::innerSolve(const SolveOptions& o, double tolerance, bool irls,
                                                           bool singular, bool trueResidual,
                                                           SolveReport& report) {
    // irls: the IRLS weights and their scale have been recorded/computed already by the caller
    // into this batch's command buffer (see solve()).
    PoissonGpuEngine& e = engine();
    vk::GpuTimer* timer = o.timer;
    const float tol = static_cast<float>(tolerance);
    const std::uint64_t fine = 3ull * e.pixels();
    const bool cgFamily = o.solver == GpuSolver::MgPcg || o.solver == GpuSolver::Cg;
    const bool pcg = o.solver == GpuSolver::MgPcg;
    const std::uint32_t zIsR = pcg ? 0u : kPoissonFlagZIsR;
    vk::CommandStream& st = stream();
    VkCommandBuffer cmd = st.cmd();

    e.recordSetup(cmd, static_cast<float>(o.alpha * o.alpha), irls, timer);
    if (o.solver != GpuSolver::Cg && o.solver != GpuSolver::Jacobi) e.recordCoarsenAll(cmd, timer);
    // Singular A (α = 0): CG works on b − mean(b), the consistent part (poisson_residual).
    const std::uint32_t project = singular && cgFamily ? kPoissonFlagProject : 0u;
    if (project) e.recordScalars(cmd, kPoissonModeMean, 0u, 0u, 0.0f, static_cast<float>(e.pixels()), timer);
    if (cgFamily) {
        e.recordResidual(cmd, 0, kPoissonFlagFromSol | kPoissonFlagDot | project, timer);
        if (pcg) e.recordVcycle(cmd, o.vcycle, true, true, timer);
    } else {
        PoissonGpuEngine::recordCopy(cmd, e.rhs, e.b, fine);
        PoissonGpuEngine::recordCopy(cmd, e.sol, e.x, fine);
        e.recordResidual(cmd, 0, kPoissonFlagDot, timer);
    }
    e.recordScalars(cmd, kPoissonModeInit, zIsR, 0, tol, 0.0f, timer);

    int batch = 4, cap = 32;
    if (o.solver == GpuSolver::Cg) batch = 32, cap = 128;
    if (o.solver == GpuSolver::Jacobi) batch = 64, cap = 1024;
    int k = 0;
    PoissonScalars sc{};
    // The device is idle here (every earlier batch was waited for), so the gate can be
    // re-armed; Init zeroes it again if the start already meets the tolerance, which lets the
    // first iterations ride in the set-up's command buffer.
    e.armGate();
    for (;;) {
        const int count = std::min(batch, o.maxIterations - k);
        e.setGated(true);
        for (int j = 0; j < count; ++j) {
            ++k;
            const std::uint32_t it = static_cast<std::uint32_t>(k);
            if (cgFamily) {
                const std::uint32_t pNew = static_cast<std::uint32_t>((k % 2) * fine);
                const std::uint32_t pOld = static_cast<std::uint32_t>(((k + 1) % 2) * fine);
                e.recordCgDirection(cmd, zIsR | (k == 1 ? kPoissonFlagFirst : 0u), pOld, pNew, timer);
                e.recordScalars(cmd, kPoissonModeAlpha, zIsR, it, tol, 0.0f, timer);
                e.recordCgUpdate(cmd, pNew, timer);
                if (pcg) e.recordVcycle(cmd, o.vcycle, true, true, timer);
                e.recordScalars(cmd, kPoissonModeBeta, zIsR | project, it, tol, 0.0f, timer);
            } else if (o.solver == GpuSolver::Mg) {
                e.recordVcycle(cmd, o.vcycle, false, false, timer);
                e.recordResidual(cmd, 0, kPoissonFlagDot, timer);
                e.recordScalars(cmd, kPoissonModeRecord, kPoissonFlagZIsR, it, tol, 0.0f, timer);
            } else {
                // Jacobi: two sweeps (X -> R -> X) per recorded iteration pair.
                e.recordSmooth(cmd, 0, kPoissonFlagJacobi | kPoissonFlagToR, 0u, o.vcycle.omega, timer);
                ++k;
                e.recordSmooth(cmd, 0, kPoissonFlagJacobi, 0u, o.vcycle.omega, timer);
                e.recordResidual(cmd, 0, kPoissonFlagDot, timer);
                e.recordScalars(cmd, kPoissonModeRecord, kPoissonFlagZIsR, static_cast<std::uint32_t>(k / 2),
                                tol, 0.0f, timer);
                ++j;
            }
        }
        e.setGated(false);
        // Run the open command buffer (set-up and/or iterations) and check the flags.
        st.submit();
        st.waitAll();
        ++report.batches;
        if (timer) timer->collect();
        e.scalars.download(&sc, sizeof(sc));
        if (o.progress) o.progress(roundsDone_, rounds_, report.iterations + k);
        const bool done = sc.done[0] && sc.done[1] && sc.done[2];
        if (done || k >= o.maxIterations) break;
        cmd = st.begin();
        if (timer) timer->reset(cmd);
        batch = growBatch(batch, cap);
    }
    // Stationary solvers iterate in X: copy it to Sol. With trueResidual, recompute b − A x
    // for the returned x (the recursion drifts from it by float rounding); IRLS rounds before
    // the last skip that pass, their residual is the recursive one.
    if (!cgFamily || trueResidual) {
        cmd = st.begin();
        if (timer) timer->reset(cmd);
        if (!cgFamily) PoissonGpuEngine::recordCopy(cmd, e.x, e.sol, fine);
        if (trueResidual) {
            e.recordResidual(cmd, 0, kPoissonFlagFromSol | kPoissonFlagDot | project, timer);
            e.recordScalars(cmd, kPoissonModeFinal, zIsR, 0, tol, 0.0f, timer);
        }
        st.submit();
        st.waitAll();
        ++report.batches;
        if (timer) timer->collect();
        e.scalars.download(&sc, sizeof(sc));
    }

    InnerResult result;
    result.converged = true;
    double worst = 0.0;
    for (int c = 0; c < 3; ++c) {
        const int its = static_cast<int>(sc.iterations[c]) * (o.solver == GpuSolver::Jacobi ? 2 : 1);
        result.iterations = std::max(result.iterations, its);
        const double rr = trueResidual ? sc.finalRr[c] : sc.rr[c];
        const double rel = sc.bb[c] > 0.0f ? std::sqrt(rr / sc.bb[c]) : std::sqrt(rr);
        // Done by the recursive residual, and the true residual agrees (within 2x: the
        // recursion drifts from b − A x by float rounding).
        result.converged = result.converged && sc.done[c] != 0 && rel <= 2.0 * tolerance;
        worst = std::max(worst, rel);
    }
    report.residual = worst;
    // History entries exist up to the last iteration that ran (the gate skips the rest).
    std::uint32_t ran = 0;
    for (int c = 0; c < 3; ++c) ran = std::max(ran, sc.iterations[c]);
    if (o.keepHistory) readHistory(static_cast<int>(ran), report);
    return result;
}

SyntheticReconProblem syntheticReconProblem(int width, int height) {
    SyntheticReconProblem p{Image(width, height, 0.5f), Image(width, height, 0.0f),
                            Image(width, height, 0.0f), Image(width, height, 1e-3f)};
    for (int c = 0; c < 3; ++c)
        for (std::size_t i = 0; i < p.primal.pixelCount(); ++i) {
            p.primal.plane(c)[i] = 0.5f + 0.25f * std::sin(0.37f * static_cast<float>(i % 97));
            // Low-spp-like noise in the gradients (a fixed hash, so the estimate is repeatable):
            // smooth inputs converge in far fewer iterations than real renders.
            const auto h =
                static_cast<std::uint32_t>((i * 2654435761u) ^ (static_cast<std::uint32_t>(c) * 40503u));
            p.dx.plane(c)[i] = 0.2f * (static_cast<float>(h % 1000u) / 1000.0f - 0.5f);
            p.dy.plane(c)[i] = 0.2f * (static_cast<float>((h >> 10) % 1000u) / 1000.0f - 0.5f);
        }
    return p;
}

namespace {
// Where solve() solves: host-pcg on the host unless the problem is singular (alpha 0 or no
// primal row), which needs the device's solvers.
bool solvesOnHost(const SolveOptions& o, bool singular) {
    return o.solver == GpuSolver::HostPcg && !singular;
}
}  // namespace

void PoissonSolverGpu::preparePipelines(const std::vector<SolveOptions>& solves) {
    // Solves on the host dispatch nothing. (The synthetic problem below has every primal row.)
    const bool device = std::any_of(solves.begin(), solves.end(),
                                    [](const SolveOptions& o) { return !solvesOnHost(o, !(o.alpha > 0.0)); });
    if (!device) return;
    constexpr int kSize = 16;  // two levels: every per-level variant of a V-cycle occurs
    PoissonSolverGpu small(ctx_, kSize, kSize, &engine().kernels(), engine().addressing());
    const SyntheticReconProblem p = syntheticReconProblem(kSize, kSize);
    PoissonInput in;
    in.primal = &p.primal;
    in.dx = &p.dx;
    in.dy = &p.dy;
    in.varPrimal = in.varDx = in.varDy = &p.variance;
    for (SolveOptions o : solves) {
        o.timer = nullptr;
        o.progress = nullptr;
        o.keepHistory = false;
        Image out;
        (void)small.solve(in, o, out);
    }
    engine().bind();  // the shared variants now point at the small engine's buffers
}

std::vector<float> PoissonSolverGpu::solveOnDevice(const std::vector<float>& primal,
                                                   const std::vector<float>& dx, const std::vector<float>& dy,
                                                   const std::vector<float>& weights, const SolveOptions& o,
                                                   bool singular, std::size_t rows, SolveReport& report) {
    PoissonGpuEngine& e = engine();
    const std::size_t n = e.pixels();
    e.bind();
    e.primal.uploadVector(primal);
    e.dx.uploadVector(dx);
    e.dy.uploadVector(dy);
    e.weights.uploadVector(weights);
    if (o.warmStart)
        e.sol.uploadVector(primal);  // warm start from the primal, as the published solver
    else
        e.sol.zero();

    VkCommandBuffer cmd = stream().begin();
    if (o.timer) o.timer->reset(cmd);
    roundsDone_ = 0;
    rounds_ = isIrls(o.method) ? std::max(1, o.irlsIterations) : 1;
    if (!isIrls(o.method)) {
        const InnerResult r = innerSolve(o, o.tolerance, false, singular, true, report);
        report.iterations = r.iterations;
        report.converged = r.converged;
        report.irlsIterations = 1;
    } else {
        double reg = std::ldexp(o.irlsRegInit, -report.scaleExponent);  // radiance units, scaled
        const auto started = std::chrono::steady_clock::now();
        for (int k = 0; k < rounds_; ++k) {
            if (k > 0 && o.deadline) {
                const auto now = std::chrono::steady_clock::now();
                if (now + (now - started) / k > *o.deadline) {
                    report.stoppedAtDeadline = true;
                    break;
                }
            }
            const bool last = k + 1 == rounds_;
            const double tol =
                last ? o.tolerance
                     : std::max(o.tolerance, o.irlsInnerTolerance.value_or(kDeviceIrlsInnerTolerance));
            if (k > 0) {
                // The previous inner solve submitted its buffers: open a new one for the
                // weights, their mean-1 scale and the next solve's set-up.
                cmd = stream().begin();
                if (o.timer) o.timer->reset(cmd);
                e.recordIrlsWeights(cmd, static_cast<float>(o.alpha * o.alpha), static_cast<float>(reg),
                                    o.timer);
                e.recordScalars(cmd, kPoissonModeIrls, 0u, 0u, 0.0f, static_cast<float>(rows), o.timer);
                reg *= o.irlsRegIter;
            }
            const InnerResult r = innerSolve(o, tol, k > 0, false, last, report);
            report.iterations += r.iterations;
            report.converged = r.converged;
            ++report.irlsIterations;
            roundsDone_ = k + 1;
        }
    }
    return e.sol.downloadVector<float>(3 * n);
}

std::vector<float> PoissonSolverGpu::solveOnHost(const std::vector<float>& primal,
                                                 const std::vector<float>& dx, const std::vector<float>& dy,
                                                 const std::vector<float>& weights, const SolveOptions& o,
                                                 SolveReport& report) const {
    const std::size_t n = std::size_t(width_) * std::size_t(height_);
    SpaceTimeProblem p;
    p.width = width_;
    p.height = height_;
    p.frames = 1;
    p.alpha = o.alpha;
    const auto plane = [n](const std::vector<float>& v, std::size_t k) {
        return Field(v.begin() + static_cast<std::ptrdiff_t>(k * n),
                     v.begin() + static_cast<std::ptrdiff_t>((k + 1) * n));
    };
    for (std::size_t c = 0; c < 3; ++c) {
        p.primal[c] = plane(primal, c);
        p.dx[c] = plane(dx, c);
        p.dy[c] = plane(dy, c);
        if (!o.warmStart) p.initial[c].assign(n, 0.0);  // else the solver starts from the primal
    }
    p.weightPrimal = plane(weights, 0);
    p.weightDx = plane(weights, 1);
    p.weightDy = plane(weights, 2);
    SpaceTimeOptions so;
    so.l1 = isIrls(o.method);
    so.irlsIterations = o.irlsIterations;
    so.regInit = std::ldexp(o.irlsRegInit, -report.scaleExponent);  // radiance units, scaled
    so.regIter = o.irlsRegIter;
    so.innerTolerance = std::max(o.tolerance, o.irlsInnerTolerance.value_or(kHostIrlsInnerTolerance));
    so.tolerance = o.tolerance;
    so.maxIterations = o.maxIterations;
    so.deadline = o.deadline;
    so.progress = o.progress;
    SpaceTimeStats st;
    const std::array<Field, 3> x = solveSpaceTime(p, so, &st);
    report.iterations = st.iterations;
    report.irlsIterations = st.irlsIterations;
    report.residual = st.residual;
    report.converged = st.converged;
    report.stoppedAtDeadline = st.stoppedAtDeadline;
    std::vector<float> sol(3 * n);
    for (std::size_t c = 0; c < 3; ++c)
        for (std::size_t i = 0; i < n; ++i) sol[c * n + i] = static_cast<float>(x[c][i]);
    return sol;
}

SolveReport PoissonSolverGpu::solve(const PoissonInput& in, const SolveOptions& o, Image& out) {
    Timer wall;
    if (!in.primal || !in.dx || !in.dy) throw Error("Poisson solve: primal, dx and dy are required");
    const int w = width_, h = height_;
    for (const Image* im : {in.primal, in.dx, in.dy, in.varPrimal, in.varDx, in.varDy})
        if (im && (im->width() != w || im->height() != h))
            throw Error("Poisson solve: input of size " + std::to_string(im->width()) + "x" +
                        std::to_string(im->height()) + " does not match the solver's " + std::to_string(w) +
                        "x" + std::to_string(h));
    if (!std::isfinite(o.alpha) || o.alpha < 0.0) throw Error("Poisson solve: alpha must be finite and >= 0");
    if (!(o.tolerance > 0.0) || !(o.tolerance < 1.0))
        throw Error("Poisson solve: tolerance must be in (0, 1)");
    if (o.maxIterations < 1) throw Error("Poisson solve: max iterations must be >= 1");
    if (isIrls(o.method) && !(o.alpha > 0.0))
        throw Error("Poisson solve: L1 (IRLS) needs alpha > 0 (the primal rows anchor each iterate)");
    if (needsVariance(o.method) && !(in.varPrimal && in.varDx && in.varDy))
        throw Error(std::string("Poisson solve: ") + toString(o.method) +
                    " needs the variance layers var_primal, var_dx and var_dy");
    if (o.varianceFilterRadius < 0) throw Error("Poisson solve: the variance filter radius must be >= 0");
    const std::size_t n = std::size_t(w) * std::size_t(h);
    for (const std::vector<float>* wv : {in.weightPrimal, in.weightDx, in.weightDy})
        if (wv && wv->size() != n) throw Error("Poisson solve: weight vector size does not match the image");

    SolveReport report;
    std::vector<std::uint8_t> okP, okX, okY;
    std::vector<float> primal = sanitise(*in.primal, report.nonFinite.primal, okP);
    std::vector<float> dx = sanitise(*in.dx, report.nonFinite.dx, okX);
    std::vector<float> dy = sanitise(*in.dy, report.nonFinite.dy, okY);
    // Inputs too large for the device's float32 sums of squares: the same solve scaled by
    // 2^-k (see poisson_gpu.h), the IRLS regulariser with them; undone after the download.
    report.scaleExponent =
        scaleExponentFor(std::max({maxMagnitude(primal), maxMagnitude(dx), maxMagnitude(dy)}));
    if (report.scaleExponent > 0)
        for (std::vector<float>* v : {&primal, &dx, &dy})
            for (float& x : *v) x = std::ldexp(x, -report.scaleExponent);
    std::vector<float> weights(3 * n, 1.0f);
    const bool wl2 = o.method == Reconstruction::WeightedL2;
    const bool wl1 = o.method == Reconstruction::WeightedL1;
    // WL1: each row's inverse box-filtered variance (primal, dx, dy planes; 0 where none is
    // valid, and for the rows past the last column / row, which do not exist), its contrast
    // bounded.
    std::vector<float> varianceWeights;
    if (wl1) {
        NonFiniteCounts& nf = report.nonFinite;
        varianceWeights.assign(3 * n, 0.0f);
        for (std::size_t k = 0; k < 3; ++k) {
            const Image& var = *(k == 0 ? in.varPrimal : k == 1 ? in.varDx : in.varDy);
            const std::vector<float> filtered =
                boxFilteredVariance(var, o.varianceFilterRadius, nf.variance, nf.negativeVariance);
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) {
                    if ((k == 1 && x + 1 == w) || (k == 2 && y + 1 == h)) continue;
                    const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
                    varianceWeights[k * n + i] =
                        static_cast<float>(inverseFilteredVariance(filtered[i], o.varianceEpsilon));
                }
        }
        boundWeightContrast(varianceWeights, o.varianceWeightContrast);
    }
    const auto inverse = [&](const Image& var, std::size_t i) {
        return static_cast<float>(inverseVariance(var, i, o.varianceEpsilon, report.nonFinite));
    };
    for (std::size_t i = 0; i < n; ++i) {
        float* wp = &weights[i];
        float* wx = &weights[n + i];
        float* wy = &weights[2 * n + i];
        auto userWeight = [&](const std::vector<float>* v) {
            if (!v) return 1.0f;
            const float u = (*v)[i];
            if (std::isfinite(u) && u >= 0.0f) return u;
            ++report.nonFinite.weight;
            return 0.0f;
        };
        *wp = userWeight(in.weightPrimal);
        *wx = userWeight(in.weightDx);
        *wy = userWeight(in.weightDy);
        if (wl2) {
            *wp *= inverse(*in.varPrimal, i);
            *wx *= inverse(*in.varDx, i);
            *wy *= inverse(*in.varDy, i);
        }
        if (wl1) {
            *wp *= varianceWeights[i];
            *wx *= varianceWeights[n + i];
            *wy *= varianceWeights[2 * n + i];
        }
        if (!okP[i]) *wp = 0.0f;
        if (!okX[i]) *wx = 0.0f;
        if (!okY[i]) *wy = 0.0f;
    }
    // Kept rows (dropped boundary rows excluded) and the WL2 mean-1 normalisation.
    double sum = 0.0;
    std::size_t rows = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t i =
                static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
            const float rowW[3] = {weights[i], x + 1 < w ? weights[n + i] : 0.0f,
                                   y + 1 < h ? weights[2 * n + i] : 0.0f};
            for (float v : rowW)
                if (v > 0.0f) {
                    sum += v;
                    ++rows;
                }
        }
    if ((wl2 || wl1) && sum > 0.0) {
        const float scale = static_cast<float>(double(rows) / sum);
        for (float& v : weights) v *= scale;
    }
    bool singular = o.alpha == 0.0;
    if (!singular) {
        singular = true;
        for (std::size_t i = 0; i < n && singular; ++i) singular = !(weights[i] > 0.0f);
    }

    std::vector<float> sol;
    if (solvesOnHost(o, singular)) {
        sol = solveOnHost(primal, dx, dy, weights, o, report);
    } else {
        // The host solver needs α > 0 and a primal row: a singular problem goes to the device.
        SolveOptions od = o;
        if (od.solver == GpuSolver::HostPcg) od.solver = GpuSolver::MgPcg;
        sol = solveOnDevice(primal, dx, dy, weights, od, singular, rows, report);
    }
    // Download and fix the weighted mean from the primal. Summing the rows of A x = b gives
    // Σ cp_i x_i = Σ cp_i t_i exactly for every α > 0 (the Laplacian's columns sum to 0), so
    // this shift only removes error along the near-null constant mode, which a float32
    // residual cannot see when α is tiny; for α = 0 it picks the α → 0 limit. L1's final
    // primal weights live on the device (IRLS), so there the shift is for α = 0 only, which
    // L1 rejects anyway.
    out = Image(w, h);
    const bool shiftMean = singular || !isIrls(o.method);
    for (int c = 0; c < 3; ++c) {
        const std::size_t o0 = static_cast<std::size_t>(c) * n;
        if (shiftMean) {
            double sw = 0.0, swd = 0.0, sd = 0.0;
            for (std::size_t i = 0; i < n; ++i) {
                const double d = double(primal[o0 + i]) - sol[o0 + i];
                sw += weights[i];
                swd += weights[i] * d;
                sd += d;
            }
            const double shift = sw > 0.0 ? swd / sw : sd / double(n);
            for (std::size_t i = 0; i < n; ++i) sol[o0 + i] = static_cast<float>(sol[o0 + i] + shift);
        }
        if (report.scaleExponent > 0)
            for (std::size_t i = 0; i < n; ++i) sol[o0 + i] = std::ldexp(sol[o0 + i], report.scaleExponent);
        std::copy(sol.begin() + static_cast<std::ptrdiff_t>(o0),
                  sol.begin() + static_cast<std::ptrdiff_t>(o0 + n), out.plane(c).begin());
    }
    if (o.timer) report.kernels = o.timer->totals();
    report.ms = wall.ms();
    return report;
}

Image reconstruct(const vk::Context& ctx, const Image& primal, const Image& dx, const Image& dy,
                  const Image* varPrimal, const Image* varDx, const Image* varDy, const SolveOptions& options,
                  SolveReport* report) {
    PoissonSolverGpu solver(ctx, primal.width(), primal.height());
    PoissonInput in;
    in.primal = &primal;
    in.dx = &dx;
    in.dy = &dy;
    in.varPrimal = varPrimal;
    in.varDx = varDx;
    in.varDy = varDy;
    Image out;
    const SolveReport r = solver.solve(in, options, out);
    if (report) *report = r;
    return out;
}

}  // namespace gdpt
