// poisson_spacetime.cpp — the space-time screened Poisson reconstruction (poisson_spacetime.h).
#include "poisson/poisson_spacetime.h"

#include <Eigen/Sparse>
#include <algorithm>
#include <cmath>
#include <future>
#include <thread>
#include <vector>

#include "util/error.h"
#include "util/timer.h"

namespace gdpt {
namespace {

// The normal equations A = Pᵀ W P of one channel in graph form: (A x)_i = Σ_j c_ij (x_i − x_j)
// + cp_i x_i over the x, y and frame neighbours (poisson_problem.h's form, one more axis).
struct Operator {
    int width = 0, height = 0, frames = 0;
    Field cx, cy, ct, cp;  // edge i–(i+1), i–(i+W), i–next(i); screening
    Field cb;              // rows from the fixed previous frame's pixel j to bnext(j) (W·H; empty: none)
    std::vector<std::size_t> next;   // next(i): the temporal neighbour of i in the window (where ct > 0)
    std::vector<std::size_t> bnext;  // bnext(j): the pixel of frame 0 of the previous frame's pixel j
    [[nodiscard]] std::size_t pixels() const { return std::size_t(width) * std::size_t(height); }
    [[nodiscard]] std::size_t size() const { return pixels() * std::size_t(frames); }
};

// Row weights shared by the channels (IRLS; all 1 for L2). Dropped rows are 0.
struct Weights {
    Field primal, dx, dy, dt, boundary;  // boundary: W·H rows to the previous frame, or empty
};

void check(const SpaceTimeProblem& p) {
    if (p.width < 1 || p.height < 1 || p.frames < 1) throw Error("space-time Poisson: empty window");
    if (!(p.alpha > 0.0) || !std::isfinite(p.alpha)) throw Error("space-time Poisson: alpha must be > 0");
    if (!(p.beta >= 0.0) || !std::isfinite(p.beta)) throw Error("space-time Poisson: beta must be >= 0");
    const std::size_t n = p.size(), nt = p.pixels() * std::size_t(p.frames - 1);
    for (int c = 0; c < 3; ++c) {
        const auto sized = [&](const Field& f, std::size_t want, const char* what) {
            if (f.size() != want)
                throw Error(std::string("space-time Poisson: ") + what + " has " + std::to_string(f.size()) +
                            " values, expected " + std::to_string(want));
            for (double v : f)
                if (!std::isfinite(v))
                    throw Error(std::string("space-time Poisson: ") + what + " is not finite");
        };
        sized(p.primal[c], n, "primal");
        sized(p.dx[c], n, "dx");
        sized(p.dy[c], n, "dy");
        sized(p.dt[c], nt, "dt");
        if (!p.initial[c].empty()) sized(p.initial[c], n, "initial");
        if (!p.previous[c].empty() || !p.dtPrevious[c].empty()) {
            sized(p.previous[c], p.pixels(), "previous");
            sized(p.dtPrevious[c], p.pixels(), "dtPrevious");
        }
    }
    if (p.previous[0].empty() != p.previous[1].empty() || p.previous[0].empty() != p.previous[2].empty())
        throw Error("space-time Poisson: previous is given for some channels only");
    const auto partners = [&](const std::vector<std::uint32_t>& v, std::size_t want, const char* what) {
        if (v.empty()) return;
        if (v.size() != want)
            throw Error(std::string("space-time Poisson: ") + what + " has " + std::to_string(v.size()) +
                        " entries, expected " + std::to_string(want));
        for (std::uint32_t j : v)
            if (j != kNoTemporalPartner && j >= p.pixels())
                throw Error(std::string("space-time Poisson: ") + what + " names pixel " + std::to_string(j) +
                            " of a frame of " + std::to_string(p.pixels()));
    };
    partners(p.temporalPartner, nt, "temporalPartner");
    partners(p.previousPartner, p.previous[0].empty() ? 0 : p.pixels(), "previousPartner");
}

// The temporal neighbour of every row's pixel in the window (frame f's i → frame f+1's π(i))
// and of the previous frame's pixels in frame 0; kNoRow where π names none.
constexpr std::size_t kNoRow = ~std::size_t{0};

std::vector<std::size_t> nextPixels(const SpaceTimeProblem& p) {
    const std::size_t np = p.pixels(), nt = np * std::size_t(p.frames - 1);
    std::vector<std::size_t> next(nt);
    for (std::size_t i = 0; i < nt; ++i) {
        const std::size_t frameStart = (i / np + 1) * np;
        if (p.temporalPartner.empty())
            next[i] = i + np;
        else
            next[i] = p.temporalPartner[i] == kNoTemporalPartner ? kNoRow : frameStart + p.temporalPartner[i];
    }
    return next;
}

std::vector<std::size_t> previousNext(const SpaceTimeProblem& p) {
    if (p.previous[0].empty()) return {};
    std::vector<std::size_t> next(p.pixels());
    for (std::size_t j = 0; j < next.size(); ++j) {
        if (p.previousPartner.empty())
            next[j] = j;
        else
            next[j] = p.previousPartner[j] == kNoTemporalPartner ? kNoRow : p.previousPartner[j];
    }
    return next;
}

Weights unitWeights(const SpaceTimeProblem& p) {
    const std::size_t n = p.size(), np = p.pixels(), w = std::size_t(p.width);
    Weights wt{Field(n, 1.0), Field(n, 1.0), Field(n, 1.0), Field(np * std::size_t(p.frames - 1), 1.0),
               p.previous[0].empty() ? Field() : Field(np, 1.0)};
    for (std::size_t i = 0; i < n; ++i) {
        if ((i % np) % w + 1 == w) wt.dx[i] = 0.0;
        if ((i % np) + w >= np) wt.dy[i] = 0.0;
    }
    for (std::size_t i = 0; i < p.temporalPartner.size(); ++i)
        if (p.temporalPartner[i] == kNoTemporalPartner) wt.dt[i] = 0.0;
    for (std::size_t j = 0; j < p.previousPartner.size() && !wt.boundary.empty(); ++j)
        if (p.previousPartner[j] == kNoTemporalPartner) wt.boundary[j] = 0.0;
    return wt;
}

Operator makeOperator(const SpaceTimeProblem& p, const Weights& wt) {
    Operator op;
    op.width = p.width;
    op.height = p.height;
    op.frames = p.frames;
    const std::size_t n = p.size(), np = p.pixels();
    op.cx = wt.dx;
    op.cy = wt.dy;
    op.ct.assign(n, 0.0);
    op.next = nextPixels(p);
    op.next.resize(n, kNoRow);
    op.bnext = previousNext(p);
    for (std::size_t i = 0; i + np < n; ++i)
        if (op.next[i] != kNoRow) op.ct[i] = p.beta * p.beta * wt.dt[i];
    op.cp.resize(n);
    for (std::size_t i = 0; i < n; ++i) op.cp[i] = p.alpha * p.alpha * wt.primal[i];
    op.cb = wt.boundary;
    for (double& v : op.cb) v *= p.beta * p.beta;
    return op;
}

// b = Pᵀ W target: α² wp t minus the weighted divergence of the (dx, dy, dt) field.
Field rhs(const SpaceTimeProblem& p, const Operator& op, int c) {
    const std::size_t n = op.size(), w = std::size_t(op.width);
    Field b(n);
    for (std::size_t i = 0; i < n; ++i) b[i] = op.cp[i] * p.primal[c][i];
    for (std::size_t j = 0; j < op.cb.size(); ++j)
        if (op.cb[j] != 0.0) b[op.bnext[j]] += op.cb[j] * (p.previous[c][j] + p.dtPrevious[c][j]);
    for (std::size_t i = 0; i < n; ++i) {
        if (op.cx[i] != 0.0) {
            b[i] -= op.cx[i] * p.dx[c][i];
            b[i + 1] += op.cx[i] * p.dx[c][i];
        }
        if (op.cy[i] != 0.0) {
            b[i] -= op.cy[i] * p.dy[c][i];
            b[i + w] += op.cy[i] * p.dy[c][i];
        }
        if (op.ct[i] != 0.0) {
            b[i] -= op.ct[i] * p.dt[c][i];
            b[op.next[i]] += op.ct[i] * p.dt[c][i];
        }
    }
    return b;
}

void apply(const Operator& op, const Field& x, Field& y) {
    const std::size_t n = op.size(), w = std::size_t(op.width);
    for (std::size_t i = 0; i < n; ++i) y[i] = op.cp[i] * x[i];
    for (std::size_t j = 0; j < op.cb.size(); ++j)
        if (op.cb[j] != 0.0) y[op.bnext[j]] += op.cb[j] * x[op.bnext[j]];
    for (std::size_t i = 0; i < n; ++i) {
        const double xi = x[i];
        if (op.cx[i] != 0.0) {
            const double f = op.cx[i] * (xi - x[i + 1]);
            y[i] += f;
            y[i + 1] -= f;
        }
        if (op.cy[i] != 0.0) {
            const double f = op.cy[i] * (xi - x[i + w]);
            y[i] += f;
            y[i + w] -= f;
        }
        if (op.ct[i] != 0.0) {
            const std::size_t j = op.next[i];
            const double f = op.ct[i] * (xi - x[j]);
            y[i] += f;
            y[j] -= f;
        }
    }
}

Field diagonalOf(const Operator& op) {
    const std::size_t n = op.size(), w = std::size_t(op.width);
    Field d = op.cp;
    for (std::size_t j = 0; j < op.cb.size(); ++j)
        if (op.cb[j] != 0.0) d[op.bnext[j]] += op.cb[j];
    for (std::size_t i = 0; i < n; ++i) {
        if (op.cx[i] != 0.0) d[i] += op.cx[i], d[i + 1] += op.cx[i];
        if (op.cy[i] != 0.0) d[i] += op.cy[i], d[i + w] += op.cy[i];
        if (op.ct[i] != 0.0) d[i] += op.ct[i], d[op.next[i]] += op.ct[i];
    }
    return d;
}

// Jacobi-preconditioned CG from x until ‖b − A x‖ ≤ tolerance ‖b‖. A is SPD (α > 0).
SolveStats pcg(const Operator& op, const Field& b, Field& x, double tolerance, int maxIterations) {
    const std::size_t n = op.size();
    const Field d = diagonalOf(op);
    Field r(n), z(n), p(n), q(n);
    apply(op, x, q);
    double bb = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
        r[i] = b[i] - q[i];
        bb += b[i] * b[i];
    }
    SolveStats s;
    s.rhsNorm = std::sqrt(bb);
    const double target = tolerance * s.rhsNorm;
    double rz = 0.0, rr = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
        z[i] = r[i] / d[i];
        p[i] = z[i];
        rz += r[i] * z[i];
        rr += r[i] * r[i];
    }
    while (std::sqrt(rr) > target && s.iterations < maxIterations) {
        apply(op, p, q);
        double pq = 0.0;
        for (std::size_t i = 0; i < n; ++i) pq += p[i] * q[i];
        if (!(pq > 0.0)) break;
        const double a = rz / pq;
        double rzNew = 0.0;
        rr = 0.0;
        for (std::size_t i = 0; i < n; ++i) {
            x[i] += a * p[i];
            r[i] -= a * q[i];
            z[i] = r[i] / d[i];
            rzNew += r[i] * z[i];
            rr += r[i] * r[i];
        }
        const double beta = rzNew / rz;
        rz = rzNew;
        for (std::size_t i = 0; i < n; ++i) p[i] = z[i] + beta * p[i];
        ++s.iterations;
    }
    s.residualNorm = std::sqrt(rr);
    s.converged = s.residualNorm <= target;
    return s;
}

