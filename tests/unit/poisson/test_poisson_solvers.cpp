// test_poisson_solvers.cpp — every L2 solver against the exact sparse LDLᵀ solution, exact
// gradients reconstructing their image, CG's monotone A-norm error, and singular (α = 0)
// systems.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "poisson/poisson_cpu.h"
#include "poisson_test_util.h"

namespace gdpt {
namespace {

using test::exactProblem;
using test::randomField;
using test::relativeError;
using test::structuredField;

// Log-uniform values over 12 decades, 1e-6 .. 1e6 (HDR radiance and worse).
Field hdrField(int w, int h, unsigned seed) {
    Field v = randomField(w, h, seed, -6.0, 6.0);
    for (double& x : v) x = std::pow(10.0, x);
    return v;
}

IterativeOptions tight(int maxIterations) {
    IterativeOptions o;
    o.maxIterations = maxIterations;
    o.tolerance = 1e-14;
    return o;
}

// Exact gradients + primal of an image: the energy is 0 at the image, so it is the unique
// minimiser for any α > 0. Solved from x = 0 so that the solvers have real work to do.
TEST(Reconstruction, ExactGradientsAndPrimalReturnTheImage) {
    struct Case {
        const char* name;
        int w, h;
        Field image;
    };
    const Case cases[] = {{"random", 13, 11, randomField(13, 11, 7)},
                          {"structured", 16, 9, structuredField(16, 9)},
                          {"hdr", 12, 12, hdrField(12, 12, 8)}};
    for (const Case& c : cases)
        for (double alpha : {1e-4, 0.2, 10.0}) {
            SCOPED_TRACE(std::string(c.name) + " alpha=" + std::to_string(alpha));
            const PoissonProblem p = exactProblem(c.image, c.w, c.h, alpha);
            const PoissonOperator op = makeOperator(p);
            const Field b = computeRhs(p);
            // LDLᵀ is backward stable: relative error ≲ ε·κ(A), κ ≈ λmax/λmin ≤ (8 + α²)/α²
            // (Gershgorin bound over the smallest, constant-mode eigenvalue α²).
            const double exactTolerance = std::max(1e-10, 1e-15 * (8.0 + alpha * alpha) / (alpha * alpha));
            EXPECT_LT(relativeError(solveExact(op, b), c.image), exactTolerance);
            Field x(c.image.size(), 0.0);
            solveCg(op, b, x, tight(2000));
            EXPECT_LT(relativeError(x, c.image), 1e-6);
            x.assign(c.image.size(), 0.0);
            solvePcgMultigrid(op, b, x, tight(300));
            EXPECT_LT(relativeError(x, c.image), 1e-6);
            x.assign(c.image.size(), 0.0);
            solveMultigrid(op, b, x, tight(2000));
            EXPECT_LT(relativeError(x, c.image), 1e-6);
            // The whole-channel entry point (warm start from the primal) as well.
            EXPECT_LT(relativeError(solvePoissonL2(p, L2Method::PcgMultigrid), c.image), 1e-6);
        }
}

struct SizeCase {
    int w, h;
};

class SolverAgreement : public ::testing::TestWithParam<SizeCase> {};

// Noisy, inconsistent data (independent random primal and gradients, random weights): the
// solution is not known in closed form, so the iterative solvers must match LDLᵀ.
TEST_P(SolverAgreement, IterativeSolversMatchExact) {
    const auto [w, h] = GetParam();
    for (double alpha : {1e-4, 0.2, 10.0})
        for (int variant = 0; variant < 3; ++variant) {
            SCOPED_TRACE("alpha=" + std::to_string(alpha) + " variant=" + std::to_string(variant));
            PoissonProblem p;
            p.width = w;
            p.height = h;
            p.alpha = alpha;
            p.primal = variant == 1 ? structuredField(w, h) : randomField(w, h, 3);
            p.dx = randomField(w, h, 4, -1.0, 1.0);
            p.dy = randomField(w, h, 5, -1.0, 1.0);
            if (variant == 2) {  // weighted (e.g. inverse variances), 3 decades
                p.weightPrimal = hdrField(w, h, 6);
                for (double& v : p.weightPrimal) v = 1.0 + std::log10(v) / 6.0 + 1e-3;
                p.weightDx = randomField(w, h, 7, 0.01, 10.0);
                p.weightDy = randomField(w, h, 8, 0.01, 10.0);
            }
            const Field exact = solvePoissonL2(p, L2Method::Exact);
            EXPECT_LT(relativeError(solvePoissonL2(p, L2Method::Cg, tight(5000)), exact), 1e-6);
            EXPECT_LT(relativeError(solvePoissonL2(p, L2Method::PcgMultigrid, tight(500)), exact), 1e-6);
            EXPECT_LT(relativeError(solvePoissonL2(p, L2Method::Multigrid, tight(3000)), exact), 1e-6);
            // Jacobi's rate is 1 − O(α²/4) on smooth error: only test it where it converges
            // in a few thousand sweeps.
            if (alpha >= 0.2) {
                EXPECT_LT(relativeError(solvePoissonL2(p, L2Method::Jacobi, tight(20000)), exact), 1e-6);
            }
        }
}

INSTANTIATE_TEST_SUITE_P(Sizes, SolverAgreement,
                         ::testing::Values(SizeCase{1, 1}, SizeCase{1, 9}, SizeCase{8, 1}, SizeCase{2, 2},
                                           SizeCase{5, 3}, SizeCase{16, 16}, SizeCase{17, 9},
                                           SizeCase{31, 33}));

// CG minimises the A-norm of the error over nested Krylov spaces, so ‖x_k − x*‖_A (= the
// residual's A⁻¹-norm) never increases (the residual's 2-norm may).
TEST(Cg, ANormErrorIsNonIncreasing) {
    for (double alpha : {1e-4, 0.2}) {
        PoissonProblem p = exactProblem(structuredField(20, 15), 20, 15, alpha);
        p.dx = randomField(20, 15, 9, -1.0, 1.0);  // make it inconsistent
        const PoissonOperator op = makeOperator(p);
        const Field b = computeRhs(p);
        const Field exact = solveExact(op, b);
        auto aNormError = [&](const Field& x) {
            Field e(x.size()), ae;
            for (std::size_t i = 0; i < x.size(); ++i) e[i] = x[i] - exact[i];
            applyA(op, e, ae);
            return std::sqrt(std::max(0.0, dot(e, ae)));
        };
        Field x(p.size(), 0.0);
        double previous = aNormError(x);
        const double initial = previous;
        int calls = 0;
        IterativeOptions o = tight(400);
        o.onIterate = [&](int, const Field& xk) {
            const double current = aNormError(xk);
            EXPECT_LE(current, previous * (1.0 + 1e-9) + 1e-13 * initial);
            previous = current;
            ++calls;
        };
        solveCg(op, b, x, o);
        EXPECT_GT(calls, 10);
        EXPECT_LT(previous, 1e-8 * initial);
    }
}

// α = 0: A is singular; the solution is defined up to a constant, fixed by the primal's mean.
TEST(Singular, AlphaZeroKeepsPrimalMeanAndGradients) {
    const int w = 9, h = 7;
    const Field image = structuredField(w, h);
    PoissonProblem p = exactProblem(image, w, h, 0.0);
    for (double& t : p.primal) t += 0.25;  // biased primal: the mean must follow it
    for (L2Method m : {L2Method::Exact, L2Method::Cg, L2Method::PcgMultigrid, L2Method::Multigrid}) {
        const Field x = solvePoissonL2(p, m, tight(3000));
        Field expected = image;
        for (double& v : expected) v += 0.25;
        EXPECT_LT(relativeError(x, expected), 1e-6) << static_cast<int>(m);
    }
}

}  // namespace
}  // namespace gdpt
