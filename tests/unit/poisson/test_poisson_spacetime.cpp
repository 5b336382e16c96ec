// The space-time screened Poisson solver (poisson/poisson_spacetime.h): its PCG against an
// exact sparse factorisation; one frame is the 2D problem of poisson_cpu.h; β = 0 decouples the
// frames; consistent data (gradients and temporal differences of one sequence) is recovered
// exactly by L2 and L1; an L1 solve shrugs off an outlier that L2 smears; temporal rows cut
// frame-to-frame noise; temporal rows along motion (each pixel's partner in the next frame)
// solve the least-squares problem they state, built here row by row; the result is the same bits
// for any number of threads; mixed rows (the change of dx, dy along the motion) solve the
// least-squares problem of their rows and recover consistent data; bad input is refused.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>

#include "poisson/poisson_spacetime.h"
#include "poisson_test_util.h"
#include "util/error.h"

namespace gdpt {
namespace {

// A smooth moving pattern: frame f of a structured image shifted by f/2 pixel in x, plus a
// brightness ramp over time; channel c scaled by 1 + c/4.
double truth(int x, int y, int f, int c) {
    const double xs = x - 0.5 * f;
    return (1.0 + 0.25 * c) * (0.6 + 0.3 * std::sin(0.5 * xs) * std::cos(0.3 * y) + 0.05 * f +
                               (xs > 3 && xs < 6 && y > 2 && y < 5 ? 1.0 : 0.0));
}

SpaceTimeProblem consistentProblem(int w, int h, int frames) {
    SpaceTimeProblem p;
    p.width = w;
    p.height = h;
    p.frames = frames;
    const std::size_t np = std::size_t(w) * h, n = np * frames;
    for (int c = 0; c < 3; ++c) {
        p.primal[c].resize(n);
        p.dx[c].assign(n, 0.0);
        p.dy[c].assign(n, 0.0);
        p.dt[c].assign(np * (frames - 1), 0.0);
        for (int f = 0; f < frames; ++f)
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) {
                    const std::size_t i = f * np + std::size_t(y) * w + x;
                    p.primal[c][i] = truth(x, y, f, c);
                    if (x + 1 < w) p.dx[c][i] = truth(x + 1, y, f, c) - truth(x, y, f, c);
                    if (y + 1 < h) p.dy[c][i] = truth(x, y + 1, f, c) - truth(x, y, f, c);
                    if (f + 1 < frames) p.dt[c][i] = truth(x, y, f + 1, c) - truth(x, y, f, c);
                }
    }
    return p;
}

// Independent noise of standard deviation `sigma` on every row's target.
SpaceTimeProblem noisy(SpaceTimeProblem p, double sigma, unsigned seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> n(0.0, sigma);
    for (int c = 0; c < 3; ++c)
        for (Field* f : {&p.primal[c], &p.dx[c], &p.dy[c], &p.dt[c]})
            for (double& v : *f) v += n(rng);
    return p;
}

double maxDiff(const Field& a, const Field& b) {
    double m = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) m = std::max(m, std::abs(a[i] - b[i]));
    return m;
}

// L2 solved to a relative residual of 1e-12: what the comparisons with exact answers take.
SpaceTimeOptions tightL2() {
    SpaceTimeOptions o;
    o.l1 = false;
    o.tolerance = 1e-12;
    return o;
}

TEST(SpaceTimePoisson, PcgMatchesTheExactFactorisation) {
    const SpaceTimeProblem p = noisy(consistentProblem(9, 7, 4), 0.2, 1);
    const SpaceTimeOptions o = tightL2();
    SpaceTimeStats s;
    const auto x = solveSpaceTime(p, o, &s);
    EXPECT_TRUE(s.converged);
    EXPECT_EQ(s.irlsIterations, 1);
    for (int c = 0; c < 3; ++c) EXPECT_LT(maxDiff(x[c], solveSpaceTimeExactL2(p, c)), 1e-9) << c;
}

TEST(SpaceTimePoisson, OneFrameIsThe2dProblem) {
    const int w = 11, h = 8;
    const std::vector<double> image = test::structuredField(w, h);
    PoissonProblem p2 = test::exactProblem(image, w, h, 0.3);
    std::mt19937 rng(4);
    std::normal_distribution<double> n(0.0, 0.3);
    for (double& v : p2.primal) v += n(rng);
    for (double& v : p2.dx) v += n(rng);
    SpaceTimeProblem p;
    p.width = w;
    p.height = h;
    p.frames = 1;
    p.alpha = 0.3;
    for (int c = 0; c < 3; ++c) {
        p.primal[c] = p2.primal;
        p.dx[c] = p2.dx;
        p.dy[c] = p2.dy;
    }
    const Field reference = solvePoissonL2(p2, L2Method::Exact);
    for (int c = 0; c < 3; ++c) EXPECT_LT(maxDiff(solveSpaceTimeExactL2(p, c), reference), 1e-10);
    const SpaceTimeOptions o = tightL2();
    EXPECT_LT(maxDiff(solveSpaceTime(p, o)[1], reference), 1e-9);
}