// IRLS weights of the estimate x: 1 / (‖e‖_RGB + reg) for every kept row, mean 1.
Weights irlsWeights(const SpaceTimeProblem& p, const std::array<Field, 3>& x, double reg) {
    Weights wt = unitWeights(p);
    const std::vector<std::size_t> next = nextPixels(p), bnext = previousNext(p);
    const std::size_t n = p.size(), np = p.pixels(), w = std::size_t(p.width);
    double sum = 0.0;
    std::size_t rows = 0;
    const auto weightOf = [&](const double e[3]) {
        const double v = 1.0 / (std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]) + reg);
        sum += v;
        ++rows;
        return v;
    };
    double e[3];
    for (std::size_t i = 0; i < n; ++i) {
        for (int c = 0; c < 3; ++c) e[c] = p.alpha * (x[c][i] - p.primal[c][i]);
        wt.primal[i] = weightOf(e);
        if (wt.dx[i] != 0.0) {
            for (int c = 0; c < 3; ++c) e[c] = x[c][i + 1] - x[c][i] - p.dx[c][i];
            wt.dx[i] = weightOf(e);
        }
        if (wt.dy[i] != 0.0) {
            for (int c = 0; c < 3; ++c) e[c] = x[c][i + w] - x[c][i] - p.dy[c][i];
            wt.dy[i] = weightOf(e);
        }
        if (i + np < n && wt.dt[i] != 0.0) {
            const std::size_t j = next[i];
            for (int c = 0; c < 3; ++c) e[c] = p.beta * (x[c][j] - x[c][i] - p.dt[c][i]);
            wt.dt[i] = weightOf(e);
        }
    }
    for (std::size_t i = 0; i < wt.boundary.size(); ++i) {
        if (wt.boundary[i] == 0.0) continue;
        const std::size_t j = bnext[i];
        for (int c = 0; c < 3; ++c) e[c] = p.beta * (x[c][j] - p.previous[c][i] - p.dtPrevious[c][i]);
        wt.boundary[i] = weightOf(e);
    }
    const double scale = double(rows) / sum;
    for (Field* f : {&wt.primal, &wt.dx, &wt.dy, &wt.dt, &wt.boundary})
        for (double& v : *f) v *= scale;
    return wt;
}

}  // namespace

