// test_poisson_gpu.cpp — the GPU screened-Poisson solver against the double-precision CPU
// reference (src/poisson/poisson_cpu.h): every kernel on its own, then whole solves
// (exact gradients, CPU exact solve, solver agreement, CG monotonicity, L1 robustness,
// extreme inputs, non-finite inputs, determinism), and the host's solver (host-pcg) against the
// CPU exact solve and the device's L1.
//
// Float tolerances: a kernel output is a sum of ≤ 10 products of float inputs, so its
// rounding error is ≤ ~10·2⁻²⁴·Σ|terms| ≈ 6e-7 Σ|terms|; we allow 1e-5 of the magnitude
// of the terms (values are O(1) here). Solves are compared with the CPU solution in the
// relative 2-norm at 1e-4 after converging to a relative residual of 1e-6: float32 floors
// the residual near 1e-7, and the error is bounded by cond(A)·residual with cond(A) ≲ 100
// for these small grids.
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <random>

#include "gpu_fixture.h"
#include "poisson/poisson_clone.h"
#include "poisson/poisson_cpu.h"
#include "poisson/poisson_gpu.h"
#include "poisson/poisson_irls.h"
#include "poisson_shared.h"
#include "util/error.h"
#include "vk/commands.h"

namespace gdpt {
namespace {

using namespace gpu;

PoissonKernels& sharedKernels() {
    static PoissonKernels k(test::gpuContext());
    return k;
}

Field randomField(int w, int h, unsigned seed, double lo = 0.0, double hi = 1.0) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(lo, hi);
    Field v(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
    for (double& x : v) x = u(rng);
    return v;
}

// Smooth ramp + sharp box + line, different per channel.
Image structuredImage(int w, int h, double scale = 1.0) {
    Image im(w, h);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                double v = 0.5 + 0.3 * std::sin(0.7 * x + c) * std::cos(0.4 * y);
                if (x >= w / 4 && x < w / 2 && y >= h / 3 && y < (2 * h) / 3) v += 2.0 + c;
                if (x == w / 2) v += 0.7;
                im.at(x, y, c) = static_cast<float>(scale * v);
            }
    return im;
}

Image randomImage(int w, int h, unsigned seed, double lo, double hi) {
    Image im(w, h);
    for (int c = 0; c < 3; ++c) {
        const Field f = randomField(w, h, seed + static_cast<unsigned>(c), lo, hi);
        for (std::size_t i = 0; i < f.size(); ++i) im.plane(c)[i] = static_cast<float>(f[i]);
    }
    return im;
}

// Forward differences of an image (dropped rows 0).
void gradients(const Image& im, Image& dx, Image& dy) {
    const int w = im.width(), h = im.height();
    dx = Image(w, h);
    dy = Image(w, h);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                if (x + 1 < w) dx.at(x, y, c) = im.at(x + 1, y, c) - im.at(x, y, c);
                if (y + 1 < h) dy.at(x, y, c) = im.at(x, y + 1, c) - im.at(x, y, c);
            }
}

Field channel(const Image& im, int c) {
    return Field(im.plane(c).begin(), im.plane(c).end());
}

PoissonProblem channelProblem(const Image& primal, const Image& dx, const Image& dy, double alpha, int c) {
    PoissonProblem p;
    p.width = primal.width();
    p.height = primal.height();
    p.alpha = alpha;
    p.primal = channel(primal, c);
    p.dx = channel(dx, c);
    p.dy = channel(dy, c);
    return p;
}

double relError(const Field& a, const Field& b) {
    double num = 0.0, den = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        num += (a[i] - b[i]) * (a[i] - b[i]);
        den += b[i] * b[i];
    }
    return den > 0.0 ? std::sqrt(num / den) : std::sqrt(num);
}

double maxAbs(const Field& a) {
    double m = 0.0;
    for (double v : a) m = std::max(m, std::abs(v));
    return m;
}

// Uploads one double field per channel into a float buffer at a float offset.
void uploadRgb(vk::Buffer& buf, std::uint32_t offset, const std::array<Field, 3>& f) {
    std::vector<float> v;
    for (const Field& c : f)
        for (double x : c) v.push_back(static_cast<float>(x));
    buf.upload(v.data(), v.size() * sizeof(float), std::uint64_t{offset} * sizeof(float));
}

std::vector<float> downloadFloats(const vk::Buffer& buf, std::uint32_t offset, std::size_t count) {
    std::vector<float> v(count);
    buf.download(v.data(), count * sizeof(float), std::uint64_t{offset} * sizeof(float));
    return v;
}