TEST(SpaceTimePoisson, BetaZeroDecouplesTheFrames) {
    SpaceTimeProblem p = noisy(consistentProblem(6, 5, 3), 0.3, 2);
    p.beta = 0.0;
    const Field joint = solveSpaceTimeExactL2(p, 0);
    for (int f = 0; f < 3; ++f) {
        PoissonProblem q;
        q.width = 6;
        q.height = 5;
        q.alpha = p.alpha;
        const auto part = [&](const Field& all) {
            return Field(all.begin() + f * 30, all.begin() + (f + 1) * 30);
        };
        q.primal = part(p.primal[0]);
        q.dx = part(p.dx[0]);
        q.dy = part(p.dy[0]);
        EXPECT_LT(maxDiff(part(joint), solvePoissonL2(q, L2Method::Exact)), 1e-10) << f;
    }
}

TEST(SpaceTimePoisson, ConsistentDataIsRecoveredByL2AndL1) {
    const SpaceTimeProblem p = consistentProblem(12, 9, 5);
    for (const bool l1 : {false, true}) {
        SpaceTimeOptions o;
        o.l1 = l1;
        o.tolerance = 1e-10;
        SpaceTimeProblem start = p;
        for (int c = 0; c < 3; ++c) start.initial[c].assign(p.size(), 0.0);  // far from the answer
        const auto x = solveSpaceTime(start, o);
        for (int c = 0; c < 3; ++c) EXPECT_LT(maxDiff(x[c], p.primal[c]), 1e-6) << (l1 ? "L1 " : "L2 ") << c;
    }
}

TEST(SpaceTimePoisson, L1IgnoresAnOutlierThatL2Smears) {
    // Exact gradients and differences, primal exact but for one very bright pixel in frame 2
    // (a firefly): L2 spreads part of it over the neighbourhood, L1 hardly moves.
    SpaceTimeProblem p = consistentProblem(10, 10, 4);
    const std::size_t spike = 2 * 100 + 5 * 10 + 5;
    const double clean = p.primal[0][spike];
    for (int c = 0; c < 3; ++c) p.primal[c][spike] += 50.0;
    SpaceTimeOptions l2;
    l2.l1 = false;
    SpaceTimeOptions l1;
    const double errL2 = std::abs(solveSpaceTime(p, l2)[0][spike] - clean);
    const double errL1 = std::abs(solveSpaceTime(p, l1)[0][spike] - clean);
    EXPECT_GT(errL2, 0.01);
    EXPECT_LT(errL1, 0.2 * errL2) << "L2 " << errL2 << ", L1 " << errL1;
}

TEST(SpaceTimePoisson, TemporalRowsCutFrameToFrameNoise) {
    // Noisy primal and spatial gradients per frame, exact temporal differences: the temporal
    // error (of I_f+1 − I_f against the truth's) of the space-time solve is far below that of
    // frames solved apart (β = 0): 0.18 of it with this seed (one temporal row per pixel
    // against four noisy spatial ones); 0.3 leaves room for another noise draw.
    const SpaceTimeProblem exact = consistentProblem(12, 10, 6);
    SpaceTimeProblem p = noisy(exact, 0.15, 9);
    p.dt = exact.dt;
    const auto temporalError = [&](const Field& x) {
        double e = 0.0;
        const std::size_t np = 120;
        for (std::size_t i = 0; i + np < x.size(); ++i) {
            const double d = (x[i + np] - x[i]) - exact.dt[0][i];
            e += d * d;
        }
        return e;
    };
    SpaceTimeProblem apart = p;
    apart.beta = 0.0;
    const double joint = temporalError(solveSpaceTimeExactL2(p, 0));
    const double separate = temporalError(solveSpaceTimeExactL2(apart, 0));
    EXPECT_LT(joint, 0.3 * separate) << joint << " vs " << separate;
}

// Frames 1.. of `all` as the window, with frame 0 as the fixed previous frame and its dt.
SpaceTimeProblem afterFirstFrame(const SpaceTimeProblem& all) {
    const std::size_t np = all.pixels(), frames = std::size_t(all.frames);
    SpaceTimeProblem p;
    p.width = all.width;
    p.height = all.height;
    p.frames = all.frames - 1;
    const auto from = [](const Field& f, std::size_t a, std::size_t b) {
        return Field(f.begin() + std::ptrdiff_t(a), f.begin() + std::ptrdiff_t(b));
    };
    for (int c = 0; c < 3; ++c) {
        p.primal[c] = from(all.primal[c], np, frames * np);
        p.dx[c] = from(all.dx[c], np, frames * np);
        p.dy[c] = from(all.dy[c], np, frames * np);
        p.dt[c] = from(all.dt[c], np, (frames - 1) * np);
        p.previous[c] = from(all.primal[c], 0, np);
        p.dtPrevious[c] = from(all.dt[c], 0, np);
    }
    return p;
}