std::array<Field, 3> solveSpaceTime(const SpaceTimeProblem& problem, const SpaceTimeOptions& options,
                                    SpaceTimeStats* stats) {
    check(problem);
    Timer timer;
    std::array<Field, 3> x;
    for (int c = 0; c < 3; ++c) x[c] = problem.initial[c].empty() ? problem.primal[c] : problem.initial[c];
    const int rounds = options.l1 ? std::max(1, options.irlsIterations) : 1;
    const unsigned cores =
        options.threads > 0 ? unsigned(options.threads) : std::thread::hardware_concurrency();
    const bool parallel = cores > 1;
    SpaceTimeStats s;
    std::array<int, 3> iterations{};
    for (int round = 0; round < rounds; ++round) {
        const Weights wt =
            round == 0 ? unitWeights(problem)
                       : irlsWeights(problem, x, options.regInit * std::pow(options.regIter, round - 1));
        const Operator op = makeOperator(problem, wt);
        const bool last = round + 1 == rounds;
        const double tolerance = last ? options.tolerance : options.innerTolerance;
        std::array<SolveStats, 3> solved;
        const auto solveChannel = [&](int c) {
            const Field b = rhs(problem, op, c);
            solved[c] = pcg(op, b, x[c], tolerance, options.maxIterations);
        };
        if (parallel) {
            std::array<std::future<void>, 3> jobs;
            for (int c = 0; c < 3; ++c) jobs[c] = std::async(std::launch::async, solveChannel, c);
            for (auto& j : jobs) j.get();
        } else {
            for (int c = 0; c < 3; ++c) solveChannel(c);
        }
        s.residual = 0.0;
        s.converged = true;
        for (int c = 0; c < 3; ++c) {
            iterations[c] += solved[c].iterations;
            const double rel = solved[c].rhsNorm > 0.0 ? solved[c].residualNorm / solved[c].rhsNorm : 0.0;
            s.residual = std::max(s.residual, rel);
            s.converged = s.converged && solved[c].converged;
        }
    }
    s.iterations = *std::max_element(iterations.begin(), iterations.end());
    s.irlsIterations = rounds;
    s.ms = timer.ms();
    if (stats) *stats = s;
    return x;
}

