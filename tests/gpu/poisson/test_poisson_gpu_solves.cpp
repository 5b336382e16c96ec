// test_poisson_gpu_solves.cpp — whole GPU screened-Poisson solves against the CPU reference:
// exact gradients, the CPU exact solve for every solver, CG's monotonicity, multigrid's
// iterations, L1's robustness and deadline, extreme scales and shapes, α = 0, non-finite inputs,
// bit-reproducibility, prepared pipelines, seamless cloning (poisson_gpu_support.h has the
// tolerances).
#include <chrono>
#include <cstring>

#include "poisson/poisson_clone.h"
#include "poisson_gpu_support.h"
#include "util/error.h"

namespace gdpt {
namespace {

using namespace poisson_test;

// Exact gradients and primal of an image reproduce it, from a zero initial guess.
TEST_F(PoissonGpu, ExactGradientsReturnTheImage) {
    const Image im = structuredImage(45, 31);
    Image dx, dy;
    gradients(im, dx, dy);
    for (double alpha : {1e-4, 0.2, 10.0}) {
        SolveOptions o;
        o.alpha = alpha;
        o.tolerance = 1e-6;
        o.warmStart = false;
        Image out;
        const SolveReport r = solve(im, dx, dy, o, out);
        EXPECT_TRUE(r.converged) << "alpha " << alpha;
        for (int c = 0; c < 3; ++c)
            EXPECT_LT(relError(channel(out, c), channel(im, c)), 1e-4) << "alpha " << alpha << " c " << c;
    }
}

// GPU L2 equals the CPU exact solve; all four solvers agree.
TEST_F(PoissonGpu, L2MatchesCpuExactForEverySolver) {
    struct Case {
        Image primal, dx, dy;
    };
    std::vector<Case> cases(2);
    cases[0].primal = randomImage(24, 17, 11, 0.0, 1.0);
    cases[0].dx = randomImage(24, 17, 21, -0.5, 0.5);
    cases[0].dy = randomImage(24, 17, 31, -0.5, 0.5);
    const Image truth = structuredImage(33, 20);
    gradients(truth, cases[1].dx, cases[1].dy);
    cases[1].primal = truth;
    for (std::size_t i = 0; i < cases[1].primal.pixelCount(); ++i)
        cases[1].primal.plane(0)[i] += 0.3f * static_cast<float>(i % 7) - 0.9f;  // structured noise
    for (const Case& k : cases)
        for (GpuSolver s : {GpuSolver::MgPcg, GpuSolver::Cg, GpuSolver::Jacobi, GpuSolver::Mg}) {
            SolveOptions o;
            o.solver = s;
            o.tolerance = 1e-6;
            o.maxIterations = 20000;
            Image out;
            const SolveReport r = solve(k.primal, k.dx, k.dy, o, out);
            EXPECT_TRUE(r.converged) << toString(s);
            EXPECT_LT(r.residual, 1e-5) << toString(s);
            for (int c = 0; c < 3; ++c) {
                const PoissonProblem p = channelProblem(k.primal, k.dx, k.dy, o.alpha, c);
                const Field exact = solvePoissonL2(p, L2Method::Exact);
                EXPECT_LT(relError(channel(out, c), exact), 1e-4) << toString(s) << " channel " << c;
            }
        }
}

// MG-PCG needs far fewer iterations than CG (the point of the preconditioner).
TEST_F(PoissonGpu, MultigridPreconditionerCutsIterations) {
    const Image truth = structuredImage(96, 80);
    Image dx, dy;
    gradients(truth, dx, dy);
    const Image primal = randomImage(96, 80, 5, 0.0, 3.0);
    SolveOptions o;
    Image out;
    o.solver = GpuSolver::Cg;
    const SolveReport cg = solve(primal, dx, dy, o, out);
    o.solver = GpuSolver::MgPcg;
    const SolveReport pcg = solve(primal, dx, dy, o, out);
    EXPECT_TRUE(cg.converged && pcg.converged);
    EXPECT_LT(pcg.iterations * 3, cg.iterations) << "mg-pcg " << pcg.iterations << " cg " << cg.iterations;
}

// CG minimises ‖x − x*‖_A over growing Krylov spaces: that error never increases, checked
// by stopping after k = 1..12 iterations (the iteration sequence does not depend on where a
// solve stops). The stand-alone V-cycle is a contraction: its residual history decreases.
TEST_F(PoissonGpu, CgErrorAndMultigridResidualAreMonotone) {
    const Image primal = randomImage(32, 32, 3, 0.0, 1.0);
    const Image dx = randomImage(32, 32, 13, -0.3, 0.3), dy = randomImage(32, 32, 23, -0.3, 0.3);
    const double alpha = 0.05;
    std::array<PoissonOperator, 3> ops;
    std::array<Field, 3> exact;
    for (int c = 0; c < 3; ++c) {
        const PoissonProblem p = channelProblem(primal, dx, dy, alpha, c);
        ops[static_cast<std::size_t>(c)] = makeOperator(p);
        exact[static_cast<std::size_t>(c)] = solveExact(ops[static_cast<std::size_t>(c)], computeRhs(p));
    }
    for (GpuSolver s : {GpuSolver::Cg, GpuSolver::MgPcg}) {
        std::array<double, 3> previous{1e300, 1e300, 1e300};
        for (int k = 1; k <= 12; ++k) {
            SolveOptions o;
            o.solver = s;
            o.alpha = alpha;
            o.tolerance = 1e-7;
            o.maxIterations = k;
            Image out;
            solve(primal, dx, dy, o, out);
            for (std::size_t c = 0; c < 3; ++c) {
                Field e = channel(out, static_cast<int>(c)), ae;
                for (std::size_t i = 0; i < e.size(); ++i) e[i] -= exact[c][i];
                applyA(ops[c], e, ae);
                const double energy = std::sqrt(std::max(0.0, dot(e, ae)));
                // Float noise floor: 1e-5 of the initial error.
                EXPECT_LE(energy, previous[c] * (1.0 + 1e-4) + 1e-6) << toString(s) << " k " << k;
                previous[c] = energy;
            }
        }
    }
    SolveOptions o;
    o.solver = GpuSolver::Mg;
    o.alpha = alpha;
    o.tolerance = 1e-6;
    o.keepHistory = true;
    Image out;
    const SolveReport r = solve(primal, dx, dy, o, out);
    ASSERT_GE(r.history.size(), 3u);
    for (std::size_t k = 1; k < r.history.size(); ++k)
        for (std::size_t c = 0; c < 3; ++c)
            EXPECT_LT(r.history[k][c], r.history[k - 1][c]) << "V-cycle " << k;
}

// L1 (IRLS) shrugs off a few grossly wrong gradients that L2 smears over the image.
TEST_F(PoissonGpu, L1RecoversCorruptedGradientsBetterThanL2) {
    const int w = 48, h = 48;
    NoisyProblem p = noisyProblem(w, h, 17);
    const Image& truth = p.truth;
    const Image& primal = p.primal;
    Image& dx = p.dx;
    const Image& dy = p.dy;
    for (int k = 0; k < 12; ++k) {
        const int x = 3 + (k * 7) % (w - 6), y = 2 + (k * 11) % (h - 4);
        for (int c = 0; c < 3; ++c) dx.at(x, y, c) += 5.0f;
    }
    auto rmse = [&](const Image& im) {
        double s = 0.0;
        for (int c = 0; c < 3; ++c)
            for (std::size_t i = 0; i < im.pixelCount(); ++i) {
                const double d = im.plane(c)[i] - truth.plane(c)[i];
                s += d * d;
            }
        return std::sqrt(s / (3.0 * double(im.pixelCount())));
    };
    SolveOptions o;
    Image l2, l1;
    solve(primal, dx, dy, o, l2);
    o.method = Reconstruction::L1;
    const SolveReport r = solve(primal, dx, dy, o, l1);
    EXPECT_EQ(r.irlsIterations, o.irlsIterations);
    const double e2 = rmse(l2), e1 = rmse(l1);
    EXPECT_LT(e1, 0.25 * e2) << "L1 rmse " << e1 << " L2 rmse " << e2;
}

// A deadline (a timed render's budget) stops IRLS between rounds: already passed, only the
// first round runs and the report says so; an hour away, all six run. The early result is
// the first round's (an L2-like solve, weights of the largest regulariser): finite, and not
// the six rounds' result.
TEST_F(PoissonGpu, L1StopsReweightingAtItsDeadline) {
    const NoisyProblem p = noisyProblem(32, 32, 5);
    const Image &primal = p.primal, &dx = p.dx, &dy = p.dy;
    SolveOptions o;
    o.method = Reconstruction::L1;
    Image full, early;
    o.deadline = std::chrono::steady_clock::now() + std::chrono::hours(1);
    const SolveReport all = solve(primal, dx, dy, o, full);
    EXPECT_EQ(all.irlsIterations, o.irlsIterations);
    EXPECT_FALSE(all.stoppedAtDeadline);
    o.deadline = std::chrono::steady_clock::now() - std::chrono::seconds(1);
    const SolveReport cut = solve(primal, dx, dy, o, early);
    EXPECT_EQ(cut.irlsIterations, 1);
    EXPECT_TRUE(cut.stoppedAtDeadline);
    double differs = 0.0;
    for (int c = 0; c < 3; ++c)
        for (std::size_t i = 0; i < early.pixelCount(); ++i) {
            ASSERT_TRUE(std::isfinite(early.plane(c)[i]));
            differs = std::max(differs, double(std::abs(early.plane(c)[i] - full.plane(c)[i])));
        }
    EXPECT_GT(differs, 0.0) << "the rounds left out change the result";
}

// Extreme scales, α, and degenerate sizes agree with the CPU exact solve.
TEST_F(PoissonGpu, StableAcrossScalesAlphasAndShapes) {
    struct Shape {
        int w, h;
    };
    for (Shape sh : {Shape{1, 1}, Shape{1, 37}, Shape{41, 1}, Shape{17, 13}, Shape{64, 9}})
        for (double scale : {1e-6, 1.0, 1e6})
            for (double alpha : {1e-4, 0.2, 10.0}) {
                const Image truth = structuredImage(sh.w, sh.h, scale);
                Image dx, dy;
                gradients(truth, dx, dy);
                Image primal = truth;
                for (int c = 0; c < 3; ++c)
                    for (std::size_t i = 0; i < primal.pixelCount(); ++i)
                        primal.plane(c)[i] *=
                            1.0f + 0.1f * static_cast<float>((i * 7 + static_cast<std::size_t>(c)) % 5);
                SolveOptions o;
                o.alpha = alpha;
                o.tolerance = 1e-6;
                o.maxIterations = 500;
                Image out;
                const SolveReport r = solve(primal, dx, dy, o, out);
                for (int c = 0; c < 3; ++c) {
                    const PoissonProblem p = channelProblem(primal, dx, dy, alpha, c);
                    const Field exact = solvePoissonL2(p, L2Method::Exact);
                    EXPECT_LT(relError(channel(out, c), exact), 1e-3)
                        << sh.w << "x" << sh.h << " scale " << scale << " alpha " << alpha << " residual "
                        << r.residual << " its " << r.iterations;
                }
            }
}

// α = 0: the Laplacian alone is singular; the mean is taken from the primal (CPU
// solvePoissonL2 does the same).
TEST_F(PoissonGpu, AlphaZeroFixesTheMeanFromThePrimal) {
    const Image primal = randomImage(29, 22, 41, 0.0, 2.0);
    const Image dx = randomImage(29, 22, 42, -0.2, 0.2), dy = randomImage(29, 22, 43, -0.2, 0.2);
    SolveOptions o;
    o.alpha = 0.0;
    o.tolerance = 1e-5;  // singular A: the float32 floor is ~1e-6 here
    Image out;
    const SolveReport r = solve(primal, dx, dy, o, out);
    EXPECT_TRUE(r.converged);
    for (int c = 0; c < 3; ++c) {
        const Field exact = solvePoissonL2(channelProblem(primal, dx, dy, 0.0, c), L2Method::Exact);
        EXPECT_LT(relError(channel(out, c), exact), 1e-4) << c;
    }
    // host-pcg needs a primal row: the singular problem goes to the device, the same solve.
    o.solver = GpuSolver::HostPcg;
    Image host;
    const SolveReport hr = solve(primal, dx, dy, o, host);
    EXPECT_GT(hr.batches, 0);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(channel(host, c), channel(out, c)) << c;
}

// NaN/Inf inputs are counted, replaced with zero-weight rows, and do not spread.
TEST_F(PoissonGpu, NonFiniteInputsAreCountedAndContained) {
    const Image truth = structuredImage(30, 20);
    Image dx, dy;
    gradients(truth, dx, dy);
    Image primal = truth;
    primal.at(5, 5, 0) = std::nanf("");
    primal.at(6, 5, 1) = INFINITY;
    dx.at(10, 10, 2) = -INFINITY;
    dy.at(20, 3, 0) = std::nanf("");
    for (GpuSolver s : {GpuSolver::MgPcg, GpuSolver::HostPcg})
        for (Reconstruction m : {Reconstruction::L2, Reconstruction::L1}) {
            SolveOptions o;
            o.method = m;
            o.solver = s;
            Image out;
            const SolveReport r = solve(primal, dx, dy, o, out);
            EXPECT_EQ(r.nonFinite.primal, 2u);
            EXPECT_EQ(r.nonFinite.dx, 1u);
            EXPECT_EQ(r.nonFinite.dy, 1u);
            double worst = 0.0;
            for (int c = 0; c < 3; ++c)
                for (std::size_t i = 0; i < out.pixelCount(); ++i) {
                    ASSERT_TRUE(std::isfinite(out.plane(c)[i]));
                    worst = std::max(worst, double(std::abs(out.plane(c)[i] - truth.plane(c)[i])));
                }
            // Exact data elsewhere: the dropped rows lose nothing the other rows do not pin down.
            EXPECT_LT(worst, 1e-2) << toString(m) << " " << toString(s);
        }
}

TEST_F(PoissonGpu, SolvesAreBitReproducible) {
    const Image primal = randomImage(57, 43, 61, 0.0, 1.0);
    const Image dx = randomImage(57, 43, 62, -0.3, 0.3), dy = randomImage(57, 43, 63, -0.3, 0.3);
    for (Reconstruction m : {Reconstruction::L2, Reconstruction::L1}) {
        SolveOptions o;
        o.method = m;
        Image a, b;
        solve(primal, dx, dy, o, a);
        // The second solve reuses the pipeline variants the first one compiled.
        const std::size_t variants = sharedKernels().variantCount();
        solve(primal, dx, dy, o, b);
        EXPECT_EQ(variants, sharedKernels().variantCount());
        for (int c = 0; c < 3; ++c)
            EXPECT_EQ(0, std::memcmp(a.plane(c).data(), b.plane(c).data(), a.pixelCount() * sizeof(float)));
    }
}

// preparePipelines creates every variant a solve of another size then dispatches: a solve
// after it creates none (each method with fresh kernels, so that nothing is left over from
// other tests), and it did create some.
TEST_F(PoissonGpu, PreparedPipelinesCoverALaterSolve) {
    const Image primal = randomImage(57, 43, 71, 0.0, 1.0);
    const Image dx = randomImage(57, 43, 72, -0.3, 0.3), dy = randomImage(57, 43, 73, -0.3, 0.3);
    const Image var = randomImage(57, 43, 74, 0.001, 0.01);
    for (Reconstruction m :
         {Reconstruction::L2, Reconstruction::L1, Reconstruction::WeightedL2, Reconstruction::WeightedL1}) {
        PoissonKernels kernels(ctx());
        PoissonSolverGpu solver(ctx(), primal.width(), primal.height(), &kernels);
        SolveOptions o;
        o.method = m;
        solver.preparePipelines({o});
        const std::size_t prepared = kernels.variantCount();
        EXPECT_GT(prepared, 5u) << toString(m);
        PoissonInput in;
        in.primal = &primal;
        in.dx = &dx;
        in.dy = &dy;
        in.varPrimal = in.varDx = in.varDy = &var;
        Image out;
        (void)solver.solve(in, o, out);
        EXPECT_EQ(prepared, kernels.variantCount()) << toString(m);
    }
}

// Seamless cloning (Pérez et al. 2003, eq. 7): the target is untouched outside Ω and the
// discrete Laplacian of the result equals the source's at every pixel of Ω. The solve stops
// at relative residual 1e-5 of ‖b‖ (b ~ O(1) per pixel here), so per-pixel Laplacians
// agree to ~1e-4; we allow 1e-3.
TEST_F(PoissonGpu, SeamlessCloneKeepsTargetAndMatchesSourceLaplacian) {
    const Image source = structuredImage(20, 16);
    Image target = randomImage(40, 32, 81, 0.0, 0.2);
    Image mask(20, 16);
    for (int y = 2; y < 14; ++y)
        for (int x = 2; x < 18; ++x)
            if ((x - 10) * (x - 10) / 64.0 + (y - 8) * (y - 8) / 36.0 < 1.0) mask.at(x, y, 0) = 1.0f;
    CloneOptions o;
    o.offsetX = 10;
    o.offsetY = 8;
    SolveReport report;
    const Image result = seamlessClone(ctx(), source, target, mask, o, &report);
    EXPECT_TRUE(report.converged);
    int insideCount = 0;
    for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 40; ++x) {
            const int sx = x - 10, sy = y - 8;
            const bool inside = sx >= 0 && sy >= 0 && sx < 20 && sy < 16 && mask.at(sx, sy, 0) > 0.5f;
            for (int c = 0; c < 3; ++c) {
                if (!inside) {
                    ASSERT_EQ(result.at(x, y, c), target.at(x, y, c)) << x << "," << y;
                    continue;
                }
                const double lapF = 4.0 * result.at(x, y, c) - result.at(x - 1, y, c) -
                                    result.at(x + 1, y, c) - result.at(x, y - 1, c) - result.at(x, y + 1, c);
                const double lapS = 4.0 * source.at(sx, sy, c) - source.at(sx - 1, sy, c) -
                                    source.at(sx + 1, sy, c) - source.at(sx, sy - 1, c) -
                                    source.at(sx, sy + 1, c);
                EXPECT_NEAR(lapF, lapS, 1e-3) << x << "," << y << " c " << c;
            }
            insideCount += inside ? 1 : 0;
        }
    EXPECT_GT(insideCount, 100);
    // Mixed gradients run through the same path and stay finite and equal outside.
    o.mixed = true;
    const Image mixed = seamlessClone(ctx(), source, target, mask, o);
    for (int c = 0; c < 3; ++c)
        for (std::size_t i = 0; i < mixed.pixelCount(); ++i) ASSERT_TRUE(std::isfinite(mixed.plane(c)[i]));
}

}  // namespace
}  // namespace gdpt