void expectNear(const std::vector<float>& gpu, std::size_t gpuOffset, const Field& cpu, double tol,
                const char* what) {
    const double scale = std::max(1.0, maxAbs(cpu));
    for (std::size_t i = 0; i < cpu.size(); ++i)
        ASSERT_NEAR(gpu[gpuOffset + i], cpu[i], tol * scale) << what << " at " << i;
}

class PoissonGpu : public test::GpuTest {
protected:
    template <typename F>
    void run(PoissonGpuEngine& e, F record) {
        vk::CommandStream s(ctx(), "poisson test");
        VkCommandBuffer cmd = s.begin();
        e.bind();
        record(cmd);
        s.submitAndWait();
    }

    SolveReport solve(const Image& primal, const Image& dx, const Image& dy, const SolveOptions& o,
                      Image& out, const PoissonInput* extra = nullptr) {
        PoissonSolverGpu solver(ctx(), primal.width(), primal.height(), &sharedKernels());
        PoissonInput in = extra ? *extra : PoissonInput{};
        in.primal = &primal;
        in.dx = &dx;
        in.dy = &dy;
        return solver.solve(in, o, out);
    }
};

// A 37x21 problem with random weights: 4 levels (37x21, 19x11, 10x6, 5x3).
struct OperatorCase {
    int w = 37, h = 21;
    double alpha = 0.3;
    std::array<PoissonProblem, 3> problems;
    OperatorCase() {
        for (int c = 0; c < 3; ++c) {
            PoissonProblem& p = problems[static_cast<std::size_t>(c)];
            p.width = w;
            p.height = h;
            p.alpha = alpha;
            const unsigned s = 100u * static_cast<unsigned>(c);
            p.primal = randomField(w, h, s + 1, -1.0, 2.0);
            p.dx = randomField(w, h, s + 2, -1.0, 1.0);
            p.dy = randomField(w, h, s + 3, -1.0, 1.0);
            // Shared weights (the GPU operator is one for all channels).
            p.weightPrimal = randomField(w, h, 7, 0.1, 2.0);
            p.weightDx = randomField(w, h, 8, 0.1, 2.0);
            p.weightDy = randomField(w, h, 9, 0.1, 2.0);
        }
    }
    void upload(PoissonGpuEngine& e) const {
        uploadRgb(e.primal, 0, {problems[0].primal, problems[1].primal, problems[2].primal});
        uploadRgb(e.dx, 0, {problems[0].dx, problems[1].dx, problems[2].dx});
        uploadRgb(e.dy, 0, {problems[0].dy, problems[1].dy, problems[2].dy});
        uploadRgb(e.weights, 0, {problems[0].weightPrimal, problems[0].weightDx, problems[0].weightDy});
    }
};

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

