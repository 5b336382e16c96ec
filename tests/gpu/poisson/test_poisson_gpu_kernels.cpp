// test_poisson_gpu_kernels.cpp — every kernel of the GPU screened-Poisson solver on its own
// against the double-precision CPU reference (src/poisson/poisson_cpu.h), with descriptors and
// through device addresses (poisson_gpu_support.h has the tolerances).
#include <cstring>

#include "poisson/poisson_irls.h"
#include "poisson_gpu_support.h"

namespace gdpt {
namespace {

using namespace poisson_test;

TEST_F(PoissonGpu, SetupAndCoarseningMatchCpu) {
    OperatorCase oc;
    PoissonGpuEngine e(ctx(), oc.w, oc.h, &sharedKernels());
    ASSERT_EQ(e.levels().size(), 4u);
    oc.upload(e);
    run(e, [&](VkCommandBuffer cmd) {
        e.recordSetup(cmd, static_cast<float>(oc.alpha * oc.alpha), false, nullptr);
        e.recordCoarsenAll(cmd, nullptr);
    });
    PoissonOperator op = makeOperator(oc.problems[0]);
    const std::vector<float> rhs = downloadFloats(e.rhs, 0, 3 * e.pixels());
    for (int c = 0; c < 3; ++c)
        expectNear(rhs, static_cast<std::size_t>(c) * e.pixels(),
                   computeRhs(oc.problems[static_cast<std::size_t>(c)]), 1e-5, "rhs");
    for (const PoissonLevel& l : e.levels()) {
        const std::vector<float> coef = downloadFloats(e.coef, l.offset, 3 * l.pixels());
        expectNear(coef, 0, op.cx, 1e-5, "cx");
        expectNear(coef, l.pixels(), op.cy, 1e-5, "cy");
        expectNear(coef, 2 * l.pixels(), op.cp, 1e-5, "cp");
        if (l.offset != e.levels().back().offset) op = coarsenOperator(op);
    }
}

TEST_F(PoissonGpu, ApplyResidualSmoothersRestrictProlongMatchCpu) {
    OperatorCase oc;
    PoissonGpuEngine e(ctx(), oc.w, oc.h, &sharedKernels());
    oc.upload(e);
    run(e, [&](VkCommandBuffer cmd) {
        e.recordSetup(cmd, static_cast<float>(oc.alpha * oc.alpha), false, nullptr);
        e.recordCoarsenAll(cmd, nullptr);
    });
    const PoissonOperator op0 = makeOperator(oc.problems[0]);
    const PoissonOperator op1 = coarsenOperator(op0);
    const std::size_t n = e.pixels();
    std::array<Field, 3> x, b, xc;
    for (int c = 0; c < 3; ++c) {
        x[static_cast<std::size_t>(c)] = randomField(oc.w, oc.h, 40u + static_cast<unsigned>(c), -2.0, 2.0);
        b[static_cast<std::size_t>(c)] = randomField(oc.w, oc.h, 50u + static_cast<unsigned>(c), -2.0, 2.0);
        xc[static_cast<std::size_t>(c)] =
            randomField(op1.width, op1.height, 60u + static_cast<unsigned>(c), -1.0, 1.0);
    }
    const PoissonLevel& l1 = e.levels()[1];
    auto reset = [&] {
        uploadRgb(e.x, 0, x);
        uploadRgb(e.b, 0, b);
        uploadRgb(e.x, l1.offset, xc);
    };
    // A x and b − A x.
    reset();
    run(e, [&](VkCommandBuffer cmd) { e.recordResidual(cmd, 0, kPoissonFlagApplyOnly, nullptr); });
    std::vector<float> out = downloadFloats(e.r, 0, 3 * n);
    for (std::size_t c = 0; c < 3; ++c) {
        Field y;
        applyA(op0, x[c], y);
        expectNear(out, c * n, y, 1e-5, "A x");
    }
    run(e, [&](VkCommandBuffer cmd) { e.recordResidual(cmd, 0, 0u, nullptr); });
    out = downloadFloats(e.r, 0, 3 * n);
    for (std::size_t c = 0; c < 3; ++c) {
        Field r;
        residual(op0, b[c], x[c], r);
        expectNear(out, c * n, r, 1e-5, "b - A x");
    }
    // Fused residual restriction and plain restriction of the stored residual.
    run(e, [&](VkCommandBuffer cmd) { e.recordRestrict(cmd, 0, 0u, nullptr); });
    out = downloadFloats(e.b, l1.offset, 3 * l1.pixels());
    for (std::size_t c = 0; c < 3; ++c) {
        Field r, rc;
        residual(op0, b[c], x[c], r);
        restrictFullWeighting(oc.w, oc.h, r, rc);
        expectNear(out, c * l1.pixels(), rc, 1e-5, "R (b - A x)");
    }
    run(e, [&](VkCommandBuffer cmd) { e.recordRestrict(cmd, 0, kPoissonFlagPlain, nullptr); });
    std::vector<float> plain = downloadFloats(e.b, l1.offset, 3 * l1.pixels());
    for (std::size_t i = 0; i < plain.size(); ++i) ASSERT_NEAR(plain[i], out[i], 1e-5);
    // Prolongation x += P x_H.
    run(e, [&](VkCommandBuffer cmd) { e.recordProlong(cmd, 0, nullptr); });
    out = downloadFloats(e.x, 0, 3 * n);
    for (std::size_t c = 0; c < 3; ++c) {
        Field f = x[c];
        prolongate(oc.w, oc.h, xc[c], f);
        expectNear(out, c * n, f, 1e-5, "x + P x_H");
    }
    // One red-black Gauss-Seidel sweep (red then black half-sweep).
    reset();
    run(e, [&](VkCommandBuffer cmd) {
        e.recordSmooth(cmd, 0, 0u, 0u, 0.8f, nullptr);
        e.recordSmooth(cmd, 0, 0u, 1u, 0.8f, nullptr);
    });
    out = downloadFloats(e.x, 0, 3 * n);
    for (std::size_t c = 0; c < 3; ++c) {
        Field f = x[c];
        gaussSeidelRedBlackSweep(op0, b[c], f, true);
        expectNear(out, c * n, f, 1e-5, "RB-GS sweep");
    }
    // Fused correction: black-first sweep reading x + P x_H equals prolongate + sweep.
    reset();
    run(e, [&](VkCommandBuffer cmd) {
        e.recordSmooth(cmd, 0, kPoissonFlagCorrect, 1u, 0.8f, nullptr);
        e.recordSmooth(cmd, 0, 0u, 0u, 0.8f, nullptr);
    });
    out = downloadFloats(e.x, 0, 3 * n);
    for (std::size_t c = 0; c < 3; ++c) {
        Field f = x[c];
        prolongate(oc.w, oc.h, xc[c], f);
        gaussSeidelRedBlackSweep(op0, b[c], f, false);
        expectNear(out, c * n, f, 1e-5, "prolongate + black-first sweep");
    }
    // One damped Jacobi sweep X -> R.
    reset();
    run(e, [&](VkCommandBuffer cmd) {
        e.recordSmooth(cmd, 0, kPoissonFlagJacobi | kPoissonFlagToR, 0u, 0.8f, nullptr);
    });
    out = downloadFloats(e.r, 0, 3 * n);
    for (std::size_t c = 0; c < 3; ++c) {
        Field f = x[c];
        jacobiSweep(op0, b[c], f, 0.8);
        expectNear(out, c * n, f, 1e-5, "Jacobi sweep");
    }
}

TEST_F(PoissonGpu, IrlsWeightsMatchCpu) {
    OperatorCase oc;
    PoissonGpuEngine e(ctx(), oc.w, oc.h, &sharedKernels());
    oc.upload(e);
    // Input weights all 1: every kept row counts.
    std::vector<float> ones(3 * e.pixels(), 1.0f);
    e.weights.uploadVector(ones);
    RgbPoissonProblem rgb;
    rgb.width = oc.w;
    rgb.height = oc.h;
    rgb.alpha = oc.alpha;
    std::array<Field, 3> x;
    for (std::size_t c = 0; c < 3; ++c) {
        rgb.primal[c] = oc.problems[c].primal;
        rgb.dx[c] = oc.problems[c].dx;
        rgb.dy[c] = oc.problems[c].dy;
        x[c] = randomField(oc.w, oc.h, 70u + static_cast<unsigned>(c), -1.0, 2.0);
    }
    uploadRgb(e.sol, 0, x);
    const double reg = 0.05;
    const int rows = oc.w * oc.h + (oc.w - 1) * oc.h + oc.w * (oc.h - 1);
    run(e, [&](VkCommandBuffer cmd) {
        e.recordIrlsWeights(cmd, static_cast<float>(oc.alpha * oc.alpha), static_cast<float>(reg), nullptr);
        e.recordScalars(cmd, kPoissonModeIrls, 0u, 0u, 0.0f, static_cast<float>(rows), nullptr);
    });
    const IrlsWeights cpu = computeIrlsWeights(rgb, x, reg);
    PoissonScalars sc{};
    e.scalars.download(&sc, sizeof(sc));
    std::vector<float> raw = downloadFloats(e.irls, 0, 3 * e.pixels());
    for (float& v : raw) v *= sc.irlsScale;
    expectNear(raw, 0, cpu.primal, 1e-5, "IRLS primal weight");
    expectNear(raw, e.pixels(), cpu.dx, 1e-5, "IRLS dx weight");
    expectNear(raw, 2 * e.pixels(), cpu.dy, 1e-5, "IRLS dy weight");
}

// The device-address build of the kernels (used when a field exceeds maxStorageBufferRange)
// computes exactly what the descriptor build computes: same bits for every solver, L1 and
// WL2, on an odd size with several levels.
TEST_F(PoissonGpu, DeviceAddressKernelsGiveTheSameBitsAsDescriptorKernels) {
    const int w = 67, h = 45;
    const Image primal = randomImage(w, h, 71, 0.0, 1.0);
    const Image dx = randomImage(w, h, 72, -0.3, 0.3), dy = randomImage(w, h, 73, -0.3, 0.3);
    const Image var = randomImage(w, h, 74, 0.01, 0.2);
    PoissonInput in;
    in.primal = &primal;
    in.dx = &dx;
    in.dy = &dy;
    in.varPrimal = in.varDx = in.varDy = &var;
    PoissonSolverGpu byDescriptor(ctx(), w, h, &sharedKernels(), PoissonAddressing::Descriptors);
    PoissonSolverGpu byAddress(ctx(), w, h, &sharedKernels(), PoissonAddressing::DeviceAddress);
    ASSERT_EQ(byAddress.engine().addressing(), PoissonAddressing::DeviceAddress);
    const std::vector<std::pair<Reconstruction, GpuSolver>> cases = {
        {Reconstruction::L2, GpuSolver::MgPcg},  {Reconstruction::L2, GpuSolver::Cg},
        {Reconstruction::L2, GpuSolver::Jacobi}, {Reconstruction::L2, GpuSolver::Mg},
        {Reconstruction::L1, GpuSolver::MgPcg},  {Reconstruction::WeightedL2, GpuSolver::MgPcg}};
    for (const auto& [method, solverKind] : cases) {
        SolveOptions o;
        o.method = method;
        o.solver = solverKind;
        Image a, b;
        byDescriptor.engine().bind();
        const SolveReport ra = byDescriptor.solve(in, o, a);
        byAddress.engine().bind();
        const SolveReport rb = byAddress.solve(in, o, b);
        EXPECT_TRUE(ra.converged) << toString(method) << " " << toString(solverKind);
        EXPECT_EQ(ra.iterations, rb.iterations) << toString(method) << " " << toString(solverKind);
        for (int c = 0; c < 3; ++c)
            EXPECT_EQ(0, std::memcmp(a.plane(c).data(), b.plane(c).data(), a.pixelCount() * sizeof(float)))
                << toString(method) << " " << toString(solverKind) << " channel " << c;
    }
}

// 4096x4096 (the largest size): every multigrid field is ~256 MiB, beyond lavapipe's
// 128 MiB maxStorageBufferRange, so the engine switches to device addresses by itself, and
// exact gradients of a structured image come back as the image. Tolerance: the solve stops
// at relative residual 1e-4 (the default), and with α = 0.2 the operator's condition number
// is ≤ 1 + 8/α² = 201, so the relative error is ≤ 201·1e-4 ≈ 2e-2 in the worst case; the
// multigrid error is far smaller in practice, and we require 2e-3 so that a broken level or
// an index overflow past 2^31 bytes (which corrupts a large block of pixels) fails.
TEST_F(PoissonGpu, Solves4096SquaredThroughDeviceAddresses) {
    const int n = 4096;
    if (std::uint64_t{4} * n * n * 3 * 4 / 3 <= ctx().info().maxStorageBufferRange)
        GTEST_SKIP() << "this device binds 4096x4096 fields as descriptors";
    const Image im = structuredImage(n, n);
    Image dx, dy;
    gradients(im, dx, dy);
    PoissonSolverGpu solver(ctx(), n, n, &sharedKernels());
    EXPECT_EQ(solver.engine().addressing(), PoissonAddressing::DeviceAddress);
    PoissonInput in;
    in.primal = &im;
    in.dx = &dx;
    in.dy = &dy;
    SolveOptions o;
    o.warmStart = false;  // from zero, so the answer is not the initial guess
    Image out;
    const SolveReport r = solver.solve(in, o, out);
    EXPECT_TRUE(r.converged);
    EXPECT_LE(r.residual, 1e-4);
    for (int c = 0; c < 3; ++c) {
        EXPECT_LT(relError(channel(out, c), channel(im, c)), 2e-3) << "channel " << c;
        // The last pixel (highest addresses of every field) is right too.
        const std::size_t last = out.pixelCount() - 1;
        EXPECT_NEAR(out.plane(c)[last], im.plane(c)[last], 0.05) << "channel " << c;
    }
}

}  // namespace
}  // namespace gdpt