// Consistent data (the primal is the sequence its rows describe) is recovered exactly by L2
// and L1 solves started from zero.
void expectRecoveredFromZero(SpaceTimeProblem p) {
    for (int c = 0; c < 3; ++c) p.initial[c].assign(p.size(), 0.0);
    for (const bool l1 : {false, true}) {
        SpaceTimeOptions o;
        o.l1 = l1;
        o.tolerance = 1e-10;
        const auto x = solveSpaceTime(p, o);
        for (int c = 0; c < 3; ++c) EXPECT_LT(maxDiff(x[c], p.primal[c]), 1e-6) << (l1 ? "l1 " : "l2 ") << c;
    }
}

TEST(SpaceTimePoisson, TheFrameBeforeTiesTheWindowToIt) {
    // Frames 1..4 of a consistent sequence, with frame 0 given as the fixed previous frame:
    // recovered exactly (L2 and L1) from a zero start.
    const SpaceTimeProblem p = afterFirstFrame(consistentProblem(8, 6, 5));
    expectRecoveredFromZero(p);
    // Noisy data: the PCG solve with the boundary rows matches the exact factorisation.
    SpaceTimeProblem q = noisy(p, 0.2, 5);
    for (int c = 0; c < 3; ++c) q.initial[c].clear();
    const SpaceTimeOptions o = tightL2();
    const auto x = solveSpaceTime(q, o);
    for (int c = 0; c < 3; ++c) EXPECT_LT(maxDiff(x[c], solveSpaceTimeExactL2(q, c)), 1e-9) << c;
    // The boundary matters: without it, frame 0 of the window moves.
    SpaceTimeProblem free = q;
    for (int c = 0; c < 3; ++c) free.previous[c].clear(), free.dtPrevious[c].clear();
    EXPECT_GT(maxDiff(solveSpaceTimeExactL2(free, 0), x[0]), 1e-3);
}

// The L2 minimiser of a problem's energy (poisson_spacetime.h) for channel c, from its rows
// written out one by one as a dense least-squares system and solved by QR: an answer that
// shares no code with the solver's operator.
Field denseLeastSquares(const SpaceTimeProblem& p, int c) {
    const std::size_t np = p.pixels(), n = p.size(), w = std::size_t(p.width);
    std::vector<std::vector<std::pair<std::size_t, double>>> rows;
    std::vector<double> targets;
    // A row of weight u enters as √u times itself (energy u·e²).
    const auto row = [&](std::vector<std::pair<std::size_t, double>> r, double t, const Field& weights,
                         std::size_t at) {
        const double s = weights.empty() ? 1.0 : std::sqrt(weights[at]);
        for (auto& entry : r) entry.second *= s;
        rows.push_back(std::move(r));
        targets.push_back(s * t);
    };
    for (std::size_t i = 0; i < n; ++i) {
        const std::size_t f = i / np, k = i % np;
        row({{i, p.alpha}}, p.alpha * p.primal[c][i], p.weightPrimal, i);
        if (k % w + 1 < w) row({{i + 1, 1.0}, {i, -1.0}}, p.dx[c][i], p.weightDx, i);
        if (k + w < np) row({{i + w, 1.0}, {i, -1.0}}, p.dy[c][i], p.weightDy, i);
        if (f + 1 < std::size_t(p.frames)) {
            const auto partnerOf = [&](std::size_t at) {
                return p.temporalPartner.empty() ? std::uint32_t(at % np) : p.temporalPartner[at];
            };
            const std::uint32_t to = partnerOf(i);
            if (to != kNoTemporalPartner)
                row({{(f + 1) * np + to, p.beta}, {i, -p.beta}}, p.beta * p.dt[c][i], p.weightDt, i);
            // Mixed rows where i and its neighbour i+s are carried side by side.
            const double g = p.gamma;
            const std::size_t next = (f + 1) * np + to, x = k % w, y = k / w, tx = to % w, ty = to / w;
            const std::size_t h = np / w;
            if (g > 0.0 && to != kNoTemporalPartner && x + 1 < w && tx + 1 < w && partnerOf(i + 1) == to + 1)
                row({{next + 1, g}, {next, -g}, {i + 1, -g}, {i, g}}, g * p.dxt[c][i], p.weightDxt, i);
            if (g > 0.0 && to != kNoTemporalPartner && y + 1 < h && ty + 1 < h && partnerOf(i + w) == to + w)
                row({{next + w, g}, {next, -g}, {i + w, -g}, {i, g}}, g * p.dyt[c][i], p.weightDyt, i);
        }
    }
    for (std::size_t j = 0; j < p.previous[c].size(); ++j) {
        const std::uint32_t to = p.previousPartner.empty() ? std::uint32_t(j) : p.previousPartner[j];
        if (to != kNoTemporalPartner)
            row({{to, p.beta}}, p.beta * (p.previous[c][j] + p.dtPrevious[c][j]), p.weightDtPrevious, j);
        // Mixed rows to the previous frame, where j and j+s are carried side by side.
        if (p.dxtPrevious[c].empty() || to == kNoTemporalPartner) continue;
        const auto partnerOf = [&](std::size_t at) {
            return p.previousPartner.empty() ? std::uint32_t(at) : p.previousPartner[at];
        };
        const double g = p.gamma;
        const std::size_t x = j % w, y = j / w, tx = to % w, ty = to / w, h = np / w;
        if (x + 1 < w && tx + 1 < w && partnerOf(j + 1) == to + 1)
            row({{to + 1, g}, {to, -g}}, g * (p.previous[c][j + 1] - p.previous[c][j] + p.dxtPrevious[c][j]),
                p.weightDxtPrevious, j);
        if (y + 1 < h && ty + 1 < h && partnerOf(j + w) == to + w)
            row({{to + w, g}, {to, -g}}, g * (p.previous[c][j + w] - p.previous[c][j] + p.dytPrevious[c][j]),
                p.weightDytPrevious, j);
    }
    Eigen::MatrixXd a = Eigen::MatrixXd::Zero(Eigen::Index(rows.size()), Eigen::Index(n));
    Eigen::VectorXd b(Eigen::Index(rows.size()));
    for (std::size_t r = 0; r < rows.size(); ++r) {
        for (const auto& [col, v] : rows[r]) a(Eigen::Index(r), Eigen::Index(col)) += v;
        b[Eigen::Index(r)] = targets[r];
    }
    const Eigen::VectorXd x = a.colPivHouseholderQr().solve(b);
    return Field(x.data(), x.data() + n);
}

