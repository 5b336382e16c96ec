// The host's multigrid preconditioner (poisson/host_vcycle.h): what CG needs of it (M⁻¹
// symmetric and positive definite), the same bits for any number of threads, and what it is
// for: on a one-frame solve it cuts CG's iterations several-fold against the diagonal, to the
// same answer.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "poisson/host_vcycle.h"
#include "poisson/poisson_spacetime.h"

namespace gdpt {
namespace {

// A 5-point operator with random positive weights (IRLS gives weights over orders of
// magnitude), 0 past the last column and row, and a screening term.
struct RandomOperator {
    int w, h;
    Field cx, cy, diag;
    RandomOperator(int width, int height, std::uint32_t seed) : w(width), h(height) {
        const std::size_t n = std::size_t(w) * std::size_t(h);
        std::mt19937 rng(seed);
        std::uniform_real_distribution<double> logWeight(-3.0, 1.0), screen(0.005, 0.05);
        cx.resize(n);
        cy.resize(n);
        diag.resize(n);
        for (std::size_t i = 0; i < n; ++i) {
            const std::size_t x = i % std::size_t(w), y = i / std::size_t(w);
            cx[i] = x + 1 < std::size_t(w) ? std::pow(10.0, logWeight(rng)) : 0.0;
            cy[i] = y + 1 < std::size_t(h) ? std::pow(10.0, logWeight(rng)) : 0.0;
        }
        for (std::size_t i = 0; i < n; ++i) {
            double d = screen(rng) + cx[i] + cy[i];
            if (i % std::size_t(w) > 0) d += cx[i - 1];
            if (i >= std::size_t(w)) d += cy[i - std::size_t(w)];
            diag[i] = d;
        }
    }
};

Field randomField(std::size_t n, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> g;
    Field f(n);
    for (double& v : f) v = g(rng);
    return f;
}

double dot(const Field& a, const Field& b) {
    double s = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
    return s;
}

// u·M⁻¹v = v·M⁻¹u and v·M⁻¹v > 0 (the post-smoothing sweeps the colours in the reverse order of
// the pre-smoothing; with the same order the first check fails by orders of magnitude more than
// rounding).
TEST(HostVcycle, IsSymmetricPositiveDefinite) {
    const RandomOperator op(37, 29, 1);
    HostVcycle mg;
    mg.build(op.w, op.h, op.cx, op.cy, op.diag, 1);
    ASSERT_GE(mg.levels(), 5);
    const std::size_t n = op.cx.size();
    for (std::uint32_t seed = 0; seed < 4; ++seed) {
        const Field u = randomField(n, 10 + seed), v = randomField(n, 20 + seed);
        Field mu(n), mv(n);
        mg.apply({&u, &u, &u}, {&mu, &mv, &mv}, {true, false, false}, 1);
        mg.apply({&v, &v, &v}, {&mv, &mv, &mv}, {true, false, false}, 1);
        const double a = dot(u, mv), b = dot(v, mu);
        EXPECT_NEAR(a, b, 1e-11 * std::sqrt(dot(u, mu) * dot(v, mv))) << seed;
        EXPECT_GT(dot(v, mv), 0.0) << seed;
    }
}

// Rows of every level that has more than one range of them go to the threads; each colour reads
// only the other: the same bits for 1, 2 and 3 threads, each channel as if alone.
TEST(HostVcycle, SameBitsForAnyThreadCountAndChannel) {
    const RandomOperator op(300, 200, 2);
    const std::size_t n = op.cx.size();
    const Field r0 = randomField(n, 3), r1 = randomField(n, 4), r2 = randomField(n, 5);
    HostVcycle mg;
    mg.build(op.w, op.h, op.cx, op.cy, op.diag, 1);
    std::array<Field, 3> one{Field(n), Field(n), Field(n)};
    mg.apply({&r0, &r1, &r2}, {&one[0], &one[1], &one[2]}, {true, true, true}, 1);
    for (const std::uint32_t threads : {2u, 3u}) {
        HostVcycle other;
        other.build(op.w, op.h, op.cx, op.cy, op.diag, threads);
        std::array<Field, 3> z{Field(n), Field(n), Field(n)};
        other.apply({&r0, &r1, &r2}, {&z[0], &z[1], &z[2]}, {true, true, true}, threads);
        for (int c = 0; c < 3; ++c) EXPECT_TRUE(z[c] == one[c]) << threads << " threads, channel " << c;
    }
    Field alone(n);
    mg.apply({&r1, &r1, &r1}, {&alone, &alone, &alone}, {false, true, false}, 2);
    EXPECT_TRUE(alone == one[1]);
}

// A one-frame L1 solve of noisy data: multigrid needs at most a fifth of the diagonal's
// iterations (63 against 463 on 2026-12-04; a restriction of ½Pᵀ instead of ¼Pᵀ took 136) and
// reaches the same image (every solve stops at the relative residual 1e-6; they agreed to 1e-5).
TEST(HostVcycle, CutsTheIterationsOfAOneFrameSolveToTheSameAnswer) {
    SpaceTimeProblem p;
    p.width = 160;
    p.height = 120;
    p.frames = 1;
    const std::size_t n = p.pixels();
    std::mt19937 rng(7);
    std::normal_distribution<double> noise(0.0, 0.3);
    for (int c = 0; c < 3; ++c) {
        p.primal[c].resize(n);
        p.dx[c].resize(n);
        p.dy[c].resize(n);
        for (std::size_t i = 0; i < n; ++i) {
            const double x = double(i % 160), y = double(i / 160);
            p.primal[c][i] = 1.0 + 0.5 * std::sin(0.1 * x + c) * std::cos(0.07 * y) + noise(rng);
            p.dx[c][i] = 0.05 * std::cos(0.1 * x + c) * std::cos(0.07 * y) + 0.2 * noise(rng);
            p.dy[c][i] = -0.035 * std::sin(0.1 * x + c) * std::sin(0.07 * y) + 0.2 * noise(rng);
        }
    }
    SpaceTimeOptions o;
    o.tolerance = 1e-6;
    o.innerTolerance = 1e-6;  // every IRLS round solved as far: the rounds see the same weights
    o.multigrid = false;
    SpaceTimeStats jacobi, multigrid;
    const auto xj = solveSpaceTime(p, o, &jacobi);
    o.multigrid = true;
    const auto xm = solveSpaceTime(p, o, &multigrid);
    ASSERT_TRUE(jacobi.converged);
    ASSERT_TRUE(multigrid.converged);
    EXPECT_LE(5 * multigrid.iterations, jacobi.iterations)
        << multigrid.iterations << " against " << jacobi.iterations;
    double worst = 0.0;
    for (int c = 0; c < 3; ++c)
        for (std::size_t i = 0; i < n; ++i) worst = std::max(worst, std::abs(xm[c][i] - xj[c][i]));
    EXPECT_LT(worst, 1e-4);
}

}  // namespace
}  // namespace gdpt