// The structured image, its exact gradients, and a primal with Gaussian noise (σ 0.05).
struct NoisyProblem {
    Image truth, primal, dx, dy;
};
NoisyProblem noisyProblem(int w, int h, unsigned seed) {
    NoisyProblem p;
    p.truth = structuredImage(w, h);
    gradients(p.truth, p.dx, p.dy);
    p.primal = p.truth;
    std::mt19937 rng(seed);
    std::normal_distribution<float> noise(0.0f, 0.05f);
    for (int c = 0; c < 3; ++c)
        for (float& v : p.primal.plane(c)) v += noise(rng);
    return p;
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

// Random primal, gradients and variances (primal variance in [0.01, 1], the gradients'
// in the given ranges) from images seeded seed .. seed + 5.
struct VarianceProblem {
    Image primal, dx, dy, vp, vx, vy;
    [[nodiscard]] PoissonInput variances() const {
        PoissonInput in;
        in.varPrimal = &vp;
        in.varDx = &vx;
        in.varDy = &vy;
        return in;
    }
};
VarianceProblem varianceProblem(int w, int h, unsigned seed, std::array<double, 2> vxRange,
                                std::array<double, 2> vyRange) {
    return {randomImage(w, h, seed, 0.0, 1.0),
            randomImage(w, h, seed + 1, -0.3, 0.3),
            randomImage(w, h, seed + 2, -0.3, 0.3),
            randomImage(w, h, seed + 3, 0.01, 1.0),
            randomImage(w, h, seed + 4, vxRange[0], vxRange[1]),
            randomImage(w, h, seed + 5, vyRange[0], vyRange[1])};
}

// Inverse-variance weights equal the CPU solve with the same row weights.
TEST_F(PoissonGpu, WeightedL2MatchesCpuWithInverseVarianceWeights) {
    const VarianceProblem p0 = varianceProblem(26, 19, 51, {0.01, 1.0}, {0.01, 1.0});
    const Image &primal = p0.primal, &dx = p0.dx, &dy = p0.dy, &vp = p0.vp, &vx = p0.vx, &vy = p0.vy;
    SolveOptions o;
    o.method = Reconstruction::WeightedL2;
    o.tolerance = 1e-6;
    const PoissonInput in = p0.variances();
    Image out;
    const SolveReport r = solve(primal, dx, dy, o, out, &in);
    EXPECT_TRUE(r.converged);
    auto inv = [&](const Image& v) {
        Field f(v.pixelCount());
        for (std::size_t i = 0; i < f.size(); ++i)
            f[i] = 1.0 / ((double(v.plane(0)[i]) + v.plane(1)[i] + v.plane(2)[i]) / 3.0 + o.varianceEpsilon);
        return f;
    };
    for (int c = 0; c < 3; ++c) {
        PoissonProblem p = channelProblem(primal, dx, dy, o.alpha, c);
        p.weightPrimal = inv(vp);
        p.weightDx = inv(vx);
        p.weightDy = inv(vy);
        EXPECT_LT(relError(channel(out, c), solvePoissonL2(p, L2Method::Exact)), 1e-4) << c;
    }
}

// The WL1 variance filter against a direct sum over each clipped box: RGB means, invalid
// values (non-finite, negative) left out of the averages and counted, -1 where a box has
// no valid value.
TEST(BoxFilteredVariance, AveragesTheClippedBoxOfValidValues) {
    const int w = 7, h = 5;
    Image var(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c) var.at(x, y, c) = float(x + 10 * y + c);
    var.at(2, 1, 1) = std::nanf("");
    var.at(5, 3, 0) = -400.0f;  // a negative channel: no variance
    const auto valid = [&](int x, int y) { return !((x == 2 && y == 1) || (x == 5 && y == 3)); };
    for (int radius : {0, 1, 2, 9}) {
        std::size_t nonFinite = 0, negative = 0;
        const std::vector<float> f = boxFilteredVariance(var, radius, nonFinite, negative);
        EXPECT_EQ(nonFinite, 1u);
        EXPECT_EQ(negative, 1u);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                double sum = 0.0;
                int count = 0;
                for (int yy = std::max(0, y - radius); yy <= std::min(h - 1, y + radius); ++yy)
                    for (int xx = std::max(0, x - radius); xx <= std::min(w - 1, x + radius); ++xx)
                        if (valid(xx, yy)) {
                            sum += xx + 10.0 * yy + 1.0;  // mean of the channels x+10y+c
                            ++count;
                        }
                const float expected = count > 0 ? float(sum / count) : -1.0f;
                EXPECT_NEAR(f[static_cast<std::size_t>(y * w + x)], expected, 1e-4f)
                    << "radius " << radius << " at " << x << "," << y;
            }
    }
}

// A firefly's variance beside zeros: the running sums take it in and out again, and the boxes
// after it, all zeros, must average to about 0 (a rounding residue far below WL1's ε = 1e-4),
// never to a negative residue (which WL1 read as a missing variance and gave its rows weight 0).
// Before the clamp: -2.6e-13 at every one of these pixels.
TEST(BoxFilteredVariance, ZerosAfterAFireflyAverageToZero) {
    const int w = 40, h = 3;
    Image var(w, h);
    for (int y = 0; y < h; ++y)
        for (int c = 0; c < 3; ++c) {
            var.at(3, y, c) = 5703.4f;
            var.at(4, y, c) = 0.1f + 0.01f * float(c);
            var.at(5, y, c) = 13928.7f;
        }
    std::size_t nonFinite = 0, negative = 0;
    const std::vector<float> f = boxFilteredVariance(var, 3, nonFinite, negative);
    for (int y = 0; y < h; ++y)
        for (int x = 9; x < w; ++x) {
            EXPECT_GE(f[std::size_t(y * w + x)], 0.0f) << x << "," << y;
            EXPECT_LT(f[std::size_t(y * w + x)], 1e-9f) << x << "," << y;
        }
    for (float v : f) EXPECT_GE(v, 0.0f);
}