// Frames 1..3 of consistentProblem's window as the unknowns and frame 0 as the fixed previous
// frame; random partners (a quarter of them none) in both kinds of temporal rows.
SpaceTimeProblem withRandomPartners(unsigned seed) {
    SpaceTimeProblem p = afterFirstFrame(noisy(consistentProblem(6, 5, 4), 0.3, seed));
    const std::size_t np = p.pixels();
    std::mt19937 rng(seed);
    const auto partner = [&] { return rng() % 4 == 0 ? kNoTemporalPartner : std::uint32_t(rng() % np); };
    for (std::size_t i = 0; i < 2 * np; ++i) p.temporalPartner.push_back(partner());
    for (std::size_t j = 0; j < np; ++j) p.previousPartner.push_back(partner());
    return p;
}

TEST(SpaceTimePoisson, MotionPartnersSolveTheLeastSquaresOfTheirRows) {
    for (const unsigned seed : {1u, 2u}) {
        const SpaceTimeProblem p = withRandomPartners(seed);
        const SpaceTimeOptions o = tightL2();
        const auto x = solveSpaceTime(p, o);
        for (int c = 0; c < 3; ++c) {
            const Field dense = denseLeastSquares(p, c);
            EXPECT_LT(maxDiff(x[c], dense), 1e-8) << "seed " << seed << " channel " << c;
            EXPECT_LT(maxDiff(solveSpaceTimeExactL2(p, c), dense), 1e-8)
                << "seed " << seed << " channel " << c;
        }
        // The partners matter: the same rows at the same pixel give another answer.
        SpaceTimeProblem same = p;
        same.temporalPartner.clear();
        same.previousPartner.clear();
        EXPECT_GT(maxDiff(solveSpaceTime(same, o)[0], x[0]), 1e-3);
        EXPECT_LT(maxDiff(solveSpaceTime(same, o)[0], denseLeastSquares(same, 0)), 1e-8);
    }
}

TEST(SpaceTimePoisson, IdentityPartnersAreTheSamePixel) {
    const SpaceTimeProblem p = withRandomPartners(3);
    SpaceTimeProblem a = p, b = p;
    a.temporalPartner.clear();
    a.previousPartner.clear();
    for (std::size_t i = 0; i < b.temporalPartner.size(); ++i) b.temporalPartner[i] = std::uint32_t(i % 30);
    for (std::size_t j = 0; j < b.previousPartner.size(); ++j) b.previousPartner[j] = std::uint32_t(j);
    for (const bool l1 : {false, true}) {
        SpaceTimeOptions o;
        o.l1 = l1;
        const auto xa = solveSpaceTime(a, o), xb = solveSpaceTime(b, o);
        for (int c = 0; c < 3; ++c) EXPECT_EQ(xa[c], xb[c]) << c;
    }
}