Field solveSpaceTimeExactL2(const SpaceTimeProblem& problem, int channel) {
    check(problem);
    const Operator op = makeOperator(problem, unitWeights(problem));
    const Field b = rhs(problem, op, channel);
    const Field d = diagonalOf(op);
    const std::size_t n = op.size(), w = std::size_t(op.width);
    std::vector<Eigen::Triplet<double>> triplets;
    triplets.reserve(n * 7);
    for (std::size_t i = 0; i < n; ++i) {
        const int ii = static_cast<int>(i);
        triplets.emplace_back(ii, ii, d[i]);
        const auto edge = [&](std::size_t j, double c) {
            if (c == 0.0) return;
            triplets.emplace_back(ii, static_cast<int>(j), -c);
            triplets.emplace_back(static_cast<int>(j), ii, -c);
        };
        edge(i + 1, op.cx[i]);
        edge(i + w, op.cy[i]);
        if (op.ct[i] != 0.0) edge(op.next[i], op.ct[i]);
    }
    Eigen::SparseMatrix<double> a(static_cast<int>(n), static_cast<int>(n));
    a.setFromTriplets(triplets.begin(), triplets.end());
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(a);
    if (ldlt.info() != Eigen::Success) throw Error("space-time Poisson: LDLT factorisation failed");
    Eigen::VectorXd bv(static_cast<int>(n));
    for (std::size_t i = 0; i < n; ++i) bv[static_cast<int>(i)] = b[i];
    const Eigen::VectorXd xv = ldlt.solve(bv);
    return Field(xv.data(), xv.data() + n);
}

}  // namespace gdpt