// boundWeightContrast: the positive weights clamped into [m/K, m·K] around their median m
// (the upper middle one of an even count), zeros kept, K < 1 (or 0) changing nothing.
TEST(BoundWeightContrast, ClampsAroundTheMedianOfThePositiveWeights) {
    // Positive: 0.01, 0.5, 1, 2, 3, 400 (six: the upper middle is 2).
    const std::vector<float> w = {0.5f, 0.0f, 400.0f, 2.0f, 0.01f, 0.0f, 1.0f, 3.0f};
    std::vector<float> b = w;
    boundWeightContrast(b, 4.0);
    EXPECT_EQ(b, (std::vector<float>{0.5f, 0.0f, 8.0f, 2.0f, 0.5f, 0.0f, 1.0f, 3.0f}));
    b = w;
    boundWeightContrast(b, 1.0);  // every positive weight becomes the median
    EXPECT_EQ(b, (std::vector<float>{2.0f, 0.0f, 2.0f, 2.0f, 2.0f, 0.0f, 2.0f, 2.0f}));
    for (double none : {0.0, 0.5}) {
        b = w;
        boundWeightContrast(b, none);
        EXPECT_EQ(b, w) << none;
    }
    std::vector<float> zeros(5, 0.0f);
    boundWeightContrast(zeros, 4.0);
    EXPECT_EQ(zeros, std::vector<float>(5, 0.0f));
}

// The inverse box-filtered variances of a problem's three row families as WL1 weights them
// (the rows past the last column / row do not exist: 0), their contrast bounded by K.
std::vector<float> wl1Weights(const VarianceProblem& p, const SolveOptions& o, double contrast) {
    const int w = p.primal.width(), h = p.primal.height();
    const std::size_t n = p.primal.pixelCount();
    std::vector<float> all(3 * n, 0.0f);
    const Image* vars[3] = {&p.vp, &p.vx, &p.vy};
    for (std::size_t k = 0; k < 3; ++k) {
        std::size_t nonFinite = 0, negative = 0;
        const std::vector<float> f =
            boxFilteredVariance(*vars[k], o.varianceFilterRadius, nonFinite, negative);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                if (!((k == 1 && x + 1 == w) || (k == 2 && y + 1 == h))) {
                    const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
                    all[k * n + i] = static_cast<float>(1.0 / (double(f[i]) + o.varianceEpsilon));
                }
    }
    boundWeightContrast(all, contrast);
    return all;
}

// WL1 is L1 (IRLS) whose rows are weighted by the inverse of the box-filtered variances,
// bounded to SolveOptions::varianceWeightContrast around their median: the same solve as L1
// given those weights explicitly (bounded by default, raw with the bound off), and not the
// unweighted L1. The variances here span 200x, so the default bound of 4 changes the weights.
TEST_F(PoissonGpu, WeightedL1IsL1WithFilteredInverseVarianceWeights) {
    const VarianceProblem p0 = varianceProblem(26, 19, 71, {0.001, 0.1}, {0.01, 2.0});
    const Image &primal = p0.primal, &dx = p0.dx, &dy = p0.dy;
    const std::size_t n = primal.pixelCount();
    const PoissonInput vars = p0.variances();
    Image l1;
    SolveOptions plain;
    plain.method = Reconstruction::L1;
    plain.tolerance = 1e-6;
    solve(primal, dx, dy, plain, l1);
    Image bounded;
    for (double contrast : {kDefaultVarianceWeightContrast, 0.0}) {
        SolveOptions o = plain;
        o.method = Reconstruction::WeightedL1;
        o.varianceWeightContrast = contrast;
        Image wl1, explicitWeights;
        const SolveReport r = solve(primal, dx, dy, o, wl1, &vars);
        EXPECT_EQ(r.irlsIterations, o.irlsIterations);
        const std::vector<float> all = wl1Weights(p0, o, contrast);
        const std::vector<float> wp(all.begin(), all.begin() + std::ptrdiff_t(n)),
            wx(all.begin() + std::ptrdiff_t(n), all.begin() + std::ptrdiff_t(2 * n)),
            wy(all.begin() + std::ptrdiff_t(2 * n), all.end());
        PoissonInput weighted;
        weighted.weightPrimal = &wp;
        weighted.weightDx = &wx;
        weighted.weightDy = &wy;
        solve(primal, dx, dy, plain, explicitWeights, &weighted);
        for (int c = 0; c < 3; ++c) {
            Field a = channel(wl1, c), b = channel(explicitWeights, c), u = channel(l1, c);
            EXPECT_LT(relError(a, b), 1e-4) << "contrast " << contrast << ", channel " << c;
            EXPECT_GT(relError(a, u), 1e-3) << c << ": the weights should change the solution";
            if (contrast == 0.0) {
                EXPECT_GT(relError(a, channel(bounded, c)), 1e-3)
                    << c << ": the bound should change the solution";
            }
        }
        if (contrast != 0.0) bounded = wl1;
    }
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