TEST(SpaceTimePoisson, DifferencesAlongTheMotionRecoverAMovingPattern) {
    // A pattern moving one pixel right per frame; its differences along the motion are 0.05
    // (the brightness ramp), its same-pixel differences are large. Rows along the motion (the
    // pixel that enters at the left edge has none) recover the frames exactly, L2 and L1.
    const int w = 9, h = 6, frames = 4;
    const auto pattern = [](int x, int y, int f, int c) {
        const int xs = x - f;
        return (1.0 + 0.25 * c) * (0.5 + 0.4 * std::sin(0.9 * xs + 0.3 * y) + 0.05 * f);
    };
    SpaceTimeProblem p = consistentProblem(w, h, frames);
    const std::size_t np = std::size_t(w) * h;
    p.temporalPartner.assign(np * (frames - 1), kNoTemporalPartner);
    for (int c = 0; c < 3; ++c)
        for (int f = 0; f < frames; ++f)
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) {
                    const std::size_t i = f * np + std::size_t(y) * w + x;
                    p.primal[c][i] = pattern(x, y, f, c);
                    p.dx[c][i] = x + 1 < w ? pattern(x + 1, y, f, c) - pattern(x, y, f, c) : 0.0;
                    p.dy[c][i] = y + 1 < h ? pattern(x, y + 1, f, c) - pattern(x, y, f, c) : 0.0;
                    if (f + 1 == frames) continue;
                    if (x + 1 < w) {
                        p.temporalPartner[i] = std::uint32_t(y * w + x + 1);
                        p.dt[c][i] = pattern(x + 1, y, f + 1, c) - pattern(x, y, f, c);
                    } else {
                        p.dt[c][i] = 1e3;  // no row: never read
                    }
                }
    expectRecoveredFromZero(p);
}

// Partners one pixel to the right (the motion of a pattern), with a few missing and a few
// elsewhere, so that some pairs of neighbours are carried rigidly and some are not; noisy mixed
// targets.
SpaceTimeProblem withMixedRows(unsigned seed) {
    SpaceTimeProblem p = noisy(consistentProblem(7, 6, 4), 0.3, seed);
    const std::size_t np = p.pixels(), w = 7;
    std::mt19937 rng(seed);
    p.temporalPartner.resize(np * 3);
    for (std::size_t i = 0; i < p.temporalPartner.size(); ++i) {
        const std::size_t k = i % np;
        const unsigned r = rng() % 8;
        p.temporalPartner[i] = r == 0 || k % w + 1 == w ? kNoTemporalPartner
                               : r == 1                 ? std::uint32_t(rng() % np)
                                                        : std::uint32_t(k + 1);
    }
    std::normal_distribution<double> n(0.0, 0.3);
    p.gamma = 0.7;
    for (int c = 0; c < 3; ++c) {
        p.dxt[c].resize(np * 3);
        p.dyt[c].resize(np * 3);
        for (double& v : p.dxt[c]) v = n(rng);
        for (double& v : p.dyt[c]) v = n(rng);
    }
    return p;
}

// The solve with the V-cycles coupled by block Gauss-Seidel over the frames (the default), with
// them as block Jacobi, with the diagonal preconditioner and the exact factorisation, each
// against the dense least-squares solve of the rows written out; returns the first.
std::array<Field, 3> expectDenseLeastSquares(const SpaceTimeProblem& p, unsigned seed) {
    const SpaceTimeOptions o = tightL2();
    SpaceTimeStats coupled, blocks;
    const auto x = solveSpaceTime(p, o, &coupled);
    EXPECT_TRUE(coupled.coupledFrames);
    SpaceTimeOptions jacobiBlocks = o;
    jacobiBlocks.coupleFrames = false;
    const auto xb = solveSpaceTime(p, jacobiBlocks, &blocks);
    EXPECT_FALSE(blocks.coupledFrames);
    EXPECT_LT(coupled.iterations, blocks.iterations) << "seed " << seed;
    SpaceTimeOptions diagonal = o;
    diagonal.multigrid = false;
    const auto xj = solveSpaceTime(p, diagonal);
    for (int c = 0; c < 3; ++c) {
        const Field dense = denseLeastSquares(p, c);
        EXPECT_LT(maxDiff(x[c], dense), 1e-8) << "seed " << seed << " channel " << c;
        EXPECT_LT(maxDiff(xb[c], dense), 1e-8) << "seed " << seed << " channel " << c;
        EXPECT_LT(maxDiff(xj[c], dense), 1e-8) << "seed " << seed << " channel " << c;
        EXPECT_LT(maxDiff(solveSpaceTimeExactL2(p, c), dense), 1e-8) << "seed " << seed << " channel " << c;
    }
    return x;
}

// p with each pixel the partner of one pixel at most (a later pixel of a shared partner gets
// none): the form the motion map and the replay give, which the solver takes without the lists
// of a general map (the shared partners of withMixedRows take the general form).
SpaceTimeProblem onePartnerEach(SpaceTimeProblem p) {
    const std::size_t np = p.pixels();
    for (std::size_t f = 0; f + 1 < std::size_t(p.frames); ++f) {
        std::vector<bool> taken(np, false);
        for (std::size_t k = 0; k < np; ++k) {
            std::uint32_t& to = p.temporalPartner[f * np + k];
            if (to == kNoTemporalPartner) continue;
            if (taken[to])
                to = kNoTemporalPartner;
            else
                taken[to] = true;
        }
    }
    return p;
}

