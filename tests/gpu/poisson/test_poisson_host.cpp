// test_poisson_host.cpp — the host's solver (host-pcg: CG preconditioned by a V-cycle, in
// double precision) against the CPU exact solve and the device's L1, its deadline and progress,
// and that host solves allocate no device fields.
#include <chrono>

#include "poisson_gpu_support.h"
#include "util/error.h"

namespace gdpt {
namespace {

using namespace poisson_test;

// host-pcg (the host's threads, double precision) is the same least-squares solve: L2 and WL2
// against the CPU exact solve (1e-6: a double CG at a relative residual of 1e-9, cond(A) ≲ 100).
TEST_F(PoissonGpu, HostPcgMatchesTheCpuExactSolve) {
    const VarianceProblem v = varianceProblem(26, 19, 91, {0.01, 1.0}, {0.01, 1.0});
    const PoissonInput vars = v.variances();
    for (Reconstruction m : {Reconstruction::L2, Reconstruction::WeightedL2}) {
        SolveOptions o;
        o.solver = GpuSolver::HostPcg;
        o.method = m;
        o.tolerance = 1e-9;
        Image out;
        const SolveReport r = solve(v.primal, v.dx, v.dy, o, out, &vars);
        EXPECT_TRUE(r.converged) << toString(m);
        EXPECT_EQ(r.batches, 0) << "host-pcg ran on the device";
        auto inv = [&](const Image& var) {
            Field f(var.pixelCount());
            for (std::size_t i = 0; i < f.size(); ++i)
                f[i] = 1.0 / ((double(var.plane(0)[i]) + var.plane(1)[i] + var.plane(2)[i]) / 3.0 +
                              o.varianceEpsilon);
            return f;
        };
        for (int c = 0; c < 3; ++c) {
            PoissonProblem p = channelProblem(v.primal, v.dx, v.dy, o.alpha, c);
            if (m == Reconstruction::WeightedL2) {
                // The solver renormalises the weights to mean 1: the same minimiser.
                p.weightPrimal = inv(v.vp);
                p.weightDx = inv(v.vx);
                p.weightDy = inv(v.vy);
            }
            EXPECT_LT(relError(channel(out, c), solvePoissonL2(p, L2Method::Exact)), 1e-6)
                << toString(m) << c;
        }
    }
}

// L1 and WL1 by host-pcg and by the device's mg-pcg: with every IRLS round solved tightly
// both follow the same rounds to the same minimiser (float32 on the device: 1e-3).
TEST_F(PoissonGpu, HostPcgL1IsTheDeviceL1) {
    const VarianceProblem v = varianceProblem(40, 28, 93, {0.001, 0.1}, {0.01, 2.0});
    const PoissonInput vars = v.variances();
    for (Reconstruction m : {Reconstruction::L1, Reconstruction::WeightedL1}) {
        SolveOptions o;
        o.method = m;
        o.tolerance = 1e-6;
        o.irlsInnerTolerance = 1e-6;
        Image device, host;
        solve(v.primal, v.dx, v.dy, o, device, &vars);
        o.solver = GpuSolver::HostPcg;
        const SolveReport r = solve(v.primal, v.dx, v.dy, o, host, &vars);
        EXPECT_EQ(r.irlsIterations, o.irlsIterations);
        EXPECT_TRUE(r.converged);
        for (int c = 0; c < 3; ++c)
            EXPECT_LT(relError(channel(host, c), channel(device, c)), 1e-3)
                << toString(m) << " channel " << c;
    }
    // Power: the same comparison tells L1 from L2.
    SolveOptions l2;
    l2.solver = GpuSolver::HostPcg;
    l2.tolerance = 1e-6;
    SolveOptions l1 = l2;
    l1.method = Reconstruction::L1;
    Image a, b;
    solve(v.primal, v.dx, v.dy, l2, a);
    solve(v.primal, v.dx, v.dy, l1, b);
    EXPECT_GT(relError(channel(a, 0), channel(b, 0)), 1e-2);
}

// host-pcg stops IRLS at a deadline, and its progress reports may stop the solve (an
// interrupt) by throwing.
TEST_F(PoissonGpu, HostPcgStopsAtItsDeadlineAndOnProgress) {
    const NoisyProblem p = noisyProblem(32, 32, 5);
    SolveOptions o;
    o.solver = GpuSolver::HostPcg;
    o.method = Reconstruction::L1;
    o.deadline = std::chrono::steady_clock::now() - std::chrono::seconds(1);
    Image out;
    const SolveReport cut = solve(p.primal, p.dx, p.dy, o, out);
    EXPECT_EQ(cut.irlsIterations, 1);
    EXPECT_TRUE(cut.stoppedAtDeadline);
    o.deadline.reset();
    int calls = 0;
    o.progress = [&](int roundsDone, int rounds, int) {
        EXPECT_EQ(rounds, 6);
        if (++calls == 2) throw Error("stop at round " + std::to_string(roundsDone));
    };
    EXPECT_THROW(solve(p.primal, p.dx, p.dy, o, out), Error);
    EXPECT_EQ(calls, 2);
}

// A solver whose solves run on the host allocates no device memory (the multigrid fields of
// a 3840x2160 image are about 1.4 GB); the first device solve allocates them, a singular
// host-pcg solve (alpha 0) too, since it goes to the device.
TEST_F(PoissonGpu, HostSolvesAllocateNoDeviceFields) {
    const NoisyProblem p = noisyProblem(48, 40, 9);
    PoissonInput in;
    in.primal = &p.primal;
    in.dx = &p.dx;
    in.dy = &p.dy;
    SolveOptions host;
    host.solver = GpuSolver::HostPcg;
    host.method = Reconstruction::L1;
    SolveOptions l2 = host;
    l2.method = Reconstruction::L2;
    const std::uint64_t before = ctx().deviceBytesNow();
    PoissonSolverGpu solver(ctx(), 48, 40, &sharedKernels());
    solver.preparePipelines({host, l2});
    Image out;
    (void)solver.solve(in, host, out);
    (void)solver.solve(in, l2, out);
    EXPECT_EQ(ctx().deviceBytesNow(), before);
    SolveOptions singular = l2;
    singular.alpha = 0.0;
    (void)solver.solve(in, singular, out);
    // 3 channels x 48 x 40 floats, several fields of them.
    EXPECT_GT(ctx().deviceBytesNow(), before + 4 * 3 * 48 * 40 * sizeof(float));
}

}  // namespace
}  // namespace gdpt