// p tied to a frame before the window (noisy previous frame, dt and mixed targets), whose
// pixels take the partners of p's first frame.
SpaceTimeProblem tiedToFrameBefore(SpaceTimeProblem p, unsigned seed) {
    const std::size_t np = p.pixels();
    p.previousPartner.assign(p.temporalPartner.begin(), p.temporalPartner.begin() + std::ptrdiff_t(np));
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, 0.3);
    for (int c = 0; c < 3; ++c)
        for (Field* f : {&p.previous[c], &p.dtPrevious[c], &p.dxtPrevious[c], &p.dytPrevious[c]}) {
            f->resize(np);
            for (double& v : *f) v = noise(rng);
        }
    return p;
}

TEST(SpaceTimePoisson, PartnersOfOnePixelEachSolveTheLeastSquaresOfTheirRows) {
    for (const unsigned seed : {5u, 6u}) {
        const SpaceTimeProblem shared = withMixedRows(seed);
        const SpaceTimeProblem p = onePartnerEach(shared);
        ASSERT_NE(p.temporalPartner, shared.temporalPartner) << "seed " << seed << ": no shared partner";
        const auto x = expectDenseLeastSquares(p, seed);
        // Without mixed rows too (the temporal rows alone, the diagonal preconditioner).
        SpaceTimeProblem without = p;
        without.gamma = 0.0;
        const auto y = solveSpaceTime(without, tightL2());
        for (int c = 0; c < 3; ++c)
            EXPECT_LT(maxDiff(y[c], denseLeastSquares(without, c)), 1e-8)
                << "seed " << seed << " channel " << c;
        EXPECT_GT(maxDiff(y[0], x[0]), 1e-3);
        // Tied to a frame before the window by rows of one partner each (its mixed rows too),
        // which frame 0 takes in the general form.
        const auto z = expectDenseLeastSquares(tiedToFrameBefore(p, seed), seed);
        EXPECT_GT(maxDiff(z[0], x[0]), 1e-3);
    }
}

// A workspace carried from solve to solve (a sequence's windows) changes no bit, whatever the
// solves before it: other sizes, general or one-partner maps, with or without mixed rows and a
// frame before.
TEST(SpaceTimePoisson, AWorkspaceGivesTheSameBitsAsFreshBuffers) {
    const std::vector<SpaceTimeProblem> problems = {
        withMixedRows(1), onePartnerEach(withMixedRows(5)), noisy(consistentProblem(9, 5, 3), 0.2, 8),
        tiedToFrameBefore(onePartnerEach(withMixedRows(7)), 7), withRandomPartners(2)};
    std::vector<std::array<Field, 3>> fresh;
    for (const SpaceTimeProblem& p : problems) fresh.push_back(solveSpaceTime(p));
    for (const bool reversed : {false, true}) {
        SpaceTimeWorkspace workspace;
        for (std::size_t k = 0; k < problems.size(); ++k) {
            const std::size_t at = reversed ? problems.size() - 1 - k : k;
            const auto x = solveSpaceTime(problems[at], {}, nullptr, &workspace);
            for (int c = 0; c < 3; ++c)
                EXPECT_TRUE(x[c] == fresh[at][c]) << "problem " << at << (reversed ? " (reversed)" : "");
        }
    }
}

TEST(SpaceTimePoisson, MixedRowsSolveTheLeastSquaresOfTheirRows) {
    for (const unsigned seed : {1u, 2u}) {
        const SpaceTimeProblem p = withMixedRows(seed);
        const SpaceTimeOptions o = tightL2();
        const auto x = expectDenseLeastSquares(p, seed);
        // The mixed rows matter: without them the answer moves.
        SpaceTimeProblem without = p;
        without.gamma = 0.0;
        EXPECT_GT(maxDiff(solveSpaceTime(without, o)[0], x[0]), 1e-3);
    }
}

// Every kind of row weighted (the variance-weighted reconstructions, tgpt --recon wl1|wl2):
// random weights in [0, 2), a tenth of them 0, on the mixed-row problem tied to a previous frame.
TEST(SpaceTimePoisson, RowWeightsSolveTheWeightedLeastSquares) {
    for (const unsigned seed : {3u, 4u}) {
        SpaceTimeProblem p = withMixedRows(seed);
        const std::size_t np = p.pixels(), n = p.size(), nt = np * std::size_t(p.frames - 1);
        std::mt19937 rng(seed);
        std::uniform_real_distribution<double> u(0.0, 2.0);
        std::normal_distribution<double> noise(0.0, 0.3);
        for (int c = 0; c < 3; ++c) {
            p.previous[c].resize(np);
            p.dtPrevious[c].resize(np);
            for (std::size_t j = 0; j < np; ++j)
                p.previous[c][j] = 1.0 + noise(rng), p.dtPrevious[c][j] = noise(rng);
        }
        // Partners one pixel to the right, some missing, some elsewhere (as withMixedRows).
        for (std::size_t j = 0; j < np; ++j) {
            const unsigned r = rng() % 8;
            p.previousPartner.push_back(r == 0 || j % 7 + 1 == 7 ? kNoTemporalPartner
                                        : r == 1                 ? std::uint32_t(rng() % np)
                                                                 : std::uint32_t(j + 1));
        }
        for (int c = 0; c < 3; ++c) {
            p.dxtPrevious[c].resize(np);
            p.dytPrevious[c].resize(np);
            for (std::size_t j = 0; j < np; ++j)
                p.dxtPrevious[c][j] = noise(rng), p.dytPrevious[c][j] = noise(rng);
        }
        const auto weights = [&](std::size_t count) {
            Field f(count);
            for (double& v : f) v = rng() % 10 == 0 ? 0.0 : u(rng);
            return f;
        };
        p.weightPrimal = weights(n);
        p.weightDx = weights(n);
        p.weightDy = weights(n);
        p.weightDt = weights(nt);
        p.weightDxt = weights(nt);
        p.weightDyt = weights(nt);
        p.weightDtPrevious = weights(np);
        p.weightDxtPrevious = weights(np);
        p.weightDytPrevious = weights(np);
        const SpaceTimeOptions o = tightL2();
        const auto x = expectDenseLeastSquares(p, seed);
        // Each kind of weight moves the answer.
        for (Field SpaceTimeProblem::*weight :
             {&SpaceTimeProblem::weightDt, &SpaceTimeProblem::weightDxt, &SpaceTimeProblem::weightDyt,
              &SpaceTimeProblem::weightDtPrevious, &SpaceTimeProblem::weightDxtPrevious,
              &SpaceTimeProblem::weightDytPrevious}) {
            SpaceTimeProblem unit = p;
            (unit.*weight).clear();
            EXPECT_GT(maxDiff(solveSpaceTime(unit, o)[0], x[0]), 1e-4) << "seed " << seed;
        }
        // Sizes and values are checked.
        SpaceTimeProblem bad = p;
        bad.weightDt.pop_back();
        EXPECT_THROW((void)solveSpaceTime(bad, o), Error);
        bad = p;
        bad.weightDtPrevious[0] = -1.0;
        EXPECT_THROW((void)solveSpaceTime(bad, o), Error);
        bad = p;
        bad.dxtPrevious[1].pop_back();
        EXPECT_THROW((void)solveSpaceTime(bad, o), Error);
        bad = p;
        bad.gamma = 0.0;
        bad.dxt = bad.dyt = {};
        EXPECT_THROW((void)solveSpaceTime(bad, o), Error) << "mixed rows to the previous frame without gamma";
        // The mixed rows to the previous frame matter.
        SpaceTimeProblem without = p;
        without.dxtPrevious = without.dytPrevious = {};
        without.weightDxtPrevious.clear();
        without.weightDytPrevious.clear();
        EXPECT_GT(maxDiff(solveSpaceTime(without, o)[0], x[0]), 1e-4) << "seed " << seed;
    }
}

TEST(SpaceTimePoisson, MixedRowsKeepConsistentDataExact) {
    // The moving pattern's own mixed differences: every row holds exactly, L2 and L1.
    const int w = 9, h = 6, frames = 4;
    SpaceTimeProblem p = consistentProblem(w, h, frames);
    const std::size_t np = p.pixels();
    p.temporalPartner.assign(np * (frames - 1), 0u);
    for (std::size_t i = 0; i < p.temporalPartner.size(); ++i)
        p.temporalPartner[i] =
            (i % np) % w + 1 < std::size_t(w) ? std::uint32_t(i % np + 1) : kNoTemporalPartner;
    p.gamma = 1.5;
    const auto at = [&](const Field& f, std::size_t frame, std::size_t k) { return f[frame * np + k]; };
    for (int c = 0; c < 3; ++c) {
        p.dxt[c].assign(np * (frames - 1), 0.0);
        p.dyt[c].assign(np * (frames - 1), 0.0);
        for (std::size_t i = 0; i < p.temporalPartner.size(); ++i) {
            const std::uint32_t to = p.temporalPartner[i];
            if (to == kNoTemporalPartner) continue;
            const std::size_t f = i / np;
            p.dt[c][i] = at(p.primal[c], f + 1, to) - p.primal[c][i];
            p.dxt[c][i] = at(p.dx[c], f + 1, to) - p.dx[c][i];
            p.dyt[c][i] = at(p.dy[c], f + 1, to) - p.dy[c][i];
        }
    }
    for (const bool l1 : {false, true}) {
        SpaceTimeOptions o;
        o.l1 = l1;
        o.tolerance = 1e-10;
        SpaceTimeProblem start = p;
        for (int c = 0; c < 3; ++c) start.initial[c].assign(p.size(), 0.0);
        const auto x = solveSpaceTime(start, o);
        for (int c = 0; c < 3; ++c)
            EXPECT_LT(maxDiff(x[c], p.primal[c]), 1e-6) << "l1 " << l1 << " channel " << c;
    }
    // The same window after its first frame, tied to it by dt and mixed rows: still exact.
    SpaceTimeProblem after = afterFirstFrame(p);
    after.gamma = p.gamma;
    after.previousPartner.assign(p.temporalPartner.begin(), p.temporalPartner.begin() + std::ptrdiff_t(np));
    after.temporalPartner.assign(p.temporalPartner.begin() + std::ptrdiff_t(np), p.temporalPartner.end());
    for (int c = 0; c < 3; ++c) {
        after.dxt[c].assign(p.dxt[c].begin() + std::ptrdiff_t(np), p.dxt[c].end());
        after.dyt[c].assign(p.dyt[c].begin() + std::ptrdiff_t(np), p.dyt[c].end());
        after.dxtPrevious[c].assign(p.dxt[c].begin(), p.dxt[c].begin() + std::ptrdiff_t(np));
        after.dytPrevious[c].assign(p.dyt[c].begin(), p.dyt[c].begin() + std::ptrdiff_t(np));
    }
    expectRecoveredFromZero(after);
    // A wrong mixed target (the sign of ∂x∂t flipped) no longer fits: the data is not recovered.
    SpaceTimeProblem wrong = p;
    for (int c = 0; c < 3; ++c)
        for (double& v : wrong.dxt[c]) v = -v;
    SpaceTimeOptions o;
    o.l1 = false;
    o.tolerance = 1e-10;
    EXPECT_GT(maxDiff(solveSpaceTime(wrong, o)[0], p.primal[0]), 1e-3);
}

// The solver splits the window into ranges of pixels over its threads and adds each range's
// sums in range order: 1, 2 and 3 threads give the same bits (L1, whose weights depend on every
// sum), on a window of several ranges with partners and the frame before.
TEST(SpaceTimePoisson, SameBitsForAnyThreadCount) {
    SpaceTimeProblem p = noisy(consistentProblem(64, 48, 10), 0.2, 5);
    const std::size_t np = p.pixels();
    ASSERT_GT(p.size(), 3u * 8192u) << "fewer ranges than threads";
    std::mt19937 rng(11);
    std::uniform_int_distribution<std::uint32_t> pick(0, std::uint32_t(np - 1));
    p.temporalPartner.resize(np * (p.frames - 1));
    for (std::size_t i = 0; i < p.temporalPartner.size(); ++i)
        p.temporalPartner[i] =
            i % 7 == 0 ? kNoTemporalPartner : (i % 5 == 0 ? pick(rng) : std::uint32_t(i % np));
    p.gamma = 0.5;
    for (int c = 0; c < 3; ++c) {
        p.previous[c].assign(np, 0.5);
        p.dtPrevious[c].assign(np, 0.1);
        p.dxt[c].assign(np * (p.frames - 1), 0.01 * c);
        p.dyt[c].assign(np * (p.frames - 1), -0.02);
    }
    // The shared partners above take the general form, one partner each the linked one.
    for (const SpaceTimeProblem& q : {p, onePartnerEach(p)}) {
        SpaceTimeOptions o;
        o.threads = 1;
        SpaceTimeStats one;
        const auto x1 = solveSpaceTime(q, o, &one);
        ASSERT_GT(one.iterations, 10);
        for (const int threads : {2, 3}) {
            o.threads = threads;
            SpaceTimeStats s;
            const auto x = solveSpaceTime(q, o, &s);
            EXPECT_EQ(s.iterations, one.iterations) << threads << " threads";
            for (int c = 0; c < 3; ++c) EXPECT_TRUE(x[c] == x1[c]) << threads << " threads, channel " << c;
        }
    }
}

TEST(SpaceTimePoisson, BadInputIsRefused) {
    SpaceTimeProblem p = consistentProblem(4, 4, 3);
    p.dt[1].pop_back();
    EXPECT_THROW((void)solveSpaceTime(p), Error);
    p = consistentProblem(4, 4, 3);
    p.primal[2][5] = std::nan("");
    EXPECT_THROW((void)solveSpaceTime(p), Error);
    p = consistentProblem(4, 4, 3);
    p.alpha = 0.0;
    EXPECT_THROW((void)solveSpaceTime(p), Error);
    p = consistentProblem(4, 4, 3);
    p.temporalPartner.assign(16, 0u);  // two frames of rows need 32
    EXPECT_THROW((void)solveSpaceTime(p), Error);
    p.temporalPartner.assign(32, 0u);
    p.temporalPartner[7] = 16u;  // beyond the frame
    EXPECT_THROW((void)solveSpaceTime(p), Error);
    p.temporalPartner[7] = kNoTemporalPartner;
    EXPECT_NO_THROW((void)solveSpaceTime(p));
    p.gamma = 0.5;  // mixed rows without their targets
    EXPECT_THROW((void)solveSpaceTime(p), Error);
    for (int c = 0; c < 3; ++c) p.dxt[c].assign(32, 0.0), p.dyt[c].assign(32, 0.0);
    EXPECT_NO_THROW((void)solveSpaceTime(p));
    p.gamma = -1.0;
    EXPECT_THROW((void)solveSpaceTime(p), Error);
}

}  // namespace
}  // namespace gdpt
